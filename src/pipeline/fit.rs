//! The fit stage: stress/strain -> the material law, corrected to the
//! heights, the law the heights call for, and the paper's chain beside it.

use crate::experiment::Specimen;
use crate::fit::data::Loaded;
use crate::fit::{FitDetail, FitModel, FitSettings, FittedMaterial, fit_material, inverse, select};
use crate::material::Material;
use crate::mechanics::{Point, StrainMeasure};
use crate::sim::scene::Scene;
use crate::sim::springs::SpringModel;

use super::*;

/// Output of the fit stage.
#[derive(Debug, Clone)]
pub struct FitOut {
    /// The material for the simulators (`material.toml`), with its provenance.
    pub material: Material,
    /// The fit.
    pub detail: FitDetail,
    /// The model fitted (the degree lowered when there were few points).
    pub model: FitModel,
    /// `(strain, secant modulus, its std)` of the points the modulus law saw,
    /// sorted by strain.
    pub modulus_points: Vec<(f64, f64, Option<f64>)>,
    /// `(stretch, Cauchy stress)` of the points the hyperelastic models saw.
    pub stress_points: Vec<(f64, f64)>,
    /// `1 - nu` (biaxial) or 1 (uniaxial): `E = k S / eps`.
    pub modulus_factor: f64,
    /// Strain measure of the law.
    pub strain_measure: StrainMeasure,
    /// Warnings about the law (unphysical regions, ill conditioning).
    pub warnings: Vec<String>,
    /// The quartic's degree lowered to what the points can determine.
    pub degree_lowered: Option<crate::fit::DegreeLowered>,
    /// The law as the stress/strain points gave it, before the correction
    /// to the heights (the same as `material` without it).
    pub cap_material: Material,
    /// The correction to the heights, when made.
    pub refined: Option<inverse::Refined>,
    /// With [`FitModel::Auto`]: every law fitted, corrected to the heights
    /// and ranked on them, and the one carried forward
    /// ([`crate::fit::select`]).
    pub laws: Option<select::Selection>,
}

/// Stage 3: stress/strain -> material ([`crate::fit::fit_material`] on the
/// stress stage's rows, then, with `settings.refine`, the correction of the
/// law to the measured heights; a correction that fails leaves the
/// points' law with a warning).
pub fn fit_stage(
    spec: &Specimen,
    settings: &Settings,
    s: &StressOut,
) -> Result<FitOut, PipelineError> {
    let data = Loaded::from_stress_rows(&s.rows, settings.stress.strain);
    let mut fit_settings = FitSettings {
        model: settings.fit,
        poisson: spec.poisson,
        modulus: settings.stress.modulus,
        modulus_stress: Some(settings.stress.modulus_stress),
        lower_degree: true,
        weighted: settings.weighted,
    };
    let source = "stress_strain.csv of bulge run";
    let (mut fitted, laws) = if settings.fit == FitModel::Auto {
        choose_law(spec, settings, s, &data, &mut fit_settings, source)?
    } else {
        let mut fitted = fit_material(&data, &fit_settings, source)?;
        if settings.refine
            && let Some(w) = crate::dome::positive_start(&mut fitted, &data)
        {
            fitted.warn(w);
        }
        (fitted, None)
    };
    if settings.refine && fitted.refined.is_none() {
        let measured = measured_heights(&s.points);
        let opts = inverse::Options {
            uncertainty: settings.uncertainty,
            weighted: settings.weighted,
            ..inverse::Options::default()
        };
        let refined = if settings.window.is_circle() {
            fitted.refine_to_heights(spec, &measured, &opts).map(|_| ())
        } else {
            let scene =
                Scene::from_window(spec, &settings.window, fitted.cap_material.clone(), vec![]);
            fitted
                .refine_in_scene(&scene, settings.mesh, &measured, &opts)
                .map(|_| ())
        };
        if let Err(e) = refined {
            fitted.warn(format!(
                "the law was not corrected to the heights ({e}); the cap-method law is used"
            ));
        } else if settings.samples > 0
            && let Err(e) = fitted.monte_carlo(spec, &measured, &opts, settings.samples, 1)
        {
            fitted.warn(format!("no Monte Carlo of the parameters: {e}"));
        }
    }
    if let Some(w) = crate::dome::stiffness_problem(
        &fitted.material.model,
        crate::dome::top_strain(&fitted.material.model, &data),
    ) {
        fitted.warn(format!(
            "the law has negative stiffness inside the measured range: {w}; a simulation can snap through or fail there (try another model or give prebulge_height_m)"
        ));
    }
    let modulus_points = data
        .strain
        .iter()
        .zip(&data.modulus_pa)
        .zip(&data.modulus_std_pa)
        .filter_map(|((&e, m), sd)| m.map(|m| (e, m, *sd)))
        .collect();
    let stress_points = data
        .equibiaxial
        .stretch
        .iter()
        .zip(&data.equibiaxial.stress_pa)
        .map(|(&l, &st)| (l, st))
        .collect();
    Ok(FitOut {
        material: fitted.material,
        detail: fitted.detail,
        model: fitted.model,
        modulus_points,
        stress_points,
        modulus_factor: settings.stress.modulus.factor(spec.poisson),
        strain_measure: settings.stress.strain,
        warnings: fitted.warnings,
        degree_lowered: fitted.degree_lowered,
        cap_material: fitted.cap_material,
        refined: fitted.refined,
        laws,
    })
}

/// The fit stage's choice of law ([`FitModel::Auto`]): every law fitted
/// and corrected to the heights weighted by their stated standard
/// deviations, ranked, the chosen one carried forward
/// ([`crate::fit::select`]). A consistent law keeps that weighted
/// correction (the statistically right weighting when the law holds); a
/// law that misses the heights is corrected again by the relative errors
/// `h_sim / h - 1` unless `settings.weighted` asks for the weights anyway,
/// so that no few precise heights pull a wrong law away from the rest.
/// Without the correction to the heights or with a non-circular window
/// there is nothing to choose by: the quartic, with a warning.
pub(super) fn choose_law(
    spec: &Specimen,
    settings: &Settings,
    s: &StressOut,
    data: &Loaded,
    fit_settings: &mut FitSettings,
    source: &str,
) -> Result<(FittedMaterial, Option<select::Selection>), PipelineError> {
    fit_settings.model = FitModel::Quartic { degree: 4 };
    if !settings.refine || !settings.window.is_circle() {
        let mut f = fit_material(data, fit_settings, source)?;
        f.warn(format!(
            "the law was not chosen by the heights ({}): the quartic is used; name a law with {} to fit another",
            if settings.refine {
                "the window is not circular, and the choice corrects every law through the exact axisymmetric inflation"
            } else {
                "the correction to the heights is off"
            },
            crate::setting::Setting::Fit
        ));
        return Ok((f, None));
    }
    let measured = measured_heights(&s.points);
    let opts = inverse::Options {
        uncertainty: settings.uncertainty,
        weighted: true,
        ..inverse::Options::default()
    };
    let sel = select::select(data, fit_settings, spec, &measured, &opts, source)?;
    let row = sel.chosen_row();
    fit_settings.model = row.model;
    let mut fitted = row
        .fitted
        .clone()
        .expect("the chosen law was fitted and corrected");
    if !row.consistent() && !settings.weighted {
        let plain = inverse::Options {
            weighted: false,
            ..opts.clone()
        };
        let mut f = fit_material(data, fit_settings, source)?;
        match f.refine_to_heights(spec, &measured, &plain) {
            Ok(_) => fitted = f,
            Err(e) => fitted.warn(format!(
                "the chosen law misses the heights, and its correction by the relative errors failed ({e}): the one weighted by the heights' standard deviations is kept"
            )),
        }
    }
    if settings.samples > 0
        && let Err(e) = fitted.monte_carlo(
            spec,
            &measured,
            &fitted_opts(&fitted, &opts),
            settings.samples,
            1,
        )
    {
        fitted.warn(format!("no Monte Carlo of the parameters: {e}"));
    }
    Ok((fitted, Some(sel)))
}

/// The correction's options as the kept correction of `f` was made.
pub(super) fn fitted_opts(f: &FittedMaterial, opts: &inverse::Options) -> inverse::Options {
    inverse::Options {
        weighted: f.refined.as_ref().is_some_and(|r| r.weighted),
        ..opts.clone()
    }
}

/// The measured heights that the correction to the heights matches: the
/// points with a positive pressure and height.
pub fn measured_heights(points: &[Point]) -> Vec<inverse::Measured> {
    points
        .iter()
        .filter(|p| p.pressure_pa > 0.0 && p.height_m > 0.0)
        .map(|p| inverse::Measured {
            pressure_pa: p.pressure_pa,
            height_m: p.height_m,
            height_std_m: p.height_std_m,
        })
        .collect()
}

impl FitOut {
    /// One line on the fit: the model, points, R^2, RMSE, and the correction
    /// to the heights when made.
    pub fn summary(&self) -> String {
        let what = match &self.detail {
            FitDetail::Quartic(q) => format!(
                "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                self.model.label(),
                q.stats.n,
                q.stats.r2,
                q.stats.rmse
            ),
            FitDetail::Hyper { fits, best } => {
                let h = &fits[*best];
                format!(
                    "{} on {} points: R^2 {:.5}, RMSE {:.3e} Pa",
                    h.kind.label(),
                    h.stats.n,
                    h.stats.r2,
                    h.stats.rmse
                )
            }
        };
        let what = match &self.refined {
            Some(r) => {
                format!("{what}; corrected to the heights: {}", r.describe())
            }
            None => what,
        };
        match &self.laws {
            Some(l) => format!("{what}; chosen of {} laws: {}", l.rows.len(), l.reason),
            None => what,
        }
    }
}

/// The paper's chain (Tudruj et al. 2023): the quartic secant modulus,
/// corrected to the heights, through TP MSS and the exact axisymmetric
/// solution, kept beside the law the heights called for.
#[derive(Debug, Clone)]
pub struct PaperChain {
    /// The quartic's label.
    pub law: String,
    /// Its runs: TP MSS, then the axisymmetric reference.
    pub runs: Vec<ModelRun>,
    /// Measured against its simulated heights.
    pub comparison: Vec<Comparison>,
    /// Its verdicts against the measured heights (with the quartic's own
    /// band).
    pub verdicts: Vec<Verdict>,
}

/// The paper's chain when the fit stage chose a law other than the quartic
/// and the quartic was corrected to the heights; `None` otherwise (or when
/// its simulation fails: the quartic's row in `laws.csv` still says how it
/// fits).
pub fn paper_chain(
    spec: &Specimen,
    settings: &Settings,
    fit: &FitOut,
    points: &[Point],
    pressures_pa: &[f64],
) -> Option<PaperChain> {
    let laws = fit.laws.as_ref()?;
    let k = laws
        .rows
        .iter()
        .position(|r| matches!(r.model, FitModel::Quartic { .. }))?;
    if k == laws.chosen {
        return None;
    }
    let f = laws.rows[k].fitted.as_ref()?;
    let r = f.refined.as_ref()?;
    let s = Settings {
        models: vec![SpringModel::Tp],
        axisym: true,
        ..settings.clone()
    };
    let runs = simulate_stage(spec, &s, &f.material, pressures_pa, &|| {}).ok()?;
    let comparison = compare(points, &runs, pressures_pa);
    let verdicts = r
        .uncertainty
        .as_ref()
        .map(|u| {
            let band = inverse::band(
                &f.material,
                spec,
                u,
                &settings.uncertainty,
                pressures_pa,
                &inverse::Options::default().axisym,
            );
            verdicts(&comparison, &runs, &band)
        })
        .unwrap_or_default();
    Some(PaperChain {
        law: f.model.label(),
        runs,
        comparison,
        verdicts,
    })
}
