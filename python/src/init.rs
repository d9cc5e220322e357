//! `init`: the experiment file from the photos alone, through the library's
//! `bulge init` ([`bulge::track::init::command`]).

use std::path::PathBuf;

use bulge::camera::Response;
use bulge::experiment::Specimen;
use bulge::track::init::command::{InitRequest, init_files};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use super::{bad, failed};

/// The experiment file's text, the picture of what was found (PNG), the
/// summary line and the notes.
type InitResult = (String, Py<PyBytes>, String, Vec<String>);

/// `bulge init` of a photo folder or a video; the experiment file's paths
/// are relative to `base`.
#[pyfunction]
#[pyo3(signature = (source, radius_m, thickness_m, poisson=0.45, base=None, every=None,
    pressure=None, glob=None, metres_per_pixel=None, points_px=None, distance_m=None,
    elevation_deg=None, camera_distance_m=None, orthographic=false, response="srgb",
    camera=None, clamp_row_px=None, clamp_row_std_px=0.0))]
#[allow(clippy::too_many_arguments)]
pub fn init(
    py: Python<'_>,
    source: PathBuf,
    radius_m: f64,
    thickness_m: f64,
    poisson: f64,
    base: Option<PathBuf>,
    every: Option<usize>,
    pressure: Option<PathBuf>,
    glob: Option<String>,
    metres_per_pixel: Option<f64>,
    points_px: Option<[f64; 4]>,
    distance_m: Option<f64>,
    elevation_deg: Option<f64>,
    camera_distance_m: Option<f64>,
    orthographic: bool,
    response: &str,
    camera: Option<PathBuf>,
    clamp_row_px: Option<f64>,
    clamp_row_std_px: f64,
) -> PyResult<InitResult> {
    let response: Response = response
        .parse()
        .map_err(|e: bulge::camera::ResponseError| bad(e.to_string()))?;
    let points_px = match (points_px, distance_m) {
        (Some(p), Some(d)) => Some((p, d)),
        (None, None) => None,
        _ => {
            return Err(bad(
                "points_px and distance_m go together: two points (x1, y1, x2, y2 px) and the distance between them, m".into(),
            ));
        }
    };
    if metres_per_pixel.is_some() && points_px.is_some() {
        return Err(bad(
            "give the scale once: metres_per_pixel, or points_px with distance_m".into(),
        ));
    }
    if orthographic && camera_distance_m.is_some() {
        return Err(bad(
            "orthographic=True says the camera has no distance: drop camera_distance_m, or orthographic".into(),
        ));
    }
    let req = InitRequest {
        source,
        every,
        specimen: Specimen {
            radius_m,
            thickness_m,
            poisson,
            prebulge_height_m: 0.0,
        },
        pressure,
        glob,
        metres_per_pixel,
        points_px,
        elevation_deg,
        clamp_row_px: clamp_row_px.map(|r| (r, clamp_row_std_px)),
        camera_distance_m,
        orthographic,
        response,
        camera,
        base: base.unwrap_or_else(|| PathBuf::from(".")),
    };
    let out = py.allow_threads(move || init_files(&req));
    match out {
        Ok(f) => Ok((
            f.toml,
            PyBytes::new(py, &f.png).unbind(),
            f.summary,
            f.notes,
        )),
        Err(e) if e.bad => Err(bad(e.message)),
        Err(e) => Err(failed(e.message)),
    }
}
