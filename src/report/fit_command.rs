//! `bulge fit` in memory: the checks of its settings, the fit of a
//! stress/strain table, the correction of the law to an experiment's
//! heights and every file it writes, built before anything is written. The
//! command line writes them; the Python package returns them.

use std::path::Path;

use crate::experiment::Experiment;
use crate::fit::data::{self, LoadOptions, Loaded};
use crate::fit::hyperelastic::Kind;
use crate::fit::{FitError, FitModel, FitSettings, FittedMaterial, fit_material, inverse};
use crate::io::{InputError, Table};
use crate::mechanics::Modulus;
use crate::report::fit_outputs::{FitOutputs, fit_outputs};
use crate::setting::Setting;

/// The choices of `bulge fit`, as its flags give them.
#[derive(Debug, Clone, PartialEq)]
pub struct FitChoices {
    /// The model (`--model`).
    pub model: FitModel,
    /// The polynomial degree (`--degree`).
    pub degree: usize,
    /// The Ogden terms (`--ogden-terms`).
    pub ogden_terms: usize,
    /// The Poisson ratio (`--poisson`).
    pub poisson: f64,
    /// The data's secant modulus convention (`--modulus`).
    pub modulus: Modulus,
    /// Weight every point by its standard deviation (`--weighted`).
    pub weighted: bool,
    /// Points of the drawn curve (`--samples`).
    pub samples: usize,
    /// How the table's columns are read (`--stress-measure`,
    /// `--strain-measure`; `poisson` and `modulus` as above).
    pub stress_measure: Option<crate::fit::StressMeasure>,
    /// See `stress_measure`.
    pub strain_measure: Option<crate::material::StrainMeasure>,
}

/// A choice out of its range: `key` (the flag's name in snake case) and a
/// text that starts with the value given and ends with the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{key} {text}")]
pub struct BadChoice {
    /// The setting, e.g. `poisson`.
    pub key: &'static str,
    /// The value, what is wrong with it and what to give.
    pub text: String,
}

impl FitChoices {
    /// The fit's settings, or the first choice out of its range.
    pub fn settings(&self) -> Result<FitSettings, BadChoice> {
        let (p, d, o, n) = (self.poisson, self.degree, self.ogden_terms, self.samples);
        let checks = [
            (
                (0.0..0.5).contains(&p),
                "poisson",
                format!(
                    "{p} is outside [0, 0.5): give the specimen's Poisson ratio (0.45 for latex, 0.5 is excluded)"
                ),
            ),
            (
                d <= 8,
                "degree",
                format!(
                    "{d} is too high: polynomial laws above degree 8 only fit the noise; use 2 to 6"
                ),
            ),
            (
                (1..=3).contains(&o),
                "ogden_terms",
                format!("{o} is not supported: use 1, 2 or 3"),
            ),
            (
                (2..=100_000).contains(&n),
                "samples",
                format!("{n} must be in 2..=100000 (points of the drawn curve; 200 is plenty)"),
            ),
        ];
        if let Some((_, key, text)) = checks.into_iter().find(|c| !c.0) {
            return Err(BadChoice { key, text });
        }
        let model = match self.model {
            FitModel::Hyperelastic(Kind::Ogden(_)) => {
                FitModel::Hyperelastic(Kind::Ogden(self.ogden_terms))
            }
            m => m.with_degree(self.degree),
        };
        Ok(FitSettings {
            model,
            poisson: self.poisson,
            modulus: self.modulus,
            modulus_stress: None,
            lower_degree: false,
            weighted: self.weighted,
        })
    }

    fn load_options(&self) -> LoadOptions {
        LoadOptions {
            stress_measure: self.stress_measure,
            strain_measure: self.strain_measure,
            poisson: self.poisson,
            modulus: self.modulus,
        }
    }
}

/// Why `bulge fit` wrote nothing.
#[derive(Debug, thiserror::Error)]
pub enum FitCommandError {
    /// A setting out of its range.
    #[error(transparent)]
    Choice(#[from] BadChoice),
    /// A file, a cell or a setting of the table refused: `setting` names
    /// the setting when one is the fix.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The data cannot give the law asked for (the message names the input).
    #[error("{0}")]
    Refused(String),
    /// The fit or the correction failed (the message names the input).
    #[error("{0}")]
    Failed(String),
}

impl crate::Refusal for FitCommandError {
    fn is_bad_input(&self) -> bool {
        !matches!(self, FitCommandError::Failed(_))
    }
}

/// Everything `bulge fit` writes, in memory, and what it says.
pub struct FitFiles {
    /// The fitted law with its uncertainty (`material.toml`).
    pub material: FittedMaterial,
    /// The side files and the figure ([`fit_outputs`]).
    pub outputs: FitOutputs,
    /// The data as loaded.
    pub data: Loaded,
    /// What was fitted and how well, and the correction, for the terminal.
    pub summary: String,
}

/// `bulge fit` of `table` (named `input` in messages) with `settings`
/// (from [`FitChoices::settings`]), corrected to the heights of `table` on
/// the specimen of the experiment file `to_heights` when given.
pub fn fit_files(
    table: &Table,
    input: &str,
    choices: &FitChoices,
    settings: &FitSettings,
    to_heights: Option<&Path>,
) -> Result<FitFiles, FitCommandError> {
    let specimen = to_heights.map(Experiment::read_specimen).transpose()?;
    let loaded = data::load(table, &choices.load_options())?;
    let mut fitted = fit_material(&loaded, settings, input).map_err(|e| match e {
        FitError::TooFewPoints { points, .. }
            if matches!(settings.model, FitModel::Quartic { .. }) =>
        {
            FitCommandError::Refused(format!(
                "{input}: {e} (with {points} points with a secant modulus, use {} {} or less)",
                Setting::Degree,
                points.max(1) - 1
            ))
        }
        FitError::Solver(_) => FitCommandError::Failed(format!("{input}: {e}")),
        e => FitCommandError::Refused(format!("{input}: {e}")),
    })?;
    let outputs = fit_outputs(&fitted, &loaded, settings, input, choices.samples);
    let mut summary = outputs.summary.clone();
    if let (Some(exp), Some(spec)) = (to_heights, &specimen) {
        summary.push_str(&correct_to_heights(
            input,
            table,
            exp,
            spec,
            &mut fitted,
            settings.weighted,
        )?);
    }
    Ok(FitFiles {
        material: fitted,
        outputs,
        data: loaded,
        summary,
    })
}

/// The law corrected to the heights of `table` on `specimen` (of the
/// experiment file `exp`, whose stated errors join the heights' own); the
/// summary line.
fn correct_to_heights(
    input: &str,
    table: &Table,
    exp: &Path,
    specimen: &crate::Specimen,
    fitted: &mut FittedMaterial,
    weighted: bool,
) -> Result<String, FitCommandError> {
    let Some(measured) = inverse::Measured::from_table(table)? else {
        return Err(FitCommandError::Refused(format!(
            "{input}: {} needs the columns pressure_pa and height_m (bulge stress writes them); fit its stress_strain.csv",
            Setting::ToHeights
        )));
    };
    let opts = inverse::Options {
        uncertainty: Experiment::read(exp)?.uncertainty(),
        weighted,
        ..Default::default()
    };
    let window = Experiment::read_window(exp)?;
    let r = if window.is_circle() {
        fitted.refine_to_heights(specimen, &measured, &opts)
    } else {
        let scene = crate::sim::scene::Scene::from_window(
            specimen,
            &window,
            fitted.cap_material.clone(),
            vec![],
        );
        fitted.refine_in_scene(&scene, None, &measured, &opts)
    }
    .map_err(|err| {
        FitCommandError::Failed(format!(
            "{input}: the law could not be corrected to the heights: {err}"
        ))
    })?;
    Ok(format!(
        "corrected to the heights of {} points on the specimen of {}: {}\n",
        measured.len(),
        exp.display(),
        r.describe()
    ))
}
