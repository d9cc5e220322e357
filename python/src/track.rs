//! `track`: an experiment file's photos -> apex height per photo, through
//! the library's tracker as `bulge track` calls it.

use std::path::PathBuf;

use bulge::Refusal;
use bulge::experiment::Experiment;
use bulge::track::{Options, Refine};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use super::stages::choice;
use super::{Counter, bad, chain, failed};

/// `heights.csv`, the warnings, the frames left out (frame, file, score,
/// reason) and the note on the lens, if any.
type TrackResult = (
    Py<PyBytes>,
    Vec<String>,
    Vec<(usize, String, f64, String)>,
    Option<String>,
);

/// `bulge track` of an experiment file; `progress(done, total)` is called
/// after each frame (with the GIL, from the tracking threads).
#[pyfunction]
#[pyo3(signature = (experiment, min_score=0.5, skip_bad_frames=false, refine="edge",
    search_margin_px=8, edge_span_px=None, edge_window_px=3, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn track(
    py: Python<'_>,
    experiment: PathBuf,
    min_score: f64,
    skip_bad_frames: bool,
    refine: &str,
    search_margin_px: usize,
    edge_span_px: Option<usize>,
    edge_window_px: usize,
    progress: Option<PyObject>,
) -> PyResult<TrackResult> {
    if !(-1.0..=1.0).contains(&min_score) {
        return Err(bad(format!(
            "min_score={min_score} is outside [-1, 1], the range of TM_CCOEFF_NORMED scores"
        )));
    }
    if edge_window_px < 2 {
        return Err(bad(format!(
            "edge_window_px={edge_window_px} is too small: give at least 2 px (more than twice the blur)"
        )));
    }
    let opts = Options {
        refine: choice::<Refine>("refine", refine)?,
        min_score,
        skip_bad_frames,
        search_margin_px,
        edge_span_px,
        edge_window_px,
    };
    let out = py.allow_threads(move || {
        let exp = Experiment::read(&experiment).map_err(|e| (true, chain(&e)))?;
        let setup = bulge::track::setup_from_experiment(&exp).map_err(|e| (e.is_bad_input(), chain(&e)))?;
        let total = setup.frames.len();
        let counter = Counter::new(progress, total);
        let tick = || counter.tick();
        let tracked = bulge::track::track(&setup, &opts, &tick).map_err(|e| (e.is_bad_input(), chain(&e)))?;
        if tracked.rows.is_empty() {
            return Err((
                true,
                format!(
                    "every one of the {total} frames scored below min_score {min_score}: nothing to return; check the template and the region"
                ),
            ));
        }
        let skipped = tracked
            .skipped
            .iter()
            .map(|s| (s.frame, s.file.clone(), s.score, s.reason.clone()))
            .collect();
        let note = setup
            .lens
            .is_none()
            .then(|| bulge::track::lens::UNCALIBRATED_NOTE.to_string());
        Ok((
            tracked.heights_csv().into_bytes(),
            tracked.warnings.clone(),
            skipped,
            note,
        ))
    });
    match out {
        Ok((csv, warnings, skipped, note)) => {
            Ok((PyBytes::new(py, &csv).unbind(), warnings, skipped, note))
        }
        Err((true, m)) => Err(bad(m)),
        Err((false, m)) => Err(failed(m)),
    }
}
