//! The coverage study through photos: each synthetic experiment is a
//! folder that `bulge run` could read, and it is fitted by the pipeline
//! itself ([`crate::pipeline::run`]: track, stress, fit with the correction
//! to the heights and its covariance, the exact inflation at the readings and
//! the heights' band).
//!
//! Experiment `i` draws the real sheet's thickness and radius about the
//! nominal ones, a gauge gain, a scale and a clamp-row error, and each
//! reading's noise, as [`super::draw`] does; then it renders the real
//! bubble's photos at the true pressures with `bulge synth`'s renderer
//! ([`crate::track::synth::write_sequence`]: a side view over a textured
//! background, Gaussian blur, sensor noise, 8-bit quantisation, JPEG), and
//! writes an experiment file that states what a laboratory would know: the
//! nominal specimen with `thickness_std_m` and `radius_std_m`, the gauge's
//! readings in `pressure.csv` with `std_pa` and `relative_std`, the
//! calibration as it was (mis)measured with `metres_per_pixel_std` and
//! `clamp_row_std_px`. The heights' own errors are the tracker's, with the
//! tracker's stated `height_std_m`; nothing about them is given by the plan.
//!
//! The experiments run in parallel on a pool of their own: the tracker
//! decodes its photos on rayon's global pool while the calling thread
//! matches them, so an experiment must not occupy a global worker while it
//! waits for its decoders.

use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use rayon::prelude::*;

use super::{Coverage, Judged, Rng};
use crate::experiment::{Experiment, PhotosConfig, PressureConfig, Specimen, Window};
use crate::fit::FitModel;
use crate::fit::inverse;
use crate::fit::uncertainty::Sources;
use crate::material::Material;
use crate::pipeline::{self, Settings};
use crate::track::image::Encoding;
use crate::track::synth::{self, Framing, Look, SequenceSpec};

/// What the camera makes of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Image width, px (the disc spans 70 % of it).
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// Gaussian blur standard deviation, px.
    pub blur_px: f64,
    /// Sensor noise standard deviation, grey levels of 255.
    pub noise_grey: f64,
    /// File format of the photos.
    pub encoding: Encoding,
}

/// What to simulate.
#[derive(Debug, Clone)]
pub struct PhotoPlan {
    /// The true law.
    pub truth: Material,
    /// The model the pipeline fits (the true law's, for coverage to mean
    /// anything).
    pub fit: FitModel,
    /// The nominal specimen (the real one is drawn about it).
    pub specimen: Specimen,
    /// The true pressures of the photos, Pa.
    pub pressures_pa: Vec<f64>,
    /// The errors besides the photos', drawn as they say and stated in the
    /// experiment file.
    pub sources: Sources,
    /// The camera.
    pub camera: Camera,
    /// Experiments.
    pub experiments: usize,
    /// Seed of the first experiment (experiment `i` uses `seed + i`, for
    /// its errors and for its scene and sensor noise).
    pub seed: u64,
    /// Weigh the correction by the points' standard deviations
    /// (`weighted = true` of `bulge run`).
    pub weighted: bool,
}

/// The counts of a photo plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PhotoCoverage {
    /// The intervals' and the band's counts over the experiments fitted with
    /// a covariance.
    pub coverage: Coverage,
    /// Experiments without a covariance (the run failed, or the correction
    /// did), with the reason; not counted above.
    pub failed: Vec<(usize, String)>,
    /// Photos tracked.
    pub photos: usize,
    /// RMS over the photos of (tracked height - the height a perfect
    /// tracker reads through the stated calibration) / stated
    /// `height_std_m`: about 1 when the tracker's stated uncertainty is the
    /// size of its error.
    pub height_z_rms: f64,
    /// Mean stated `height_std_m`, m.
    pub mean_height_std_m: f64,
}

/// One experiment as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The experiment file.
    pub experiment_toml: PathBuf,
    /// The real bubble's apex heights, m, per photo.
    pub true_heights_m: Vec<f64>,
    /// What a tracker without error reads, m, per photo: the true heights
    /// through the stated (wrong) scale and clamp row.
    pub ideal_readings_m: Vec<f64>,
}

/// Writes experiment `index` of `plan` into the folder `out` (photos,
/// `pressure.csv`, `truth.csv`, `experiment.toml`).
pub fn write_experiment(plan: &PhotoPlan, index: usize, out: &Path) -> anyhow::Result<Drawn> {
    let seed = plan.seed.wrapping_add(index as u64);
    let mut rng = Rng::new(seed);
    let s = &plan.sources;
    let nominal = plan.specimen;
    let crate::fit::monte_carlo::Shared {
        real,
        gain,
        scale,
        offset_m,
    } = crate::fit::monte_carlo::Shared::draw(s, &nominal, &mut rng);
    let mut frames = Vec::with_capacity(plan.pressures_pa.len());
    for &p in &plan.pressures_pa {
        let reading = p * gain + s.pressure_std_pa * rng.normal();
        frames.push(
            synth::axisym_frame(&plan.truth, &real, p, reading)
                .with_context(|| format!("the true law at {p} Pa"))?,
        );
    }
    let c = &plan.camera;
    let spec = SequenceSpec {
        width: c.width,
        height: c.height,
        seed,
        blur_px: c.blur_px,
        noise_grey: c.noise_grey,
        drift: 0.0,
        encoding: c.encoding,
        specimen: nominal,
        window: Window::Circle,
        framing: Framing::default(),
        look: Look::default(),
    };
    let w = synth::write_sequence(out, &spec, &frames)?;
    // The calibration as measured: a scale off by `scale`, a clamp row off
    // by `offset_m` (in the heights it gives).
    let mpp = w.scene.metres_per_pixel * scale;
    let mut stated = w.scene.clone();
    stated.metres_per_pixel = mpp;
    stated.clamp_row_px += offset_m / mpp;
    let mut file = synth::experiment_file(
        &spec,
        &stated,
        &w.layout,
        PhotosConfig::folder("photos", &format!("*.{}", c.encoding.extension())),
        PressureConfig {
            std_pa: Some(s.pressure_std_pa),
            relative_std: Some(s.pressure_relative_std),
            ..PressureConfig::file("pressure.csv")
        },
    );
    let d = &mut file.draft;
    d.specimen.thickness_std_m = Some(s.thickness_std_m);
    d.specimen.radius_std_m = Some(s.radius_std_m);
    if let Some(cal) = &mut d.calibration {
        cal.metres_per_pixel_std = Some(s.scale_relative_std * mpp);
        cal.clamp_row_std_px = Some(s.height_offset_std_m / mpp);
        cal.scale_per_clamp_row =
            (s.offset_scale_per_m != 0.0).then_some(s.offset_scale_per_m * mpp);
    }
    let path = out.join("experiment.toml");
    crate::io::write_atomic(&path, file.render().as_bytes())
        .with_context(|| format!("{}: cannot write", path.display()))?;
    let true_heights_m: Vec<f64> = w.truth.iter().map(|t| t.height_m).collect();
    let ideal_readings_m = true_heights_m
        .iter()
        .map(|h| h * scale + offset_m)
        .collect();
    Ok(Drawn {
        experiment_toml: path,
        true_heights_m,
        ideal_readings_m,
    })
}

/// One experiment's verdicts and its tracker's `sum z^2`, photos and
/// `sum height_std_m`.
type One = (Judged, f64, usize, f64);

/// Experiment `index`: written into `dir/experiment_<index>`, run through
/// the pipeline, judged, and its folder removed.
fn one(plan: &PhotoPlan, theta: &[f64], index: usize, dir: &Path) -> anyhow::Result<One> {
    let folder = dir.join(format!("experiment_{index}"));
    let result = (|| {
        let drawn = write_experiment(plan, index, &folder)?;
        let exp = Experiment::read(&drawn.experiment_toml)?;
        let settings = Settings {
            fit: plan.fit,
            models: vec![],
            axisym: true,
            refine: true,
            weighted: plan.weighted,
            ..Settings::default()
        };
        let out = pipeline::run(&exp, &settings)
            .map_err(|e| anyhow!("{} stage: {}", e.stage.name(), e.error))?;
        let u = out
            .fit
            .refined
            .as_ref()
            .and_then(|r| r.uncertainty.as_ref())
            .ok_or_else(|| anyhow!("no covariance: {}", out.fit.warnings.join("; ")))?;
        let band = out.band.as_deref().unwrap_or_default();
        let rows = &out
            .tracking
            .as_ref()
            .ok_or_else(|| anyhow!("the run tracked no photos"))?
            .tracked
            .rows;
        let mut pairs = Vec::with_capacity(rows.len());
        let (mut z2, mut sd) = (0.0, 0.0);
        for r in rows {
            let at = out.pressures_pa.iter().position(|&p| p == r.pressure_pa);
            let bp: Option<inverse::BandPoint> = at.and_then(|j| band.get(j).cloned().flatten());
            pairs.push((bp, drawn.true_heights_m[r.frame]));
            z2 += ((r.height_m - drawn.ideal_readings_m[r.frame]) / r.height_std_m).powi(2);
            sd += r.height_std_m;
        }
        Ok((Judged::new(u, theta, &pairs), z2, rows.len(), sd))
    })();
    // The folder is scratch; a failure to remove it costs only disk space.
    let _ = std::fs::remove_dir_all(&folder);
    result
}

/// Runs `plan` with the experiments' folders made (and removed) inside
/// `dir`, `threads` experiments at a time (0: as many as rayon's global
/// pool has threads).
pub fn run(plan: &PhotoPlan, dir: &Path, threads: usize) -> anyhow::Result<PhotoCoverage> {
    let (names, theta, _) = inverse::law_parameters(&plan.truth.model)
        .ok_or_else(|| anyhow!("the true law has no parameters"))?;
    let threads = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .with_context(|| format!("cannot start {threads} threads"))?;
    let all: Vec<anyhow::Result<One>> = pool.install(|| {
        (0..plan.experiments)
            .into_par_iter()
            .map(|i| one(plan, &theta, i, dir))
            .collect()
    });
    let mut judged = Vec::new();
    let mut failed = Vec::new();
    let (mut z2, mut photos, mut sd) = (0.0, 0, 0.0);
    for (i, r) in all.into_iter().enumerate() {
        match r {
            Ok((j, z, n, s)) => {
                judged.push(j);
                z2 += z;
                photos += n;
                sd += s;
            }
            Err(e) => failed.push((i, format!("{e:#}"))),
        }
    }
    let n = photos.max(1) as f64;
    Ok(PhotoCoverage {
        coverage: Coverage::tally(names, &judged),
        failed,
        photos,
        height_z_rms: (z2 / n).sqrt(),
        mean_height_std_m: sd / n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::hyperelastic::Kind;
    use crate::material::Model;

    fn plan(experiments: usize, seed: u64) -> PhotoPlan {
        PhotoPlan {
            truth: Material {
                model: Model::MooneyRivlin {
                    c1_pa: 0.12e6,
                    c2_pa: 0.03e6,
                },
                poisson: 0.45,
                fit: None,
            },
            fit: FitModel::Hyperelastic(Kind::MooneyRivlin),
            specimen: Specimen {
                radius_m: 0.0375,
                thickness_m: 3.5e-4,
                poisson: 0.45,
                prebulge_height_m: 0.0,
            },
            pressures_pa: (0..6).map(|i| 600.0 + 480.0 * i as f64).collect(),
            sources: Sources {
                pressure_std_pa: 4.0,
                pressure_relative_std: 0.005,
                thickness_std_m: 0.03 * 3.5e-4,
                ..Sources::default()
            },
            camera: Camera {
                width: 640,
                height: 480,
                blur_px: 1.5,
                noise_grey: 3.0,
                encoding: Encoding::Jpeg(85),
            },
            experiments,
            seed,
            weighted: false,
        }
    }

    /// 20 experiments of 6 photos (640x480, noise 3, blur 1.5, JPEG 85,
    /// the pressure readings' noise and gain, the thickness) through the
    /// whole pipeline. Each parameter's interval must hold the truth at
    /// least 16 times of 20 (a 95 % interval does so with probability
    /// 0.997, one of 85 % with 0.83), the band at least 108 of the 120 true
    /// heights (2.5 binomial standard deviations below 95 %), and the
    /// tracker's errors be the size of its stated `height_std_m`.
    #[test]
    fn photo_intervals_cover_the_truth() {
        let dir = tempfile::tempdir().unwrap();
        let c = run(&plan(20, 7001), dir.path(), 0).unwrap();
        eprintln!("{c:?}");
        assert!(c.failed.is_empty(), "{:?}", c.failed);
        let cov = &c.coverage;
        assert_eq!(cov.experiments, 20);
        for k in 0..2 {
            assert!(
                cov.covered[k] >= 16,
                "{}: {} of 20 intervals hold the truth",
                cov.names[k],
                cov.covered[k]
            );
        }
        assert_eq!(cov.band.1, 120);
        assert!(
            cov.band.0 >= 108,
            "the band holds {} of 120 true heights",
            cov.band.0
        );
        assert!(
            (0.7..=1.4).contains(&c.height_z_rms),
            "RMS(err/std) of the tracked heights {}",
            c.height_z_rms
        );
        // The experiment file states what was drawn, and the photos are
        // those of the true bubble.
        let out = dir.path().join("one");
        let p = plan(1, 7001);
        let d = write_experiment(&p, 0, &out).unwrap();
        let e = Experiment::read(&d.experiment_toml).unwrap();
        assert_eq!(e.uncertainty(), p.sources);
        assert_eq!(e.specimen, p.specimen);
        assert_eq!(d.true_heights_m, d.ideal_readings_m);
    }
}
