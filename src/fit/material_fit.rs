//! The fit stage as one entry: stress/strain data and settings -> a fitted
//! [`Material`] whose provenance ([`Provenance`]) says what was fitted to
//! what, how well, and what to watch out for. `bulge fit` and the fit stage
//! of `bulge run` both call [`fit_material`], and both correct the law to the
//! measured heights through [`FittedMaterial::refine_to_heights`].

use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::data::{Loaded, Source, effective_std};
use super::hyperelastic::{self, HyperFit, Kind};
use super::quartic::{self, PolyFit};
use super::{FitError, StressMeasure, inverse};
use crate::experiment::Specimen;
use crate::material::{Material, Model};
use crate::mechanics::{Modulus, ModulusStress};

#[cfg(test)]
mod tests;

/// The model the fit stage fits. In settings files it is written by name
/// (`fit = "mooney-rivlin"`; see [`FitModel::NAMES`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum FitModel {
    /// The polynomial secant modulus `E(eps) = sum c_k eps^k` of this degree
    /// (4: the quartic of Tudruj et al. 2023), fitted to the secant modulus.
    Quartic {
        /// Polynomial degree, 1 to 8.
        degree: usize,
    },
    /// One incompressible hyperelastic model, fitted to the equibiaxial stress.
    Hyperelastic(Kind),
    /// Every hyperelastic model (Ogden with 1, 2 and 3 terms); the one with
    /// the lowest AICc among the Drucker-stable fits is kept.
    AllHyperelastic,
    /// Every law (the polynomial modulus and each hyperelastic model),
    /// corrected to the heights, the one they call for chosen
    /// ([`super::select`]): `bulge run`'s default. [`fit_material`] alone
    /// cannot choose (it has no heights) and refuses it.
    Auto,
}

impl Default for FitModel {
    fn default() -> Self {
        FitModel::Quartic { degree: 4 }
    }
}

impl FitModel {
    /// The names [`FromStr`] accepts.
    pub const NAMES: &'static str = "quartic, neo-hookean, mooney-rivlin, yeoh, ogden-1, ogden-2, ogden-3 (or ogden), gent, all, auto";

    /// Display name: `quartic`, `polynomial E(eps) of degree N`, `ogden-3`, `all`.
    pub fn label(&self) -> String {
        match self {
            FitModel::Quartic { degree: 4 } => "quartic".into(),
            FitModel::Quartic { degree } => format!("polynomial E(eps) of degree {degree}"),
            FitModel::Hyperelastic(k) => k.label(),
            FitModel::AllHyperelastic => "all".into(),
            FitModel::Auto => "auto".into(),
        }
    }

    /// The same model with the polynomial degree set (other models unchanged).
    pub fn with_degree(self, degree: usize) -> FitModel {
        match self {
            FitModel::Quartic { .. } => FitModel::Quartic { degree },
            m => m,
        }
    }
}

/// Parses `quartic`, `neo-hookean`, `mooney-rivlin`, `yeoh`, `ogden-N`
/// (`ogden`: three terms), `gent`, `all` or `auto`; the quartic has degree 4.
/// A fit model name that is not one of [`FitModel::NAMES`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{0}` is not one of {names}", names = FitModel::NAMES)]
pub struct UnknownFitModel(pub String);

impl FromStr for FitModel {
    type Err = UnknownFitModel;

    fn from_str(s: &str) -> Result<Self, UnknownFitModel> {
        let s = s.trim();
        match s {
            "quartic" => Ok(FitModel::Quartic { degree: 4 }),
            "all" => Ok(FitModel::AllHyperelastic),
            "auto" => Ok(FitModel::Auto),
            "ogden" => Ok(FitModel::Hyperelastic(Kind::Ogden(3))),
            _ => Kind::all()
                .into_iter()
                .find(|k| k.label() == s)
                .map(FitModel::Hyperelastic)
                .ok_or_else(|| UnknownFitModel(s.to_string())),
        }
    }
}

impl TryFrom<String> for FitModel {
    type Error = UnknownFitModel;

    fn try_from(s: String) -> Result<Self, UnknownFitModel> {
        s.parse()
    }
}

impl From<FitModel> for String {
    fn from(m: FitModel) -> String {
        match m {
            FitModel::Quartic { .. } => "quartic".into(),
            m => m.label(),
        }
    }
}

impl fmt::Display for FitModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label())
    }
}

/// The settings of the fit stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSettings {
    /// The model (default: the quartic secant modulus).
    pub model: FitModel,
    /// Poisson ratio written to the material (the mass-spring models read
    /// it), in [0, 0.5). Default 0.45.
    pub poisson: f64,
    /// The secant modulus convention of the data (default biaxial).
    pub modulus: Modulus,
    /// The stress the secant modulus was built from, when known (recorded).
    pub modulus_stress: Option<ModulusStress>,
    /// Lower the polynomial degree to `points - 1` when there are too few
    /// points for it (with a warning) instead of refusing the data.
    pub lower_degree: bool,
    /// Weight every point by its standard deviation, carried from its
    /// height's (the effective variance, [`super::data::effective_std`]),
    /// when the data carry them; else fitted unweighted with a warning.
    pub weighted: bool,
}

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            model: FitModel::default(),
            poisson: 0.45,
            modulus: Modulus::Biaxial,
            modulus_stress: None,
            lower_degree: false,
            weighted: false,
        }
    }
}

/// Where a material came from: the data, the fit's quality, its warnings and
/// the correction to the heights (`[fit]` of `material.toml`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Provenance {
    /// The input (a file name, or the stage that made the data).
    #[serde(default)]
    pub source: String,
    /// What kind of input it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_kind: Option<String>,
    /// Which columns were fitted.
    #[serde(default)]
    pub data: String,
    /// Points fitted.
    #[serde(default)]
    pub points: usize,
    /// Rows left out at zero strain (no secant modulus there).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points_skipped_zero_strain: Option<usize>,
    /// Polynomial degree (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub degree: Option<usize>,
    /// Secant modulus convention (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modulus_convention: Option<Modulus>,
    /// Stress in the secant modulus, when known (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modulus_stress: Option<ModulusStress>,
    /// Stress measure fitted (hyperelastic models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress_measure: Option<StressMeasure>,
    /// The hyperelastic model kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted: Option<String>,
    /// Root-mean-square residual, Pa.
    #[serde(default)]
    pub rmse_pa: f64,
    /// Coefficient of determination (none when the data do not vary).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r2: Option<f64>,
    /// Akaike information criterion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aic: Option<f64>,
    /// Small-sample AIC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aicc: Option<f64>,
    /// Condition number of the scaled Vandermonde matrix (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condition_number: Option<f64>,
    /// Condition number of the unscaled Vandermonde matrix (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condition_number_unscaled: Option<f64>,
    /// Standard errors of the coefficients, Pa (modulus law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_errors_pa: Option<Vec<f64>>,
    /// How the points were weighted, when they were.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<String>,
    /// The weighted residuals' sum of squares per degree of freedom (about
    /// 1 when the heights' standard deviations are right and the law fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chi2_per_dof: Option<f64>,
    /// Drucker stability inside the fitted range (hyperelastic models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drucker_stable: Option<bool>,
    /// Stretch range of the Drucker check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drucker_stretch_range: Option<[f64; 2]>,
    /// Starts of the nonlinear least squares.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub starts: Option<usize>,
    /// How the model was chosen among several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selected_by: Option<String>,
    /// What to watch out for.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Standard errors per parameter (hyperelastic models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_errors: Option<BTreeMap<String, f64>>,
    /// The correction to the measured heights, when made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refined: Option<RefinedRecord>,
}

/// `[fit.refined]`: the correction of the law to the measured heights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefinedRecord {
    /// The method.
    pub method: String,
    /// Root-mean-square relative height error of the law before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_rms_before: Option<f64>,
    /// The same after.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_rms_after: Option<f64>,
    /// Levenberg-Marquardt iterations.
    #[serde(default)]
    pub iterations: u64,
    /// Axisymmetric solves spent.
    #[serde(default)]
    pub axisym_solves: usize,
    /// The law fitted to the stress/strain points, before the correction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cap_law: Option<Model>,
    /// What the correction was held to, if anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint: Option<String>,
    /// The stress-free dome height found beside the law, m (a slack
    /// membrane), when it was sought.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prebulge_height_m: Option<f64>,
    /// The corrected parameters' standard errors, 95 % intervals,
    /// covariance and the share of each source
    /// ([`super::uncertainty::ParamUncertainty::toml_table`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<toml::Table>,
}

impl RefinedRecord {
    /// The record of a correction that started from `cap`.
    pub fn of(r: &inverse::Refined, cap: &Model) -> RefinedRecord {
        RefinedRecord {
            method: match (&r.window, r.weighted) {
                (None, false) => "parameters corrected so that the exact axisymmetric inflation reproduces the measured heights (least squares of h_sim / h - 1)".into(),
                (None, true) => "parameters corrected so that the exact axisymmetric inflation reproduces the measured heights (least squares of (h_sim - h) / sigma, sigma the point's standard deviation)".into(),
                (Some(w), _) => format!("parameters corrected so that the membrane model (constant-strain triangles) on the {w} reproduces the measured heights (least squares of h_sim / h - 1; {} membrane sweeps)", r.solves),
            },
            height_rms_before: inverse::Refined::rms(&r.before),
            height_rms_after: inverse::Refined::rms(&r.after),
            iterations: r.iterations,
            axisym_solves: if r.window.is_none() { r.solves } else { 0 },
            cap_law: Some(cap.clone()),
            constraint: r.constraint.clone(),
            prebulge_height_m: r.prebulge_height_m,
            uncertainty: r.uncertainty.as_ref().map(|u| {
                let mut t = u.toml_table();
                if let Some(mc) = &r.monte_carlo {
                    t.insert("monte_carlo".into(), mc.toml_table().into());
                }
                t
            }),
        }
    }
}

/// The fit itself.
#[derive(Debug, Clone)]
pub enum FitDetail {
    /// The polynomial modulus law.
    Quartic(PolyFit),
    /// Hyperelastic fits (one, or every model with `all`) and the one kept.
    Hyper {
        /// Every model fitted.
        fits: Vec<HyperFit>,
        /// Index of the one kept.
        best: usize,
    },
}

impl FitDetail {
    /// The hyperelastic fit kept, if the fit was hyperelastic.
    pub fn chosen_hyper(&self) -> Option<&HyperFit> {
        match self {
            FitDetail::Hyper { fits, best } => fits.get(*best),
            FitDetail::Quartic(_) => None,
        }
    }
}

/// The output of [`fit_material`].
#[derive(Debug, Clone)]
pub struct FittedMaterial {
    /// The material, with its [`Provenance`] in `fit`.
    pub material: Material,
    /// The fit.
    pub detail: FitDetail,
    /// The model actually fitted (the degree may have been lowered).
    pub model: FitModel,
    /// The law as the points gave it, before any correction to the heights.
    pub cap_material: Material,
    /// The correction to the heights, when made.
    pub refined: Option<inverse::Refined>,
    /// Models of `all` that could not be fitted, with the reason.
    pub skipped: Vec<String>,
    /// Warnings about the law (also in the provenance).
    pub warnings: Vec<String>,
    /// The quartic's degree lowered to what the points can determine.
    pub degree_lowered: Option<DegreeLowered>,
}

/// The quartic's degree lowered because the points were too few for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("only {points} points with a secant modulus: degree lowered from {from} to {to}")]
pub struct DegreeLowered {
    /// Points with a secant modulus.
    pub points: usize,
    /// The degree asked for.
    pub from: usize,
    /// The degree fitted.
    pub to: usize,
}

impl FittedMaterial {
    /// The provenance of the material.
    pub fn provenance(&self) -> &Provenance {
        self.material
            .fit
            .as_ref()
            .expect("a fitted material has its provenance")
    }

    fn provenance_mut(&mut self) -> &mut Provenance {
        self.material
            .fit
            .as_mut()
            .expect("a fitted material has its provenance")
    }

    /// Corrects the law until the exact axisymmetric inflation of `specimen`
    /// reproduces `measured` ([`inverse::refine`]); the material and its
    /// provenance then hold the corrected law, and a quartic that softens
    /// inside its range gets a warning.
    pub fn refine_to_heights(
        &mut self,
        specimen: &Specimen,
        measured: &[inverse::Measured],
        opts: &inverse::Options,
    ) -> Result<&inverse::Refined, FitError> {
        let r = inverse::refine(&self.cap_material, specimen, measured, opts)?;
        Ok(self.adopt(r))
    }

    /// As [`FittedMaterial::refine_to_heights`] for a non-circular window:
    /// the heights of the membrane model on `scene` (its geometry and
    /// thickness; meshed at `mesh`, default the scene's) reproduce
    /// `measured` ([`inverse::refine_in_scene`]).
    pub fn refine_in_scene(
        &mut self,
        scene: &crate::sim::scene::Scene,
        mesh: Option<crate::sim::scene::MeshSize>,
        measured: &[inverse::Measured],
        opts: &inverse::Options,
    ) -> Result<&inverse::Refined, FitError> {
        let r = inverse::refine_in_scene(&self.cap_material, scene, mesh, measured, opts)?;
        Ok(self.adopt(r))
    }

    /// Adds the Monte Carlo of the correction's parameters (`samples`
    /// tests drawn from the corrected law, seeded by `seed`) to the
    /// correction and its record; nothing when there is no correction.
    pub fn monte_carlo(
        &mut self,
        specimen: &Specimen,
        measured: &[inverse::Measured],
        opts: &inverse::Options,
        samples: usize,
        seed: u64,
    ) -> Result<(), FitError> {
        let Some(r) = self.refined.as_mut() else {
            return Ok(());
        };
        let mc = super::monte_carlo::monte_carlo(r, specimen, measured, opts, samples, seed)?;
        r.monte_carlo = Some(mc);
        let record = RefinedRecord::of(r, &self.cap_material.model);
        self.provenance_mut().refined = Some(record);
        Ok(())
    }

    /// Takes a correction's law and records it.
    fn adopt(&mut self, r: inverse::Refined) -> &inverse::Refined {
        let record = RefinedRecord::of(&r, &self.cap_material.model);
        if let Model::Quartic {
            coefficients_pa,
            strain_range,
            ..
        } = &r.material.model
        {
            let extra: Vec<String> = quartic::check_law(coefficients_pa, *strain_range)
                .iter()
                .map(|w| format!("corrected law: {w}"))
                .collect();
            self.warnings.extend(extra.iter().cloned());
            self.provenance_mut().warnings.extend(extra);
        }
        if let Some(u) = &r.uncertainty
            && let Some(w) = u.misfit_warning()
        {
            self.warnings.push(w.clone());
            self.provenance_mut().warnings.push(w);
        }
        self.material.model = r.material.model.clone();
        self.provenance_mut().refined = Some(record);
        self.refined.insert(r)
    }

    /// Adds a warning to the material and its provenance.
    pub fn warn(&mut self, w: String) {
        self.provenance_mut().warnings.push(w.clone());
        self.warnings.push(w);
    }
}

/// Fits `settings.model` to `data` (a `stress_strain.csv` of the stress
/// stage, or raw equibiaxial data; see [`super::data`]).
///
/// The modulus law is fitted to the rows with a secant modulus (rows at zero
/// strain have none and are skipped); the hyperelastic models to the
/// equibiaxial stretch and stress. `source` names the input in the
/// provenance.
pub fn fit_material(
    data: &Loaded,
    settings: &FitSettings,
    source: &str,
) -> Result<FittedMaterial, FitError> {
    if !(0.0..0.5).contains(&settings.poisson) {
        return Err(FitError::Unsupported(format!(
            "Poisson ratio {} is outside [0, 0.5): give the specimen's (0.45 for latex; 0.5 is excluded)",
            settings.poisson
        )));
    }
    if settings.model == FitModel::Auto {
        return Err(FitError::Unsupported(
            "fit model `auto` chooses among the laws by how well each reproduces the measured heights, which this fit does not have: run `bulge run` (it chooses), or name a model".into(),
        ));
    }
    let mut prov = Provenance {
        source: source.to_string(),
        input_kind: Some(
            match data.source {
                Source::StressStage => "stress_strain.csv of bulge stress",
                Source::Raw => "raw equibiaxial stretch and stress",
            }
            .into(),
        ),
        ..Provenance::default()
    };
    let mut warnings = Vec::new();
    let mut model_used = settings.model;
    let mut degree_lowered = None;
    let mut skipped = Vec::new();
    // How the fitted points move with their heights, when weighted: the
    // modulus law's `(strain, modulus)`, the hyperelastic `(stretch, stress)`.
    let shifts = if settings.weighted {
        let shifts = match settings.model {
            FitModel::Quartic { .. } => data.modulus_shifts(),
            _ => data.stress_shifts(),
        };
        match shifts {
            Some(_) => prov.weights = Some(WEIGHTS.into()),
            None => warnings.push(UNWEIGHTED.into()),
        }
        shifts
    } else {
        None
    };
    let (model, detail) = match settings.model {
        FitModel::Quartic { degree } => {
            let (strain, modulus) = data.modulus_points();
            let mut degree = degree;
            if settings.lower_degree && strain.len() >= 2 && strain.len() <= degree {
                let lowered = DegreeLowered {
                    points: strain.len(),
                    from: degree,
                    to: strain.len() - 1,
                };
                warnings.push(lowered.to_string());
                degree_lowered = Some(lowered);
                degree = strain.len() - 1;
                model_used = FitModel::Quartic { degree };
            }
            let mut f = quartic::fit(&strain, &modulus, degree)?;
            if let Some(shifts) = &shifts {
                f = reweighted(
                    f,
                    (shifts, &strain),
                    |f, e| quartic::eval_derivative(&f.coefficients_pa, e),
                    |sd| quartic::fit_weighted(&strain, &modulus, degree, Some(sd)),
                )?;
            }
            prov.chi2_per_dof = f.chi2_per_dof;
            warnings.extend(f.warnings.iter().map(|w| w.to_string()));
            if f.condition_scaled > 1e8 {
                warnings.push(format!(
                    "the scaled Vandermonde matrix has condition number {:.2e}: the coefficients are poorly determined; lower the degree",
                    f.condition_scaled
                ));
            }
            prov.data = "strain, secant_modulus_pa".into();
            prov.points = f.stats.n;
            prov.points_skipped_zero_strain =
                Some(data.modulus_pa.iter().filter(|m| m.is_none()).count());
            prov.degree = Some(degree);
            prov.modulus_convention = Some(settings.modulus);
            prov.modulus_stress = settings.modulus_stress;
            prov.rmse_pa = f.stats.rmse;
            prov.r2 = Some(f.stats.r2).filter(|v| v.is_finite());
            prov.aic = Some(f.stats.aic);
            prov.condition_number = Some(f.condition_scaled);
            prov.condition_number_unscaled = Some(f.condition_raw);
            prov.std_errors_pa = f.std_errors_pa.clone();
            let model = Model::Quartic {
                coefficients_pa: f.coefficients_pa.clone(),
                strain_range: f.strain_range,
                strain_measure: data.strain_measure,
            };
            (model, FitDetail::Quartic(f))
        }
        FitModel::Hyperelastic(kind) => {
            let f = fit_hyper(kind, data, shifts.as_deref())?;
            (
                f.model.clone(),
                FitDetail::Hyper {
                    fits: vec![f],
                    best: 0,
                },
            )
        }
        FitModel::Auto => unreachable!("`auto` is refused above"),
        FitModel::AllHyperelastic => {
            let mut fits = Vec::new();
            for kind in Kind::all() {
                match fit_hyper(kind, data, shifts.as_deref()) {
                    Ok(f) => fits.push(f),
                    Err(e @ FitError::TooFewPoints { .. }) => {
                        skipped.push(format!("{}: {e}", kind.label()))
                    }
                    Err(FitError::Solver(e)) => {
                        skipped.push(format!("{}: solver failed: {e}", kind.label()))
                    }
                    Err(e) => return Err(e),
                }
            }
            if fits.is_empty() {
                return Err(FitError::Unsupported(format!(
                    "no model could be fitted: {}",
                    skipped.join("; ")
                )));
            }
            let best = select_by_aicc(&fits);
            prov.selected_by = Some("lowest AICc among the Drucker-stable fits".into());
            (fits[best].model.clone(), FitDetail::Hyper { fits, best })
        }
    };
    if let FitDetail::Hyper { fits, best } = &detail {
        for f in fits {
            if !f.drucker.stable {
                let at: Vec<String> = f
                    .drucker
                    .first_unstable
                    .iter()
                    .map(|(m, l)| format!("{} from stretch {l:.3}", m.name()))
                    .collect();
                warnings.push(format!(
                    "{}: not Drucker-stable inside the fitted range ({})",
                    f.kind.label(),
                    at.join(", ")
                ));
            }
            if f.stats.n > f.kind.n_params() && f.params.iter().any(|p| p.std_error.is_none()) {
                warnings.push(format!(
                    "{}: the Jacobian is singular at the optimum, so some parameters are not determined by these data \
                     (no standard errors); a model with fewer parameters fits as well",
                    f.kind.label()
                ));
            }
        }
        let chosen = &fits[*best];
        prov.data = format!("stretch, {}", data.stress_column);
        prov.stress_measure = Some(data.equibiaxial.measure);
        prov.fitted = Some(chosen.kind.label());
        prov.points = chosen.stats.n;
        prov.rmse_pa = chosen.stats.rmse;
        prov.r2 = Some(chosen.stats.r2).filter(|v| v.is_finite());
        prov.aic = Some(chosen.stats.aic);
        prov.aicc = chosen.stats.aicc;
        prov.std_errors = Some(
            chosen
                .params
                .iter()
                .filter_map(|p| p.std_error.map(|e| (p.name.clone(), e)))
                .collect(),
        );
        prov.chi2_per_dof = chosen.chi2_per_dof;
        prov.drucker_stable = Some(chosen.drucker.stable);
        prov.drucker_stretch_range = Some(chosen.drucker.range);
        prov.starts = Some(chosen.starts);
    }
    warnings.extend(skipped.iter().map(|s| format!("skipped {s}")));
    if !prov.rmse_pa.is_finite() {
        return Err(FitError::Unsupported(format!(
            "the fit's residuals are not finite (RMSE {} Pa): the data are beyond double precision; check the units",
            prov.rmse_pa
        )));
    }
    prov.warnings = warnings.clone();
    let cap_material = Material {
        model,
        poisson: settings.poisson,
        fit: None,
    };
    let mut material = cap_material.clone();
    material.fit = Some(prov);
    Ok(FittedMaterial {
        material,
        detail,
        model: model_used,
        cap_material,
        refined: None,
        skipped,
        warnings,
        degree_lowered,
    })
}

/// Weighted fits: the unweighted fit, then this many refits, each weighted
/// by the effective standard deviations of the last one's law (they depend
/// on its slope; two refits change them by well under a percent).
const REWEIGHTS: usize = 2;

/// `weights` of the provenance of a weighted fit.
const WEIGHTS: &str = "inverse variance of each point, carried from its height's standard deviation along the law (effective variance)";

/// The warning when a weighted fit was asked of data without shifts.
const UNWEIGHTED: &str = "a weighted fit was asked but not every row carries its height's uncertainty \
     with the signs of its errors (give `bulge stress --height-std-m`, or heights with a height_std_m \
     value on every row; a stress_strain.csv needs its *_std and *_corr columns): fitted unweighted";

/// The weighted fit from the unweighted `first`: [`REWEIGHTS`] times, the
/// points' effective standard deviations from the last fit's slope
/// (`slope(fit, x)`) at the points `x` moving by `shifts`, and `refit` with
/// them.
fn reweighted<F>(
    first: F,
    (shifts, x): (&[(f64, f64)], &[f64]),
    slope: impl Fn(&F, f64) -> f64,
    refit: impl Fn(&[f64]) -> Result<F, FitError>,
) -> Result<F, FitError> {
    let mut f = first;
    for _ in 0..REWEIGHTS {
        let sd = effective_std(shifts, x, |v| slope(&f, v));
        f = refit(&sd)?;
    }
    Ok(f)
}

/// `kind` fitted to the equibiaxial data, weighted (see [`reweighted`])
/// when the rows' `(stretch, stress)` shifts are given.
fn fit_hyper(
    kind: Kind,
    data: &Loaded,
    shifts: Option<&[(f64, f64)]>,
) -> Result<HyperFit, FitError> {
    let eq = &data.equibiaxial;
    let f = hyperelastic::fit(kind, eq)?;
    let Some(shifts) = shifts else {
        return Ok(f);
    };
    reweighted(
        f,
        (shifts, &eq.stretch),
        |f, l| {
            let d = 1e-6 * l;
            (eq.predict(&f.model, l + d) - eq.predict(&f.model, l - d)) / (2.0 * d)
        },
        |sd| hyperelastic::fit_weighted(kind, eq, Some(sd)),
    )
}

/// Lowest AICc among the Drucker-stable fits, else among all. A model with
/// `n <= k + 1` has no AICc (it can interpolate the data): it ranks after
/// every model that has one, by AIC among its kind.
fn select_by_aicc(fits: &[HyperFit]) -> usize {
    let score = |f: &HyperFit| match f.stats.aicc {
        Some(a) => (0, a),
        None => (1, f.stats.aic),
    };
    let pick = |stable_only: bool| {
        fits.iter()
            .enumerate()
            .filter(|(_, f)| !stable_only || f.drucker.stable)
            .min_by(|a, b| {
                let (sa, sb) = (score(a.1), score(b.1));
                sa.0.cmp(&sb.0).then(sa.1.total_cmp(&sb.1))
            })
            .map(|(i, _)| i)
    };
    pick(true).or_else(|| pick(false)).unwrap_or(0)
}
