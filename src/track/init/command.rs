//! `bulge init` in memory: the checks of its settings, the frames of a photo
//! folder or a video, the set-up found in them, the experiment file and the
//! picture of what was found, for the command line and the Python package
//! alike. Messages name each setting through [`Setting`], as the front end
//! spells it (`--every` on the command line).

use std::path::{Component, Path, PathBuf};

use super::{Found, Frames, Given, ScaleSource, Sources};
use crate::camera::Response;
use crate::experiment::Specimen;
use crate::setting::Setting;
use crate::track::{self, TrackError};

/// What `bulge init` is told.
#[derive(Debug, Clone)]
pub struct InitRequest {
    /// The photo folder or the video.
    pub source: PathBuf,
    /// A video's frames: every n-th.
    pub every: Option<usize>,
    /// The opening's radius, the membrane's thickness and Poisson ratio.
    pub specimen: Specimen,
    /// The pressure file, by photo name.
    pub pressure: Option<PathBuf>,
    /// Which photos of the folder (default: the most common extension).
    pub glob: Option<String>,
    /// The scale, m per px, when known.
    pub metres_per_pixel: Option<f64>,
    /// Two points a known distance apart (x1, y1, x2, y2 px) and that
    /// distance, m: the scale.
    pub points_px: Option<([f64; 4], f64)>,
    /// The camera's angle above the clamp plane, degrees, when known.
    pub elevation_deg: Option<f64>,
    /// The clamp plane's row at the bubble's axis (from a raised camera the
    /// clamp ring's centre), px in the photo, when init is to take it
    /// instead of finding it, and its standard deviation, px.
    pub clamp_row_px: Option<(f64, f64)>,
    /// The horizontal distance from the bubble's axis to the lens, m.
    pub camera_distance_m: Option<f64>,
    /// The lens is telecentric: no distance wanted.
    pub orthographic: bool,
    /// The camera's tone curve.
    pub response: Response,
    /// A `[camera]` table written by `bulge calibrate`.
    pub camera: Option<PathBuf>,
    /// The folder the experiment file is for: its paths are written
    /// relative to it.
    pub base: PathBuf,
}

/// Why `bulge init` wrote nothing: the input refused (`bad`), or the work
/// failed.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct InitError {
    /// The user's input (exit status 2), not a failure of the work.
    pub bad: bool,
    /// What is wrong, the value and the fix.
    pub message: String,
}

impl crate::Refusal for InitError {
    fn is_bad_input(&self) -> bool {
        self.bad
    }
}

fn refused(message: String) -> InitError {
    InitError { bad: true, message }
}

impl From<TrackError> for InitError {
    fn from(e: TrackError) -> Self {
        use crate::Refusal;
        InitError {
            bad: e.is_bad_input(),
            message: crate::io::chain(&e),
        }
    }
}

/// What `bulge init` writes and says.
pub struct InitFiles {
    /// The experiment file.
    pub toml: String,
    /// The picture of what was found (PNG).
    pub png: Vec<u8>,
    /// The frames, their size and what was found, in one line.
    pub summary: String,
    /// Notes: the camera read as orthographic, the pressure file missing.
    pub notes: Vec<String>,
    /// The frames read (photos, or the video).
    pub inputs: Vec<PathBuf>,
    /// The set-up found.
    pub found: Found,
}

/// The frames of `req.source` and the glob that chose them (empty for a
/// video).
fn frames(req: &InitRequest) -> Result<(Frames, String), InitError> {
    if req.source.is_dir() {
        let glob = match &req.glob {
            Some(g) => g.clone(),
            None => default_glob(&req.source)?,
        };
        let photos = track::list_photos(&req.source, &glob)?;
        return Ok((Frames::Photos(photos), glob));
    }
    let info = track::video::probe(&req.source)?;
    let indices = info.select(req.every, None).map_err(|m| {
        refused(format!(
            "{}: {m} ({})",
            req.source.display(),
            Setting::Every
        ))
    })?;
    let frames = Frames::Video {
        path: req.source.clone(),
        indices,
    };
    Ok((frames, String::new()))
}

/// Checks every setting before any work.
fn check(req: &InitRequest) -> Result<(), InitError> {
    req.specimen.validate().map_err(|m| {
        refused(format!(
            "the specimen ({}, {}, {}): {m}",
            Setting::RadiusM,
            Setting::ThicknessM,
            Setting::Poisson
        ))
    })?;
    if let Some(m) = req.metres_per_pixel
        && !(m.is_finite() && m > 0.0)
    {
        return Err(refused(format!(
            "{} {m}: give a positive scale, m per px",
            Setting::MetresPerPixel
        )));
    }
    if let Some(e) = req.elevation_deg
        && !(0.0..=30.0).contains(&e)
    {
        return Err(refused(format!(
            "{} {e}: give 0 to 30 degrees",
            Setting::ElevationDeg
        )));
    }
    if let Some((r, s)) = req.clamp_row_px {
        if !r.is_finite() {
            return Err(refused(format!(
                "{} {r}: give the clamp plane's row at the bubble's axis, px from the photo's top",
                Setting::ClampRow
            )));
        }
        if !(s.is_finite() && s >= 0.0) {
            return Err(refused(format!(
                "{} {s}: give the clamp row's standard deviation, px (0 or more)",
                Setting::ClampRowStd
            )));
        }
    }
    if !req.source.exists() {
        return Err(refused(format!(
            "{}: no such folder or video; give the folder the camera wrote the test's photos to, or the video",
            req.source.display()
        )));
    }
    if req.every.is_some() && req.source.is_dir() {
        return Err(refused(format!(
            "{every} applies to a video, and {} is a photo folder: drop {every}, or use {} to choose photos",
            req.source.display(),
            Setting::Glob,
            every = Setting::Every,
        )));
    }
    if let Some((p, d)) = req.points_px {
        let len = ((p[2] - p[0]).powi(2) + (p[3] - p[1]).powi(2)).sqrt();
        if !(d.is_finite() && d > 0.0) || len == 0.0 {
            return Err(refused(format!(
                "{} {p:?} with {} {d}: give two different points and a positive distance",
                Setting::PointsPx,
                Setting::DistanceM
            )));
        }
    }
    if let Some(p) = &req.pressure
        && !p.is_file()
    {
        return Err(refused(format!(
            "{} {}: no such file",
            Setting::Pressure,
            p.display()
        )));
    }
    let radius_m = req.specimen.radius_m;
    if let Some(d) = req.camera_distance_m
        && !(d.is_finite() && d > 2.0 * radius_m)
    {
        return Err(refused(format!(
            "{} {d}: give the horizontal distance from the bubble's axis to the camera's lens, m, more than the opening's diameter {}",
            Setting::CameraDistance,
            2.0 * radius_m
        )));
    }
    Ok(())
}

/// The frames of a request, checked, and the files they are read from:
/// what the caller guards against its outputs before [`init_files`].
pub fn init_inputs(req: &InitRequest) -> Result<Vec<PathBuf>, InitError> {
    check(req)?;
    let (frames, _) = frames(req)?;
    let mut inputs = match frames {
        Frames::Photos(p) => p,
        Frames::Video { path, .. } => vec![path],
    };
    inputs.extend(req.pressure.clone());
    inputs.extend(req.camera.clone());
    Ok(inputs)
}

/// `bulge init`: the set-up found in the frames of `req.source`, as the
/// experiment file and the picture of what was found.
pub fn init_files(req: &InitRequest) -> Result<InitFiles, InitError> {
    check(req)?;
    let (frames, glob) = frames(req)?;
    let lens = match &req.camera {
        Some(p) => Some(read_lens(p)?),
        None => None,
    };
    let points = req
        .points_px
        .map(|(p, d)| ([[p[0], p[1]], [p[2], p[3]]], d));
    let given = Given {
        metres_per_pixel: req.metres_per_pixel.or(points
            .map(|(p, d)| d / ((p[1][0] - p[0][0]).powi(2) + (p[1][1] - p[0][1]).powi(2)).sqrt())),
        elevation_deg: req.elevation_deg,
        clamp_row_px: req
            .clamp_row_px
            .map(|(value, std)| super::Estimate { value, std }),
        response: req.response,
        lens,
        camera_distance_m: req.camera_distance_m,
        distance_from_focal: !req.orthographic,
    };
    // Where the clamp plane (its row, the ring's ellipse, the opening at
    // it) is what was not found, init can be given it; not where the
    // bubble was not found, nor for a rolled camera, which a row given
    // would hide.
    let found = super::find_in(&frames, req.specimen.radius_m, given).map_err(|e| {
        let clamp = matches!(&e, TrackError::NotFound { clamp_plane: true, .. })
            && req.clamp_row_px.is_none();
        let mut err = InitError::from(e);
        if clamp {
            err.message.push_str(&format!(
                "; or give init the clamp plane's row at the bubble's axis ({} ROW; from a raised camera the ring centre's row, with {}: docs/track.md, \"The clamp row given\")",
                Setting::ClampRow,
                Setting::ElevationDeg
            ));
        }
        err
    })?;
    if let Some(why) = found
        .raised_without_distance()
        .filter(|_| !req.orthographic)
    {
        return Err(refused(format!(
            "{why}; give {} D (from the bubble's axis to the lens, m), or {} camera.toml (bulge calibrate: the distance from its focal length), or {} if the lens is telecentric",
            Setting::CameraDistance,
            Setting::Camera,
            Setting::Orthographic
        )));
    }
    let sources = Sources {
        dir: relative(&req.source, &req.base),
        video_every: match frames {
            Frames::Photos(_) => None,
            Frames::Video { .. } => Some(req.every.unwrap_or(1)),
        },
        glob,
        count: frames.len(),
        pressure_csv: req.pressure.as_ref().map(|p| relative(p, &req.base)),
        points,
    };
    let toml = found.experiment_toml(&req.specimen, &sources);
    let png = track::annotate::init_png(&frames, frames.len() - 1, &found, 1600).map_err(|e| {
        InitError {
            bad: false,
            message: crate::io::chain(&e),
        }
    })?;
    let mut notes = Vec::new();
    if found.camera_distance_m.is_none()
        && !req.orthographic
        && found.scale_from == ScaleSource::ClampOpening
    {
        notes.push(format!(
            "note: the camera is read as orthographic (no {}, no lens with a focal length): a camera D from the bubble's axis sees the opening through its tangent points, so the scale comes out about a^2 / (2 D^2) small (0.35 % at 0.45 m); give {} D or {} camera.toml (bulge calibrate)",
            Setting::CameraDistance,
            Setting::CameraDistance,
            Setting::Camera
        ));
    }
    if let Some(e) = found.elevation_deg.filter(|e| {
        !found.clamp_row_given && e.value - 2.0 * e.std > super::file::MEASURED_ELEVATION_DEG
    }) {
        notes.push(format!(
            "note: the camera looks down on the clamp plane from {:.2} degrees, beyond the {} degrees init's search of the clamp ring is measured on (on a path-traced scene at 9 degrees the clamp row was found 0.28 px off, 3.8 of its stated deviations): check the clamp's edge on init.png, or give the row ({}; docs/track.md, \"The clamp row given\")",
            e.value,
            super::file::MEASURED_ELEVATION_DEG,
            Setting::ClampRow
        ));
    }
    if found.clamp_row_given && req.elevation_deg.is_none() {
        notes.push(format!(
            "note: the clamp row was given without {}: the camera is taken as level with the clamp plane; from a raised camera give its elevation too (taken as level, a camera e degrees up puts the heights off by the factor cos e, 1 % at 8 degrees, and the scale read at the row off as well)",
            Setting::ElevationDeg
        ));
    }
    if let Some(t) = found.clamp_clipped_px {
        notes.push(format!(
            "note: the clamp ring's face is at the sensor's largest value beside its top edge (clipped): the edge located on the clipped step lies up to {t:.1} px towards the wall from the true one, and clamp_row_std_px includes {:.2} px for it; lower the exposure or the light on the ring until its face stays below the largest value",
            t / 3f64.sqrt()
        ));
    }
    let inputs = match &frames {
        Frames::Photos(p) => p.clone(),
        Frames::Video { path, .. } => vec![path.clone()],
    };
    Ok(InitFiles {
        toml,
        png,
        summary: summary(&frames, &found),
        notes,
        inputs,
        found,
    })
}

/// The frames, their size and what was found, in one line.
fn summary(frames: &Frames, found: &Found) -> String {
    let a = found.radius_px.map_or(String::new(), |a| {
        format!(", 2a = {:.2} +- {:.2} px", 2.0 * a.value, 2.0 * a.std)
    });
    let e = found.elevation_deg.map_or(String::new(), |e| {
        format!(", elevation {:.2} +- {:.2} deg", e.value, e.std)
    });
    let e = match (found.camera_distance_m, found.camera_distance_from_focal) {
        (Some(d), true) => {
            format!("{e}, camera {d:.4} m from the axis (the lens's focal length times the scale)")
        }
        _ => e,
    };
    let rows = found.apexes_px.iter().map(|p| p[1]);
    format!(
        "{} {} {}x{} px: clamp row {:.3} +- {:.3} px, axis {:.2} px{a}, {:.5e} m/px{e}; apex rows {:.0} to {:.0}",
        frames.len(),
        match frames {
            Frames::Photos(_) => "photos",
            Frames::Video { .. } => "video frames",
        },
        found.width,
        found.height,
        found.clamp_row_px.value,
        found.clamp_row_px.std,
        found.axis_x_px.value,
        found.metres_per_pixel.value,
        rows.clone().fold(f64::INFINITY, f64::min),
        rows.fold(f64::NEG_INFINITY, f64::max),
    )
}

/// The lens of a `[camera]` table written by `bulge calibrate`.
fn read_lens(p: &Path) -> Result<track::lens::Lens, InitError> {
    #[derive(serde::Deserialize)]
    struct File {
        camera: Option<crate::experiment::CameraConfig>,
    }
    let bad = |m: String| refused(format!("{}: {m}", p.display()));
    let text = std::fs::read_to_string(p).map_err(|e| {
        bad(format!(
            "cannot read it ({e}); give the file `bulge calibrate` wrote"
        ))
    })?;
    let f: File = toml::from_str(&text).map_err(|e| bad(format!("not a [camera] table: {e}")))?;
    let c = f
        .camera
        .ok_or_else(|| bad("no [camera] table: give the file `bulge calibrate` wrote".into()))?;
    track::lens::Lens::from_config(&c)
        .map_err(bad)?
        .ok_or_else(|| bad("the [camera] table has no lens (focal_px, principal_point_px, distortion): give the file `bulge calibrate` wrote".into()))
}

/// `path` relative to the folder `base` (both made absolute and normal
/// first), with `/` between its parts, as the experiment file gives paths.
pub fn relative(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| {
        let p = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        p.components().fold(PathBuf::new(), |mut acc, c| {
            match c {
                Component::ParentDir => {
                    acc.pop();
                }
                Component::CurDir => {}
                c => acc.push(c),
            }
            acc
        })
    };
    let (p, b) = (abs(path), abs(base));
    let pc: Vec<Component> = p.components().collect();
    let bc: Vec<Component> = b.components().collect();
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); bc.len() - common];
    parts.extend(
        pc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    if parts.is_empty() {
        ".".into()
    } else {
        parts.join("/")
    }
}

/// The photos of a folder: `*.ext` of its most common photo extension.
fn default_glob(dir: &Path) -> Result<String, InitError> {
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    let rd = std::fs::read_dir(dir).map_err(|e| {
        refused(format!(
            "{}: cannot read the photo folder: {e}",
            dir.display()
        ))
    })?;
    for e in rd.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        if let Some((_, ext)) = file.rsplit_once('.') {
            let ext = ext.to_string();
            if ["jpg", "jpeg", "png", "tif", "tiff", "bmp"]
                .contains(&ext.to_ascii_lowercase().as_str())
            {
                *counts.entry(ext).or_default() += 1;
            }
        }
    }
    counts
        .into_iter()
        .max_by_key(|(_, n)| *n)
        .map(|(ext, _)| format!("*.{ext}"))
        .ok_or_else(|| {
            refused(format!(
                "{}: no photos (.jpg, .jpeg, .png, .tif, .tiff, .bmp) in the folder; give the folder of the test's photos, or {}",
                dir.display(),
                Setting::Glob
            ))
        })
}
