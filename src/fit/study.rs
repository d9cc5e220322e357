//! A material across specimens: every specimen's law corrected to its own
//! heights (in parallel, each with its covariance), then the parameters'
//! mean, standard deviation and coefficient of variation over the
//! specimens, the 95 % interval of the mean (Student's t with `n - 1`
//! degrees of freedom: the specimens' scatter, material and preparation
//! alike, is what the mean is uncertain by), an inverse-variance pooled
//! value, and the specimens that stand out flagged.
//!
//! A specimen is flagged on a parameter when it lies outside the 99 %
//! prediction interval of the others, `|x_j - mean_-j| > t(0.995, n - 2)
//! s_-j sqrt(1 + 1 / (n - 1))` (the mean and standard deviation of the
//! other `n - 1` specimens; needs four specimens or more): a new specimen
//! of the same population falls outside it 1 % of the time (D. C.
//! Montgomery and G. C. Runger, Applied Statistics and Probability for
//! Engineers, Wiley, 2014, section 8.7, prediction interval for a future
//! observation).

use rayon::prelude::*;

use super::FitError;
use super::inverse::{self, Measured};
use super::uncertainty::student_t_quantile;
use crate::experiment::Specimen;
use crate::material::Material;

/// One specimen of a study.
#[derive(Debug, Clone)]
pub struct StudyInput {
    /// Its name (the experiment file, say).
    pub name: String,
    /// Its nominal dimensions.
    pub specimen: Specimen,
    /// Its measured heights.
    pub measured: Vec<Measured>,
    /// Its inputs' uncertainties besides the heights' own.
    pub options: inverse::Options,
}

/// One specimen's corrected parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecimenFit {
    /// The specimen's name.
    pub name: String,
    /// The parameters.
    pub values: Vec<f64>,
    /// Their standard errors (first order), when found.
    pub std_errors: Option<Vec<f64>>,
    /// Per parameter, whether the specimen stands out from the others.
    pub outlier: Vec<bool>,
}

/// The material across the specimens.
#[derive(Debug, Clone, PartialEq)]
pub struct Study {
    /// Parameter names.
    pub names: Vec<String>,
    /// Per specimen.
    pub specimens: Vec<SpecimenFit>,
    /// Mean over the specimens.
    pub mean: Vec<f64>,
    /// Sample standard deviation over the specimens.
    pub std: Vec<f64>,
    /// Coefficient of variation `std / |mean|`.
    pub cv: Vec<f64>,
    /// 95 % interval of the mean.
    pub mean_ci95: Vec<[f64; 2]>,
    /// Inverse-variance weighted mean of the specimens' values (when every
    /// specimen has standard errors), and its standard error from theirs.
    pub pooled: Option<(Vec<f64>, Vec<f64>)>,
}

/// Corrects `start` to each specimen's heights and gathers the material
/// across them (see the module docs). At least two specimens.
pub fn study(inputs: &[StudyInput], start: &Material) -> Result<Study, FitError> {
    if inputs.len() < 2 {
        return Err(FitError::Unsupported(format!(
            "a study needs two specimens or more, {} given",
            inputs.len()
        )));
    }
    let fits: Vec<Result<inverse::Refined, FitError>> = inputs
        .par_iter()
        .map(|s| inverse::refine(start, &s.specimen, &s.measured, &s.options))
        .collect();
    let mut specimens = Vec::new();
    let mut names = Vec::new();
    for (s, f) in inputs.iter().zip(fits) {
        let r = f.map_err(|e| match e {
            FitError::Solver(m) => FitError::Solver(format!("specimen {}: {m}", s.name)),
            e => FitError::Unsupported(format!("specimen {}: {e}", s.name)),
        })?;
        let (n, values, _) = inverse::law_parameters(&r.material.model)
            .ok_or_else(|| FitError::Unsupported("the law has no parameters".into()))?;
        names = n;
        specimens.push(SpecimenFit {
            name: s.name.clone(),
            std_errors: r.uncertainty.as_ref().map(|u| u.std_errors()),
            outlier: vec![false; values.len()],
            values,
        });
    }
    gather(names, specimens)
}

/// The material across specimens already fitted (each [`SpecimenFit`]'s
/// `values` and `std_errors` in the order of `names`; its `outlier` is
/// set here): the statistics of [`study`] without the fits, for a caller
/// that corrected each specimen's law itself (`bulge study` does, through
/// the whole pipeline). At least two specimens, all with `names.len()`
/// values.
pub fn gather(names: Vec<String>, mut specimens: Vec<SpecimenFit>) -> Result<Study, FitError> {
    if specimens.len() < 2 {
        return Err(FitError::Unsupported(format!(
            "a study needs two specimens or more, {} given",
            specimens.len()
        )));
    }
    for s in &specimens {
        let se = s.std_errors.as_ref().map_or(names.len(), Vec::len);
        if s.values.len() != names.len() || se != names.len() {
            return Err(FitError::Unsupported(format!(
                "specimen {}: {} values (and {se} standard errors) for the {} parameters {}: every specimen must be fitted with the same law",
                s.name,
                s.values.len(),
                names.len(),
                names.join(", ")
            )));
        }
    }
    let n = specimens.len();
    let p = names.len();
    let col = |k: usize, skip: Option<usize>| -> Vec<f64> {
        specimens
            .iter()
            .enumerate()
            .filter(|(j, _)| Some(*j) != skip)
            .map(|(_, s)| s.values[k])
            .collect()
    };
    let mean_std = |v: &[f64]| {
        let m = v.len() as f64;
        let mean = v.iter().sum::<f64>() / m;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m - 1.0)).sqrt();
        (mean, sd)
    };
    let t = student_t_quantile(0.975, (n - 1) as f64);
    // flags[k][j]: specimen j stands out on parameter k.
    let mut flags: Vec<Vec<bool>> = Vec::with_capacity(p);
    let (mut mean, mut std, mut cv, mut mean_ci95) = (vec![], vec![], vec![], vec![]);
    for k in 0..p {
        let (m, s) = mean_std(&col(k, None));
        mean.push(m);
        std.push(s);
        cv.push(s / m.abs());
        let half = t * s / (n as f64).sqrt();
        mean_ci95.push([m - half, m + half]);
        let tp = student_t_quantile(0.995, n.saturating_sub(2) as f64);
        flags.push(
            (0..n)
                .map(|j| {
                    if n < 4 {
                        return false;
                    }
                    let (mo, so) = mean_std(&col(k, Some(j)));
                    let bound = tp * so * (1.0 + 1.0 / (n - 1) as f64).sqrt();
                    (specimens[j].values[k] - mo).abs() > bound
                })
                .collect(),
        );
    }
    for (j, s) in specimens.iter_mut().enumerate() {
        s.outlier = flags.iter().map(|f| f[j]).collect();
    }
    let pooled = specimens
        .iter()
        .map(|s| s.std_errors.clone())
        .collect::<Option<Vec<Vec<f64>>>>()
        .map(|se| {
            (0..p)
                .map(|k| {
                    let w: Vec<f64> = se.iter().map(|s| 1.0 / (s[k] * s[k])).collect();
                    let sw: f64 = w.iter().sum();
                    let v = specimens
                        .iter()
                        .zip(&w)
                        .map(|(s, w)| w * s.values[k])
                        .sum::<f64>()
                        / sw;
                    (v, 1.0 / sw.sqrt())
                })
                .unzip()
        });
    Ok(Study {
        names,
        specimens,
        mean,
        std,
        cv,
        mean_ci95,
        pooled,
    })
}

/// One law fitted to every specimen's heights together.
#[derive(Debug, Clone, PartialEq)]
pub struct JointFit {
    /// Parameter names, as [`Study::names`].
    pub names: Vec<String>,
    /// The joint law's parameters.
    pub values: Vec<f64>,
    /// Their standard errors, cluster-robust by specimen, when known.
    pub std_errors: Option<Vec<f64>>,
    /// The fit itself (the law, the heights' RMS relative error before and
    /// after).
    pub refined: inverse::JointRefined,
}

/// One law fitted to every specimen's heights at once, each specimen with
/// its own dimensions ([`inverse::refine_joint`]): a pooled estimate beside
/// the inverse-variance mean of [`study`], which weighs each specimen by
/// its own law's standard errors. The points of every specimen weigh
/// alike (relative errors), so a specimen with more photos counts more. At
/// least two specimens; `inputs`' options besides the solver's are not
/// used. The standard errors are cluster-robust by specimen (see
/// [`inverse::refine_joint`]).
pub fn joint(inputs: &[StudyInput], start: &Material) -> Result<JointFit, FitError> {
    if inputs.len() < 2 {
        return Err(FitError::Unsupported(format!(
            "a joint fit needs two specimens or more, {} given",
            inputs.len()
        )));
    }
    let data: Vec<(Specimen, Vec<Measured>)> = inputs
        .iter()
        .map(|s| (s.specimen, s.measured.clone()))
        .collect();
    let refined = inverse::refine_joint(start, &data, &inputs[0].options)?;
    let (names, values, _) = inverse::law_parameters(&refined.material.model)
        .ok_or_else(|| FitError::Unsupported("the law has no parameters".into()))?;
    Ok(JointFit {
        names,
        values,
        std_errors: refined.std_errors.clone(),
        refined,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::monte_carlo::draw;
    use crate::fit::uncertainty::Sources;
    use crate::material::Model;
    use crate::numerics::Rng;

    /// The Mooney-Rivlin law of the joint-fit tests (C1 = 0.12 MPa, C2 =
    /// 0.03 MPa).
    fn mooney_rivlin() -> Material {
        Material {
            model: Model::MooneyRivlin {
                c1_pa: 0.12e6,
                c2_pa: 0.03e6,
            },
            poisson: 0.45,
            fit: None,
        }
    }

    /// The exact heights of `law` on `real` at 800, 1400, ... 3800 Pa, each
    /// times `1 + noise()`.
    fn heights(
        law: &Material,
        real: &Specimen,
        opts: &inverse::Options,
        mut noise: impl FnMut() -> f64,
    ) -> Vec<Measured> {
        (0..6)
            .map(|i| {
                let p = 800.0 + 600.0 * i as f64;
                let h = crate::axisym::solve_pressure(law, real, p, &opts.axisym)
                    .unwrap()
                    .height_m;
                Measured {
                    pressure_pa: p,
                    height_m: h * (1.0 + noise()),
                    height_std_m: None,
                }
            })
            .collect()
    }

    /// Heights of the exact inflation of one Mooney-Rivlin law (C1 = 0.12
    /// MPa, C2 = 0.03 MPa) on five specimens of different thicknesses (330
    /// to 370 um) and radii, noise-free: the joint fit from a start 20 %
    /// soft on C1 and 30 % stiff on C2 gives the law back (the truth is
    /// the one law that reproduces every specimen's heights with its own
    /// dimensions); the same heights with every specimen given one nominal
    /// thickness do not.
    #[test]
    fn joint_fit_recovers_one_law_from_specimens_of_different_thickness() {
        let truth = mooney_rivlin();
        let opts = inverse::Options::default();
        let make = |k: usize| {
            let specimen = Specimen {
                thickness_m: [3.5e-4, 3.3e-4, 3.7e-4, 3.4e-4, 3.6e-4][k],
                radius_m: [0.0375, 0.0370, 0.0380, 0.0375, 0.0372][k],
                ..Specimen::latex()
            };
            let measured = heights(&truth, &specimen, &opts, || 0.0);
            StudyInput {
                name: format!("s{k}"),
                specimen,
                measured,
                options: opts.clone(),
            }
        };
        let inputs: Vec<StudyInput> = (0..5).map(make).collect();
        let start = Material {
            model: Model::MooneyRivlin {
                c1_pa: 0.096e6,
                c2_pa: 0.039e6,
            },
            ..truth.clone()
        };
        let j = joint(&inputs, &start).unwrap();
        assert_eq!(j.names, ["c1_pa", "c2_pa"]);
        for (v, t) in j.values.iter().zip([0.12e6, 0.03e6]) {
            assert!((v / t - 1.0).abs() < 1e-4, "{:?}", j.values);
        }
        assert!(j.refined.rms_after.unwrap() < 1e-6, "{:?}", j.refined);
        let nominal: Vec<StudyInput> = inputs
            .iter()
            .map(|s| StudyInput {
                specimen: Specimen {
                    thickness_m: 3.5e-4,
                    ..s.specimen
                },
                ..s.clone()
            })
            .collect();
        let n = joint(&nominal, &start).unwrap();
        assert!(n.refined.rms_after.unwrap() > 1e-3, "{:?}", n.refined);
        assert!(joint(&inputs[..1], &start).is_err());
    }

    /// The joint fit's cluster-robust standard errors against the scatter
    /// of its estimates: five specimens whose true thicknesses differ from
    /// the stated 350 um by 3 % (one draw per specimen, shared by its
    /// points: the error the clustering is for) with 0.3 % independent
    /// height noise, 12 seeded repetitions. The mean standard error is
    /// within a factor 2 of the estimates' standard deviation, and most
    /// 95 % intervals hold the truth.
    #[test]
    fn joint_standard_errors_match_the_scatter_of_the_joint_fit() {
        let truth = mooney_rivlin();
        let opts = inverse::Options::default();
        let stated = Specimen {
            thickness_m: 3.5e-4,
            ..Specimen::latex()
        };
        let mut rng = Rng::new(77);
        let (mut est, mut se, mut held) = (Vec::new(), Vec::new(), 0);
        let reps = 12;
        for _ in 0..reps {
            let inputs: Vec<StudyInput> = (0..5)
                .map(|k| {
                    let real = Specimen {
                        thickness_m: stated.thickness_m * (1.0 + 0.03 * rng.normal()),
                        ..stated
                    };
                    let measured = heights(&truth, &real, &opts, || 0.003 * rng.normal());
                    StudyInput {
                        name: format!("s{k}"),
                        specimen: stated,
                        measured,
                        options: opts.clone(),
                    }
                })
                .collect();
            let j = joint(&inputs, &truth).unwrap();
            let e = j.std_errors.clone().unwrap();
            held += usize::from((j.values[0] - 0.12e6).abs() <= 1.96 * e[0]);
            est.push(j.values[0]);
            se.push(e[0]);
        }
        let mean = est.iter().sum::<f64>() / reps as f64;
        let sd = (est.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (reps as f64 - 1.0)).sqrt();
        let se_mean = se.iter().sum::<f64>() / reps as f64;
        eprintln!(
            "C1: sd of estimates {sd:.1} Pa, mean standard error {se_mean:.1} Pa, {held} of {reps} held"
        );
        assert!(
            se_mean > 0.5 * sd && se_mean < 2.0 * sd,
            "sd {sd}, se {se_mean}"
        );
        assert!(held >= 9, "{held} of {reps}");
    }

    fn given(name: &str, values: Vec<f64>, se: f64) -> SpecimenFit {
        SpecimenFit {
            name: name.into(),
            std_errors: Some(vec![se; values.len()]),
            outlier: vec![],
            values,
        }
    }

    /// The statistics of given fits against hand-computed ones: five values
    /// 1..5 (x 1e5 Pa) have mean 3e5, sample standard deviation
    /// sqrt(2.5) 1e5, and a 95 % interval of the mean of half-width
    /// t(0.975, 4) s / sqrt(5) with t(0.975, 4) = 2.776445 (Student's t
    /// table, Montgomery & Runger 2014, Table V); equal standard errors pool
    /// to the plain mean with se / sqrt(5). A value five times the others'
    /// scatter away is flagged; a specimen with a different law is refused.
    #[test]
    fn gathered_statistics_match_hand_computed_ones() {
        let fits: Vec<SpecimenFit> = (1..=5)
            .map(|i| given(&format!("s{i}"), vec![i as f64 * 1e5], 2e4))
            .collect();
        let s = gather(vec!["c1_pa".into()], fits.clone()).unwrap();
        let sd = 2.5f64.sqrt() * 1e5;
        assert!((s.mean[0] - 3e5).abs() < 1e-6);
        assert!((s.std[0] / sd - 1.0).abs() < 1e-12);
        assert!((s.cv[0] - sd / 3e5).abs() < 1e-12);
        let half = 2.776445 * sd / 5f64.sqrt();
        assert!((s.mean_ci95[0][1] - 3e5 - half).abs() < 1e-5 * half);
        assert!((3e5 - s.mean_ci95[0][0] - half).abs() < 1e-5 * half);
        let (pv, pse) = s.pooled.unwrap();
        assert!((pv[0] - 3e5).abs() < 1e-6 && (pse[0] - 2e4 / 5f64.sqrt()).abs() < 1e-9);
        assert!(s.specimens.iter().all(|f| f.outlier == [false]));

        let mut odd: Vec<SpecimenFit> = [1.0, 1.02, 0.98, 1.01, 0.99]
            .iter()
            .enumerate()
            .map(|(i, v)| given(&format!("s{i}"), vec![v * 1e5], 1e3))
            .collect();
        odd.push(given("odd", vec![1.5e5], 1e3));
        let s = gather(vec!["c1_pa".into()], odd).unwrap();
        assert!(s.specimens[5].outlier[0]);
        assert!(s.specimens[..5].iter().all(|f| !f.outlier[0]));

        let mut mixed = fits;
        mixed[2].values.push(1.0);
        let e = gather(vec!["c1_pa".into()], mixed).unwrap_err().to_string();
        assert!(e.contains("specimen s3") && e.contains("same law"), "{e}");
        let e = gather(vec!["c1_pa".into()], vec![given("a", vec![1.0], 1.0)]).unwrap_err();
        assert!(e.to_string().contains("two specimens"), "{e}");
    }

    /// Five specimens of one Mooney-Rivlin rubber whose thicknesses scatter
    /// by 3 % (each measured to 1 %), heights 30 um, gauge 0.5 %: the
    /// study's mean holds the truth within its own 95 % interval, the
    /// scatter is reported, no specimen is flagged; a sixth specimen of a
    /// rubber 40 % stiffer is flagged on C1.
    #[test]
    fn five_specimens_with_thickness_scatter() {
        let truth = Material {
            model: Model::MooneyRivlin {
                c1_pa: 0.12e6,
                c2_pa: 0.03e6,
            },
            poisson: 0.45,
            fit: None,
        };
        let base = Specimen::latex();
        let mut rng = Rng::new(31);
        let pressures: Vec<f64> = (0..8).map(|i| 600.0 + 350.0 * i as f64).collect();
        let mut make = |name: String, law: &Material| {
            let specimen = Specimen {
                thickness_m: base.thickness_m * (1.0 + 0.03 * rng.normal()),
                ..base
            };
            let sources = Sources {
                thickness_std_m: 0.01 * specimen.thickness_m,
                pressure_relative_std: 0.005,
                ..Sources::default()
            };
            let stds = vec![3e-5; pressures.len()];
            let data = draw(law, &specimen, &pressures, &stds, &sources, &mut rng).unwrap();
            StudyInput {
                name,
                specimen,
                measured: data.measured,
                options: inverse::Options {
                    uncertainty: sources,
                    ..inverse::Options::default()
                },
            }
        };
        let mut inputs: Vec<StudyInput> = (1..=5).map(|i| make(format!("s{i}"), &truth)).collect();
        let s = study(&inputs, &truth).unwrap();
        let theta = [0.12e6, 0.03e6];
        for (k, &th) in theta.iter().enumerate() {
            let [lo, hi] = s.mean_ci95[k];
            assert!(lo <= th && th <= hi, "{}: {lo}..{hi}", s.names[k]);
            assert!(s.cv[k] > 0.0 && s.cv[k] < 0.5, "{:?}", s.cv);
        }
        assert!(s.specimens.iter().all(|f| f.outlier.iter().all(|o| !o)));
        let (pooled, pooled_se) = s.pooled.clone().unwrap();
        assert!((pooled[0] / theta[0] - 1.0).abs() < 3.0 * pooled_se[0] / theta[0]);
        eprintln!("{s:?}");
        // one law fitted to the five specimens' heights together lands
        // inside the mean's interval too
        let j = joint(&inputs, &truth).unwrap();
        eprintln!("joint: {:?}", j.values);
        for (k, v) in j.values.iter().enumerate() {
            let [lo, hi] = s.mean_ci95[k];
            assert!(
                lo <= *v && *v <= hi,
                "{}: joint {v}, mean's interval {lo}..{hi}",
                s.names[k]
            );
        }
        let stiff = Material {
            model: Model::MooneyRivlin {
                c1_pa: 0.168e6,
                c2_pa: 0.03e6,
            },
            ..truth.clone()
        };
        inputs.push(make("stiff".into(), &stiff));
        let s6 = study(&inputs, &truth).unwrap();
        assert!(s6.specimens[5].outlier[0], "{:?}", s6.specimens[5]);
        assert!(s6.specimens[..5].iter().all(|f| !f.outlier[0]));
    }
}
