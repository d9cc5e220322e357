//! Tests of the tracker on synthetic photos with known truth, one file per
//! concern; the helpers that write, track and compare sequences are here.

use std::path::Path;

use super::*;
use crate::experiment::Experiment;

mod clean;
mod dirty;
mod elevation;
mod guards;
mod inputs;
mod seed;

/// The experiment that `synth::write_sequence` wrote into `dir`, tracked
/// with `opts`.
fn tracked_in(dir: &Path, opts: &Options) -> Result<Tracked, TrackError> {
    let e = Experiment::read(dir.join("experiment.toml")).unwrap();
    track(&setup_from_experiment(&e).unwrap(), opts, &|| {})
}

/// Writes a cap sequence, tracks it, returns the apex errors.
fn accuracy(spec: &synth::SequenceSpec, n: usize, refine: Refine) -> synth::ApexErrors {
    let dir = tempfile::tempdir().unwrap();
    let frames = synth::cap_frames(spec.specimen.radius_m, 0.6 * spec.specimen.radius_m, n);
    let w = synth::write_sequence(dir.path(), spec, &frames).unwrap();
    let opts = Options {
        refine,
        ..Options::default()
    };
    let t = tracked_in(dir.path(), &opts).unwrap();
    assert_eq!(t.rows.len(), n);
    if std::env::var_os("BULGE_TRACK_DEBUG").is_some() {
        for (r, tr) in t.rows.iter().zip(&w.truth) {
            let e = r.edge.unwrap();
            eprintln!(
                "{} score {:.3} dy {:+.3} (std {:.3}) dx {:+.3} dx_q {:+.3} dx_v {:+.3} (std {:.3}) curv {:.5} rms {:.3} cols {}",
                r.file,
                r.score,
                r.apex_y_px - tr.apex_y_px,
                r.apex_y_std_px,
                r.apex_x_px - tr.apex_x_px,
                r.apex_quadratic_px[0] - tr.apex_x_px,
                e.x_vertex - tr.apex_x_px,
                e.x_std,
                e.curvature,
                e.rms,
                e.columns
            );
        }
    }
    synth::apex_errors(&t.rows, &w.truth)
}

/// Prints the errors and holds the reported apex row's RMS to `bound` px.
fn assert_row_rms(a: &synth::ApexErrors, bound: f64) {
    eprintln!("{a:?}");
    assert!(
        a.reported[1] <= bound,
        "RMS apex row error {} px > {bound}",
        a.reported[1]
    );
}

fn spec(seed: u64, blur: f64, noise: f64, enc: image::Encoding) -> synth::SequenceSpec {
    synth::SequenceSpec::plain(640, 480, seed, blur, noise, enc)
}

/// A sequence of spherical caps with clutter behind the bubble (a shelf
/// edge and a cable across the apex's path), uneven light and a specular
/// highlight near the apex, tracked with `skip_bad_frames`: returns the
/// tracking and the truth.
fn lab_sequence(
    seed: u64,
    look: synth::Look,
    skip: bool,
) -> (Result<Tracked, TrackError>, Vec<synth::Truth>) {
    let s = synth::SequenceSpec {
        width: 1280,
        height: 960,
        look,
        ..spec(seed, 1.5, 3.0, image::Encoding::Jpeg(90))
    };
    let frames = synth::cap_frames(s.specimen.radius_m, 0.6 * s.specimen.radius_m, 12);
    written_and_tracked(&s, &frames, skip)
}

/// Holds every tracked frame's apex row within 4 of its stated standard
/// deviations of the truth (none silently wrong); returns the errors, px.
fn kept_within_4_sd(rows: &[FrameResult], truth: &[synth::Truth], what: &str) -> Vec<f64> {
    rows.iter()
        .map(|r| {
            let tr = truth.iter().find(|tr| tr.file == r.file).unwrap();
            let err = r.apex_y_px - tr.apex_y_px;
            assert!(
                err.abs() <= 4.0 * r.apex_y_std_px,
                "{what} {}: apex row {err:+.3} px off, stated std {:.3} px",
                r.file,
                r.apex_y_std_px
            );
            err
        })
        .collect()
}

/// `frames` written as `s` into a temporary folder and tracked with the
/// experiment file written beside them (the true set-up): the tracking and
/// the truth.
fn written_and_tracked(
    s: &synth::SequenceSpec,
    frames: &[synth::SynthFrame],
    skip: bool,
) -> (Result<Tracked, TrackError>, Vec<synth::Truth>) {
    let dir = tempfile::tempdir().unwrap();
    let w = synth::write_sequence(dir.path(), s, frames).unwrap();
    let opts = Options {
        skip_bad_frames: skip,
        ..Options::default()
    };
    (tracked_in(dir.path(), &opts), w.truth)
}
