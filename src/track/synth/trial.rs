//! One synthetic experiment through `bulge init` and `bulge track`: the
//! photos written, the set-up found from them alone, the heights tracked
//! with the experiment file it wrote, and every figure against the truth.
//! The tests and `cargo run --release --features harness --example
//! init_accuracy` (and `--example camera_grid`) share it; built only for
//! them (the `harness` feature).

use std::path::Path;

use anyhow::Context;

use super::{SequenceSpec, SynthFrame, write_sequence};
use crate::experiment::Experiment;
use crate::track::init::{self, Given, Sources};
use crate::track::{Options, list_photos, setup_from_experiment, track};

/// What one experiment gives against its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct InitTrial {
    /// Relative error of the scale found.
    pub scale: f64,
    /// The stated relative standard deviation of the scale.
    pub scale_std: f64,
    /// The same with the clamp row's part (`scale_per_clamp_row` times the
    /// row's deviation) in quadrature: the scale is read at the clamp row.
    pub scale_std_all: f64,
    /// Error of the clamp row found, px.
    pub clamp_px: f64,
    /// The clamp row's stated standard deviation, px.
    pub clamp_std_px: f64,
    /// Error of the elevation found, degrees (0 when none was found).
    pub elevation_deg: f64,
    /// The largest relative height error over the photos tracked.
    pub heights: f64,
    /// RMS error of the apex row over the photos tracked, px.
    pub apex_rms_px: f64,
    /// Mean error of the apex row over the photos tracked, px (positive:
    /// below the true top).
    pub apex_mean_px: f64,
    /// RMS of (apex row error / its stated deviation): the apex's own
    /// term of `height_std_m`, alone.
    pub apex_z: f64,
    /// RMS of (height error / `height_std_m`): against the frame's own
    /// deviation.
    pub rms_z: f64,
    /// RMS of (height error / all the stated terms): `height_std_m`, the
    /// height times the scale's relative deviation and the clamp row's
    /// deviation times `mpp + h scale_per_clamp_row` (the scale read at
    /// the clamp row moves with it), in quadrature.
    pub rms_z_all: f64,
    /// RMS of (height error less the parts the scale's and the clamp
    /// row's errors give it, over `height_std_m`): the frame's own term
    /// against the frame's own error alone.
    pub own_z: f64,
    /// RMS of (the height error's common part, the scale's and the clamp
    /// row's, over their stated deviation together).
    pub common_z: f64,
    /// The scale's error less its part through the clamp row's error,
    /// over the scale's stated relative deviation.
    pub scale_own_z: f64,
    /// The mean share of each stated term in the stated variance over the
    /// photos tracked: `height_std_m`, the scale's part and the clamp
    /// row's part.
    pub shares: [f64; 3],
    /// Photos tracked, of those written.
    pub tracked: [usize; 2],
    /// The tracker's warnings (photos kept that broke a rule which is no
    /// physical bound).
    pub warnings: Vec<String>,
}

/// Writes `frames` as `spec` into `dir`, finds the set-up with `bulge
/// init`'s search (the scale given only when `scale_given`), tracks with
/// the experiment file it wrote (leaving out the photos it refuses when
/// the look has clutter) and compares. Errors name the seed.
pub fn init_and_track(
    dir: &Path,
    spec: &SequenceSpec,
    frames: &[SynthFrame],
    scale_given: bool,
) -> anyhow::Result<InitTrial> {
    let seed = spec.seed;
    let at = || format!("seed {seed}");
    let w = write_sequence(dir, spec, frames).with_context(at)?;
    let glob = format!("*.{}", spec.encoding.extension());
    let photos = list_photos(&dir.join("photos"), &glob).with_context(at)?;
    let given = Given {
        metres_per_pixel: scale_given.then_some(w.scene.metres_per_pixel),
        elevation_deg: None,
        clamp_row_px: None,
        response: spec.look.response,
        lens: w.scene.look.lens,
        // With a lens on a pinhole camera the distance is found from its
        // focal length, as `bulge init --camera` finds it; without one, it
        // is given.
        camera_distance_m: (spec.look.camera_distance_m > 0.0 && w.scene.look.lens.is_none())
            .then_some(spec.look.camera_distance_m),
        distance_from_focal: true,
    };
    let found = init::find(&photos, spec.specimen.radius_m, given).with_context(at)?;
    let toml = found.experiment_toml(
        &spec.specimen,
        &Sources {
            dir: "photos".into(),
            glob,
            video_every: None,
            count: photos.len(),
            pressure_csv: Some("pressure.csv".into()),
            points: None,
        },
    );
    let path = dir.join("init.toml");
    std::fs::write(&path, &toml).with_context(at)?;
    let with_file = || format!("seed {seed}, with this experiment file:\n{toml}");
    let e = Experiment::read(&path).with_context(with_file)?;
    let opts = Options {
        skip_bad_frames: spec.look.clutter,
        ..Options::default()
    };
    // `track` decodes on rayon's pool itself: never call it from inside it.
    let setup = setup_from_experiment(&e).with_context(at)?;
    let t = track(&setup, &opts, &|| {}).with_context(with_file)?;
    let mpp = &found.metres_per_pixel;
    let (scale_rel, row_m) = (mpp.std / mpp.value, found.clamp_row_px.std * mpp.value);
    let (mut heights, mut apex2, mut z2, mut z2_all) = (0.0f64, 0.0, 0.0, 0.0);
    let (mut apex1, mut apex_z2, mut own2, mut common2) = (0.0, 0.0, 0.0, 0.0);
    let scale_err = found.metres_per_pixel.value / w.scene.metres_per_pixel - 1.0;
    let row_err_px = found.clamp_row_px.value - w.scene.clamp_row_px;
    let row_err_m = row_err_px * mpp.value;
    let mut shares = [0.0; 3];
    for r in &t.rows {
        let tr = w
            .truth
            .iter()
            .find(|x| x.file == r.file)
            .ok_or_else(|| anyhow::anyhow!("seed {seed}: no truth for {}", r.file))?;
        let err = r.height_m - tr.height_m;
        heights = heights.max((err / tr.height_m).abs());
        apex2 += (r.apex_y_px - tr.apex_y_px).powi(2);
        apex1 += r.apex_y_px - tr.apex_y_px;
        apex_z2 += ((r.apex_y_px - tr.apex_y_px) / r.apex_y_std_px).powi(2);
        z2 += (err / r.height_std_m).powi(2);
        let row = row_m * (1.0 + r.height_m * found.scale_per_clamp_row / mpp.value);
        let terms = [r.height_std_m, r.height_m * scale_rel, row];
        let all = terms[0].hypot(terms[1]).hypot(terms[2]);
        z2_all += (err / all).powi(2);
        let own = err - r.height_m * scale_err - row_err_m;
        own2 += (own / r.height_std_m).powi(2);
        common2 += ((err - own) / terms[1].hypot(terms[2])).powi(2);
        for (s, t) in shares.iter_mut().zip(terms) {
            *s += (t / all).powi(2);
        }
    }
    let n = t.rows.len().max(1) as f64;
    Ok(InitTrial {
        scale: scale_err,
        scale_std: found.metres_per_pixel.std / found.metres_per_pixel.value,
        scale_std_all: scale_rel.hypot(found.scale_per_clamp_row * found.clamp_row_px.std),
        clamp_px: row_err_px,
        clamp_std_px: found.clamp_row_px.std,
        elevation_deg: found.elevation_deg.map_or(0.0, |e| e.value) - spec.look.elevation_deg,
        heights,
        apex_rms_px: (apex2 / n).sqrt(),
        apex_mean_px: apex1 / n,
        apex_z: (apex_z2 / n).sqrt(),
        rms_z: (z2 / n).sqrt(),
        rms_z_all: (z2_all / n).sqrt(),
        own_z: (own2 / n).sqrt(),
        common_z: (common2 / n).sqrt(),
        scale_own_z: (scale_err - found.scale_per_clamp_row * row_err_px) / scale_rel,
        shares: shares.map(|s| s / n),
        tracked: [t.rows.len(), w.truth.len()],
        warnings: t.warnings.clone(),
    })
}
