//! `stress` and `fit`: the stages that need no photos, over tables given
//! as CSV bytes (the Python side writes a DataFrame with its header), each
//! through the library's own entry of `bulge stress` and `bulge fit`.

use std::path::{Path, PathBuf};

use bulge::Refusal;
use bulge::experiment::{Experiment, Specimen};
use bulge::fit::FitModel;
use bulge::fit::uncertainty::Sources;
use bulge::io::{InputError, Table};
use bulge::mechanics::{self, Modulus};
use bulge::pipeline;
use bulge::report::fit_command::{FitChoices, FitCommandError, fit_files};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde::Deserialize;
use serde::de::IntoDeserializer;

use super::{bad, chain, failed};

/// A choice named as the settings files and the command line spell it
/// (`"log"`, `"biaxial"`, ...), or the message naming the keyword.
pub(crate) fn choice<'de, T: Deserialize<'de>>(key: &str, value: &'de str) -> PyResult<T> {
    T::deserialize(value.into_deserializer())
        .map_err(|e: serde::de::value::Error| bad(format!("{key}={value:?}: {e}")))
}

/// An input error with the keyword that is its fix, as the command line
/// adds its flag (`(--stress-measure)`).
fn with_keyword(e: InputError, keys: &[&str]) -> InputError {
    match keys.iter().find(|k| e.setting == Some(**k)) {
        Some(k) => InputError {
            message: format!("{} ({k}=)", e.message),
            ..e
        },
        None => e,
    }
}

/// A table from a DataFrame's CSV bytes named `label`, or, without bytes,
/// the CSV file at the path `label`, read as the command line reads it.
fn table(bytes: Option<&[u8]>, label: &str) -> Result<Table, InputError> {
    match bytes {
        Some(b) => Table::parse(Path::new(label), b),
        None => Table::read(label),
    }
}

fn bytes(py: Python<'_>, b: &[u8]) -> Py<PyBytes> {
    PyBytes::new(py, b).unbind()
}

/// The specimen of `bulge stress`: from the experiment file, or from the
/// keywords (each required without it), and the experiment's stated
/// errors besides the heights'; a window that is not a circle is said.
fn specimen(
    experiment: Option<PathBuf>,
    given: [Option<f64>; 4],
    warnings: &mut Vec<String>,
) -> Result<(Specimen, Sources), String> {
    if let Some(path) = experiment {
        let spec = Experiment::read_specimen(&path).map_err(|e| chain(&e))?;
        let whole = Experiment::read(&path).map_err(|e| chain(&e))?;
        if !whole.window.is_circle() {
            warnings.push(format!(
                "{}: [window] is not a circle: the spherical-cap formulas hold for a circular opening only, so these rows are a first guess of the law (radius_m as the cap's radius); correct it through the window with bulge.fit(..., to_heights=...) or use bulge.run",
                path.display()
            ));
        }
        return Ok((spec, whole.uncertainty()));
    }
    let keys = ["radius_m", "thickness_m", "poisson"];
    let need =
        |i: usize| given[i].ok_or_else(|| format!("{} is required without experiment", keys[i]));
    let spec = Specimen {
        radius_m: need(0)?,
        thickness_m: need(1)?,
        poisson: need(2)?,
        prebulge_height_m: given[3].unwrap_or(0.0),
    };
    spec.validate().map_err(|m| format!("{}: {m}", m.field()))?;
    Ok((spec, Sources::default()))
}

/// What `bulge stress` writes: `stress_strain.csv`, the sources table when
/// the experiment states errors besides the heights', and the warnings.
type StressResult = (Py<PyBytes>, Option<Py<PyBytes>>, Vec<String>);

/// `bulge stress` of a heights table (CSV bytes named `label` in messages).
#[pyfunction]
#[pyo3(signature = (heights, label, experiment=None, radius_m=None, thickness_m=None, poisson=None,
    prebulge_height_m=None, strain="engineering", true_stress="paper", modulus="biaxial",
    modulus_stress="nominal", height_std_m=None))]
#[allow(clippy::too_many_arguments)]
pub fn stress(
    py: Python<'_>,
    heights: Option<Vec<u8>>,
    label: String,
    experiment: Option<PathBuf>,
    radius_m: Option<f64>,
    thickness_m: Option<f64>,
    poisson: Option<f64>,
    prebulge_height_m: Option<f64>,
    strain: &str,
    true_stress: &str,
    modulus: &str,
    modulus_stress: &str,
    height_std_m: Option<f64>,
) -> PyResult<StressResult> {
    let opts = mechanics::Options {
        strain: choice("strain", strain)?,
        true_stress: choice("true_stress", true_stress)?,
        modulus: choice("modulus", modulus)?,
        modulus_stress: choice("modulus_stress", modulus_stress)?,
    };
    if let Some(sd) = height_std_m
        && !(sd.is_finite() && sd >= 0.0)
    {
        return Err(bad(format!(
            "height_std_m={sd}: a standard deviation must be a finite number >= 0 (in metres, e.g. 5e-5)"
        )));
    }
    let given = [radius_m, thickness_m, poisson, prebulge_height_m];
    let out = py.allow_threads(move || {
        let mut warnings = Vec::new();
        let (spec, sources) = specimen(experiment, given, &mut warnings).map_err(|m| (true, m))?;
        let t = table(heights.as_deref(), &label).map_err(|e| (true, chain(&e)))?;
        let tables = pipeline::stress_of_table(&spec, &opts, &t, height_std_m, &sources)
            .map_err(|e| (e.is_bad_input(), chain(&e)))?;
        warnings.extend(tables.warnings);
        Ok::<_, (bool, String)>((
            tables.csv.into_bytes(),
            tables.sources_csv.map(|c| c.into_bytes()),
            warnings,
        ))
    });
    match out {
        Ok((csv, sources, warnings)) => {
            Ok((bytes(py, &csv), sources.map(|s| bytes(py, &s)), warnings))
        }
        Err((true, m)) => Err(bad(m)),
        Err((false, m)) => Err(failed(m)),
    }
}

/// What `bulge fit` writes: `material.toml`, the curve, the residuals, the
/// comparison of every model (`all`), the figure as SVG and PNG, the
/// summary and the warnings.
type FitResult = (
    String,
    Py<PyBytes>,
    Py<PyBytes>,
    Option<Py<PyBytes>>,
    Option<(Py<PyBytes>, Py<PyBytes>)>,
    String,
    Vec<String>,
);

/// `bulge fit` of a stress/strain table (CSV bytes named `label`).
#[pyfunction]
#[pyo3(signature = (stress_strain, label, model="quartic", degree=4, ogden_terms=3,
    poisson=0.45, modulus="biaxial", weighted=false, samples=200, stress_measure=None,
    strain_measure=None, to_heights=None, plot=true))]
#[allow(clippy::too_many_arguments)]
pub fn fit(
    py: Python<'_>,
    stress_strain: Option<Vec<u8>>,
    label: String,
    model: &str,
    degree: usize,
    ogden_terms: usize,
    poisson: f64,
    modulus: &str,
    weighted: bool,
    samples: usize,
    stress_measure: Option<&str>,
    strain_measure: Option<&str>,
    to_heights: Option<PathBuf>,
    plot: bool,
) -> PyResult<FitResult> {
    let choices = FitChoices {
        model: model
            .parse::<FitModel>()
            .map_err(|e| bad(format!("model={model:?}: {e}")))?,
        degree,
        ogden_terms,
        poisson,
        modulus: choice::<Modulus>("modulus", modulus)?,
        weighted,
        samples,
        stress_measure: stress_measure
            .map(|s| choice("stress_measure", s))
            .transpose()?,
        strain_measure: strain_measure
            .map(|s| choice("strain_measure", s))
            .transpose()?,
    };
    let settings = choices
        .settings()
        .map_err(|e| bad(format!("{}={}", e.key, e.text)))?;
    let t = table(stress_strain.as_deref(), &label).map_err(|e| bad(chain(&e)))?;
    let out = py.allow_threads(move || {
        let f =
            fit_files(&t, &label, &choices, &settings, to_heights.as_deref()).map_err(
                |e| match e {
                    FitCommandError::Input(e) => (
                        true,
                        chain(&with_keyword(e, &["stress_measure", "strain_measure"])),
                    ),
                    e => (e.is_bad_input(), chain(&e)),
                },
            )?;
        let material =
            bulge::io::to_toml_string(&f.material.material).map_err(|e| (false, chain(&e)))?;
        let figure = if plot {
            let svg = f.outputs.figure.to_svg().map_err(|e| (false, chain(&e)))?;
            let png = f.outputs.figure.to_png().map_err(|e| (false, chain(&e)))?;
            Some((svg.into_bytes(), png))
        } else {
            None
        };
        Ok::<_, (bool, String)>((
            material,
            f.outputs.curve.into_bytes(),
            f.outputs.residuals.into_bytes(),
            f.outputs.models.map(|m| m.into_bytes()),
            figure,
            f.summary,
            f.material.warnings,
        ))
    });
    match out {
        Ok((material, curve, residuals, models, figure, summary, warnings)) => Ok((
            material,
            bytes(py, &curve),
            bytes(py, &residuals),
            models.map(|m| bytes(py, &m)),
            figure.map(|(s, p)| (bytes(py, &s), bytes(py, &p))),
            summary,
            warnings,
        )),
        Err((true, m)) => Err(bad(m)),
        Err((false, m)) => Err(failed(m)),
    }
}
