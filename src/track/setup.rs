//! The set-up from an experiment file: the photos in natural order, the
//! pressure log joined by file name, the region, template and calibration
//! checked.

use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::*;
use crate::experiment::{Experiment, PhotosConfig, PressureConfig};
use crate::io::Table;
use crate::pressure_log::PressureLog;

/// Compares names the way people count: `img2` < `img10`.
// Kept by hand: natord orders `img02` before `img1`, alphanumeric-sort `img2` before `img02`, lexical-sort `img002` after `img10`.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (ab, bb) = (a.as_bytes(), b.as_bytes());
    let (mut i, mut j) = (0, 0);
    while i < ab.len() && j < bb.len() {
        if ab[i].is_ascii_digit() && bb[j].is_ascii_digit() {
            let si = i;
            while i < ab.len() && ab[i].is_ascii_digit() {
                i += 1;
            }
            let sj = j;
            while j < bb.len() && bb[j].is_ascii_digit() {
                j += 1;
            }
            let na = a[si..i].trim_start_matches('0');
            let nb = b[sj..j].trim_start_matches('0');
            let o = na.len().cmp(&nb.len()).then_with(|| na.cmp(nb));
            if o != Ordering::Equal {
                return o;
            }
        } else {
            let o = ab[i].cmp(&bb[j]);
            if o != Ordering::Equal {
                return o;
            }
            i += 1;
            j += 1;
        }
    }
    (ab.len() - i).cmp(&(bb.len() - j)).then_with(|| a.cmp(b))
}

/// Shell-style match of a file name: `*` any run, `?` one character,
/// `[abc]` / `[a-z]` / `[!abc]` one character of a set. An invalid pattern
/// (e.g. an unclosed `[`) matches nothing.
pub fn glob_match(pattern: &str, name: &str) -> bool {
    glob::Pattern::new(pattern).is_ok_and(|p| p.matches(name))
}

/// The photos of a folder matching a glob, in natural order of their names.
pub fn list_photos(dir: &Path, glob: &str) -> Result<Vec<PathBuf>, TrackError> {
    let rd = std::fs::read_dir(dir).map_err(|e| TrackError::PhotoFolder {
        dir: dir.to_path_buf(),
        reason: if e.kind() == std::io::ErrorKind::NotFound {
            "it does not exist".into()
        } else {
            e.to_string()
        },
    })?;
    let mut names: Vec<String> = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| TrackError::PhotoFolder {
            dir: dir.to_path_buf(),
            reason: e.to_string(),
        })?;
        if entry.file_type().map(|t| t.is_dir()).unwrap_or(false) {
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        names.push(name);
    }
    if names.is_empty() {
        return Err(TrackError::EmptyFolder {
            dir: dir.to_path_buf(),
        });
    }
    let pattern = glob::Pattern::new(glob).map_err(|e| TrackError::BadGlob {
        dir: dir.to_path_buf(),
        glob: glob.to_string(),
        reason: e.to_string(),
    })?;
    names.sort_by(|a, b| natural_cmp(a, b));
    let matched: Vec<PathBuf> = names
        .iter()
        .filter(|n| pattern.matches(n))
        .map(|n| dir.join(n))
        .collect();
    if matched.is_empty() {
        let examples = names
            .iter()
            .take(3)
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(TrackError::GlobNoMatch {
            dir: dir.to_path_buf(),
            glob: glob.to_string(),
            count: names.len(),
            examples,
        });
    }
    Ok(matched)
}

/// Reads the pressure log: file name -> pressure, Pa.
pub fn read_pressures(csv: &Path) -> Result<HashMap<String, f64>, TrackError> {
    let t = Table::read(csv)?;
    let fc = t.require("file")?;
    let pc = t.require("pressure_pa")?;
    let mut map = HashMap::new();
    let mut first_line = HashMap::new();
    for r in 0..t.len() {
        let raw = t.cell(r, fc);
        let key = Path::new(raw)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| raw.to_string());
        let p = t.number(r, pc)?;
        if let Some(l) = first_line.insert(key.clone(), t.lines[r]) {
            return Err(t
                .error_at(
                    r,
                    "file",
                    format!(
                        "photo `{key}` already has a pressure on line {l}; keep one row per photo"
                    ),
                )
                .into());
        }
        map.insert(key, p);
    }
    Ok(map)
}

/// Resolves the `[photos]`, `[calibration]` and `[pressure]` tables of an
/// experiment into a [`Setup`]: lists the photos and joins the pressures.
pub fn setup_from_experiment(e: &Experiment) -> Result<Setup, TrackError> {
    let cfg = |message: String| TrackError::Config {
        path: e.path.clone(),
        message,
    };
    let photos = e.photos.as_ref().ok_or_else(|| {
        cfg("no [photos] table: add one with `dir`, `glob` and `roi_px` (or `video` and `roi_px`; see docs/track.md)".into())
    })?;
    let cal = e.calibration.as_ref().ok_or_else(|| {
        cfg("no [calibration] table: add `metres_per_pixel` (or `points_px` and `distance_m`) and `clamp_row_px`".into())
    })?;
    let pressure = e.pressure.as_ref().ok_or_else(|| {
        cfg("no [pressure] table: add `csv = \"pressure.csv\"` (columns file,pressure_pa, or time_s,pressure_pa)".into())
    })?;

    let [x, y, w, h] = photos.roi_px;
    if w <= 0 || h <= 0 {
        return Err(cfg(format!(
            "[photos] roi_px = {:?}: width and height must be positive pixel counts",
            photos.roi_px
        )));
    }
    let roi = [i64::from(x), i64::from(y), i64::from(w), i64::from(h)];
    let template = match (&photos.template, &photos.template_rect_px) {
        (Some(f), None) => TemplateSource::File(e.resolve(f)),
        (None, Some(r)) => {
            if r[2] <= 0 || r[3] <= 0 {
                return Err(cfg(format!(
                    "[photos] template_rect_px = {r:?}: width and height must be positive pixel counts"
                )));
            }
            TemplateSource::Rect(r.map(i64::from))
        }
        (Some(_), Some(_)) => {
            return Err(cfg(
                "[photos] gives both `template` and `template_rect_px`: keep one".into(),
            ));
        }
        (None, None) => {
            return Err(cfg(
                "[photos] needs a template: `template = \"file.png\"` or `template_rect_px = [x, y, w, h]` cut from the reference frame".into(),
            ));
        }
    };
    let scale = match (cal.metres_per_pixel, cal.points_px, cal.distance_m) {
        (Some(s), None, None) => s,
        (None, Some([p, q]), Some(d)) => {
            let len = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
            if len.is_nan() || len <= 0.0 {
                return Err(cfg(format!(
                    "[calibration] points_px = {:?} are the same point: give two points a known distance apart",
                    [p, q]
                )));
            }
            d / len
        }
        (Some(_), _, _) => {
            return Err(cfg(
                "[calibration] gives `metres_per_pixel` and also `points_px`/`distance_m`: keep one way".into(),
            ));
        }
        _ => {
            return Err(cfg(
                "[calibration] needs `metres_per_pixel`, or `points_px = [[x1, y1], [x2, y2]]` with `distance_m`".into(),
            ));
        }
    };
    if !(scale.is_finite() && scale > 0.0) {
        return Err(cfg(format!(
            "[calibration] the scale is {scale} m/px: it must be a positive length per pixel (e.g. 1.7e-4)"
        )));
    }
    let origin = match cal.clamp_row_px {
        Some(r) if r.is_finite() => HeightOrigin::ClampRow(r),
        Some(r) => {
            return Err(cfg(format!(
                "[calibration] clamp_row_px = {r} is not a finite row"
            )));
        }
        None => HeightOrigin::Reference {
            prebulge_height_m: e.specimen.prebulge_height_m,
        },
    };

    let elevation = match cal.elevation_deg {
        None => None,
        Some(d) if !(d.is_finite() && (0.0..=30.0).contains(&d)) => {
            return Err(cfg(format!(
                "[calibration] elevation_deg = {d}: give the camera's elevation above the clamp plane, 0 to 30 degrees"
            )));
        }
        Some(_) if !matches!(origin, HeightOrigin::ClampRow(_)) => {
            return Err(cfg(
                "[calibration] elevation_deg needs clamp_row_px (the row of the clamp ring's centre): the correction for the elevation is made on the height above the clamp plane".into(),
            ));
        }
        Some(d) => Some(Elevation {
            radians: d.to_radians(),
            radius_m: e.specimen.radius_m,
        }),
    };
    let camera_distance_m = match e.camera.as_ref().and_then(|c| c.distance_m) {
        None => None,
        Some(d) if !(d.is_finite() && d > 2.0 * e.specimen.radius_m) => {
            return Err(cfg(format!(
                "[camera] distance_m = {d}: give the horizontal distance from the bubble's axis to the camera's lens, m, more than the opening's diameter {}",
                2.0 * e.specimen.radius_m
            )));
        }
        Some(_) if !matches!(origin, HeightOrigin::ClampRow(_)) => {
            return Err(cfg(
                "[camera] distance_m needs [calibration] clamp_row_px (the row of the clamp ring's centre): heights are read through the rays from the camera to the clamp plane and the bubble's top".into(),
            ));
        }
        Some(d) => Some(d),
    };
    let lens = match &e.camera {
        Some(c) => super::lens::Lens::from_config(c).map_err(cfg)?,
        None => None,
    };
    let (mut frames, video) = list_frames(e, photos)?;
    join_pressures(e, pressure, &mut frames)?;
    check_pressures(e, pressure, &frames)?;
    if photos.reference_frame >= frames.len() {
        return Err(cfg(format!(
            "[photos] reference_frame = {} but there are only {} photos (frames 0..{})",
            photos.reference_frame,
            frames.len(),
            frames.len() - 1
        )));
    }
    Ok(Setup {
        experiment: e.path.clone(),
        frames,
        roi,
        template,
        video,
        reference_frame: photos.reference_frame,
        apex_in_template: photos.apex_in_template_px,
        response: e.camera.as_ref().map(|c| c.response()).unwrap_or_default(),
        calibration: Calibration {
            metres_per_pixel: scale,
            origin,
            elevation,
            opening_radius_m: e.specimen.radius_m,
            camera_distance_m,
        },
        lens,
    })
}

/// The frames of `[photos]`: the photos of a folder in natural order (with
/// times when `interval_s` is given), or the chosen frames of a video (with
/// the container's times). Pressures are set by [`join_pressures`].
fn list_frames(
    e: &Experiment,
    photos: &PhotosConfig,
) -> Result<(Vec<Frame>, Option<PathBuf>), TrackError> {
    let cfg = |message: String| TrackError::Config {
        path: e.path.clone(),
        message,
    };
    let fmt = crate::io::fmt_short;
    match (&photos.video, &photos.dir) {
        (Some(_), Some(_)) => Err(cfg(
            "[photos] gives both `video` and `dir`: keep one source of frames (a video file, or a folder of photos with `glob`)".into(),
        )),
        (Some(_), None) if photos.glob.is_some() => Err(cfg(
            "[photos] gives `video` and `glob`: `glob` chooses the photos of a folder; remove it (the frames of a video are chosen by `every` or `times_s`)".into(),
        )),
        (None, None) => Err(cfg(
            "[photos] needs `dir = \"photos\"` (a folder of photos) or `video = \"test.mp4\"` (a video file)".into(),
        )),
        (Some(v), None) => {
            if photos.interval_s.is_some() || photos.start_s.is_some() {
                return Err(cfg(
                    "[photos] `interval_s`/`start_s` give the times of a folder's photos; a video's frames carry their own times: remove them".into(),
                ));
            }
            let path = e.resolve(v);
            let info = super::video::probe(&path)?;
            let chosen = info
                .select(photos.every, photos.times_s.as_deref())
                .map_err(&cfg)?;
            let frames = chosen
                .into_iter()
                .map(|i| Frame {
                    path: path.clone(),
                    file: super::video::frame_name(i),
                    pressure_pa: f64::NAN,
                    time_s: info.times_s.as_ref().map(|t| t[i]),
                    video_frame: Some(i),
                })
                .collect();
            Ok((frames, Some(path)))
        }
        (None, Some(d)) => {
            if photos.every.is_some() || photos.times_s.is_some() {
                return Err(cfg(
                    "[photos] `every`/`times_s` choose the frames of a video; a folder's photos are chosen by `glob`: remove them".into(),
                ));
            }
            let times = match (photos.interval_s, photos.start_s) {
                (None, Some(s)) => {
                    return Err(cfg(format!(
                        "[photos] start_s = {} without interval_s: give `interval_s` (the time between photos, s) too, or remove start_s",
                        fmt(s)
                    )));
                }
                (Some(dt), _) if !(dt.is_finite() && dt > 0.0) => {
                    return Err(cfg(format!(
                        "[photos] interval_s = {}: the time between photos must be a positive number of seconds",
                        fmt(dt)
                    )));
                }
                (_, Some(s)) if !s.is_finite() => {
                    return Err(cfg(format!("[photos] start_s = {s} is not a finite time in seconds")));
                }
                (Some(dt), s) => Some((s.unwrap_or(0.0), dt)),
                (None, None) => None,
            };
            let dir = e.resolve(d);
            let paths = list_photos(&dir, photos.glob())?;
            let frames = paths
                .into_iter()
                .enumerate()
                .map(|(k, p)| Frame {
                    file: p
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default(),
                    path: p,
                    pressure_pa: f64::NAN,
                    time_s: times.map(|(s, dt)| s + k as f64 * dt),
                    video_frame: None,
                })
                .collect();
            Ok((frames, None))
        }
    }
}

/// A bulge test's pressure is a gauge pressure, above the atmosphere: a
/// photo at a negative one (suction) shows no inflated bubble, and is the
/// log's fault, named before any photo is judged. (A log's readings between
/// the photos may dip below zero with the gauge's offset at rest; only the
/// photos' pressures count.)
fn check_pressures(
    e: &Experiment,
    pressure: &PressureConfig,
    frames: &[Frame],
) -> Result<(), TrackError> {
    let Some(f) = frames
        .iter()
        .find(|f| !(f.pressure_pa.is_finite() && f.pressure_pa >= 0.0))
    else {
        return check_rising(e, pressure, frames);
    };
    Err(TrackError::Config {
        path: e.resolve(&pressure.csv),
        message: format!(
            "photo {} gets a pressure of {} Pa from this log{}: a bubble is inflated by a positive gauge pressure (above the atmosphere); if the gauge reads an offset at rest, subtract it from the log, and leave out photos taken under suction",
            f.file,
            crate::io::fmt_short(f.pressure_pa),
            match f.time_s {
                Some(t) => format!(" (at the photo's time, {} s)", crate::io::fmt_short(t)),
                None => String::new(),
            }
        ),
    })
}

/// The tracker follows an inflation: each photo's bubble is at least as
/// tall as the last one's, so a pressure that falls in the photos' order is
/// the log's (or the order's) fault, said before any photo is judged. A
/// gauge's noise may dip: only a fall of more than 5 % of the series'
/// pressure span below an earlier photo's is refused.
fn check_rising(
    e: &Experiment,
    pressure: &PressureConfig,
    frames: &[Frame],
) -> Result<(), TrackError> {
    let (lo, hi) = frames.iter().fold((f64::INFINITY, 0.0_f64), |(l, h), f| {
        (l.min(f.pressure_pa), h.max(f.pressure_pa))
    });
    let allowed = 0.05 * (hi - lo);
    let mut top: Option<&Frame> = None;
    for f in frames {
        if let Some(t) = top
            && f.pressure_pa < t.pressure_pa - allowed
        {
            return Err(TrackError::Config {
                path: e.resolve(&pressure.csv),
                message: format!(
                    "photo {} gets {} Pa from this log, below the {} Pa of the earlier photo {}: the pressure falls in the photos' order, and bulge follows an inflation; put the photos in the order they were taken at rising pressure, check the log's column or its time offset, or leave out the deflation's photos",
                    f.file,
                    crate::io::fmt_short(f.pressure_pa),
                    crate::io::fmt_short(t.pressure_pa),
                    t.file
                ),
            });
        }
        if top.is_none_or(|t| f.pressure_pa > t.pressure_pa) {
            top = Some(f);
        }
    }
    Ok(())
}

/// Sets each frame's pressure from `[pressure] csv`: by file name (columns
/// `file,pressure_pa`), or interpolated at the frame's time (columns
/// `time_s,pressure_pa`; logger time = frame time + `offset_s`).
fn join_pressures(
    e: &Experiment,
    pressure: &PressureConfig,
    frames: &mut [Frame],
) -> Result<(), TrackError> {
    let cfg = |message: String| TrackError::Config {
        path: e.path.clone(),
        message,
    };
    let fmt = crate::io::fmt_short;
    let csv = e.resolve(&pressure.csv);
    let table = Table::read(&csv)?;
    if !PressureLog::is_time_log(&table) {
        if let Some(o) = pressure.offset_s {
            return Err(cfg(format!(
                "[pressure] offset_s = {} aligns a log by time (columns time_s,pressure_pa), but {} is joined by file name (column `file`): remove offset_s",
                fmt(o),
                csv.display()
            )));
        }
        let pressures = read_pressures(&csv)?;
        for f in frames.iter_mut() {
            f.pressure_pa = *pressures
                .get(&f.file)
                .ok_or_else(|| TrackError::NoPressure {
                    file: f.file.clone(),
                    csv: csv.clone(),
                })?;
        }
        return Ok(());
    }
    let offset = pressure.offset_s.unwrap_or(0.0);
    if !offset.is_finite() {
        return Err(cfg(format!(
            "[pressure] offset_s = {offset} is not a finite time in seconds"
        )));
    }
    let log = PressureLog::from_table(&table)?;
    let Some(first) = frames.first() else {
        return Ok(());
    };
    if first.time_s.is_none() {
        // The camera's clock: EXIF DateTimeOriginal, seconds after the first
        // photo's.
        let mut t0 = None;
        for f in frames.iter_mut() {
            let t = super::exif_time::photo_time(&f.path).map_err(|why| {
                cfg(format!(
                    "{} is a pressure log by time (columns time_s,pressure_pa), but the photos have no times: {} has no time from the camera ({why}); give `interval_s` (the time between photos, s; and `start_s`, the first photo's time, default 0) in [photos], or join by file name (columns file,pressure_pa)",
                    csv.display(),
                    f.file
                ))
            })?;
            f.time_s = Some(t - *t0.get_or_insert(t));
        }
        // Each photo's pressure is the log's at its time: two photos at one
        // time (EXIF gives the second; sub-seconds only when the camera
        // writes them) or out of order could not be told apart.
        for w in frames.windows(2) {
            let (a, b) = (w[0].time_s.unwrap_or(0.0), w[1].time_s.unwrap_or(0.0));
            if b <= a {
                return Err(cfg(format!(
                    "{} is a pressure log by time, but the camera's clock (EXIF DateTimeOriginal) puts photo {} at {} s, {} photo {} ({} s): each photo's pressure is read at its time, so these two would get {}; give `interval_s` (the time between photos, s) in [photos], or join by file name (columns file,pressure_pa){}",
                    csv.display(),
                    w[1].file,
                    fmt(b),
                    if b == a { "the same time as" } else { "before" },
                    w[0].file,
                    fmt(a),
                    if b == a {
                        "one pressure"
                    } else {
                        "pressures in the wrong order"
                    },
                    if b == a {
                        " (the camera writes times to the second without sub-seconds)"
                    } else {
                        ", or name the photos in the order taken"
                    }
                )));
            }
        }
    }
    let times: Vec<f64> = frames
        .iter()
        .map(|f| f.time_s.unwrap_or(f64::NAN))
        .collect();
    let (t0, t1) = (times[0], times[times.len() - 1]);
    for (f, &t) in frames.iter_mut().zip(&times) {
        f.pressure_pa = log.at(t + offset).map_err(|o| TrackError::OutsideLog {
            csv: csv.clone(),
            message: format!(
                "{} at {} s on the camera's clock is logger time {} s (offset_s = {} s), outside the log's span {}..{} s (the frames span {}..{} s on the camera's clock, {}..{} s on the logger's); fix `offset_s` in [pressure] (logger time = frame time + offset_s), or leave out the frames the log does not cover",
                f.file,
                fmt(t),
                fmt(t + offset),
                fmt(offset),
                fmt(o.first_s),
                fmt(o.last_s),
                fmt(t0),
                fmt(t1),
                fmt(t0 + offset),
                fmt(t1 + offset)
            ),
        })?;
    }
    Ok(())
}

pub(super) fn check_rect(
    path: &Path,
    r: [i64; 4],
    width: usize,
    height: usize,
) -> Result<[usize; 4], TrackError> {
    let [x, y, w, h] = r;
    if x < 0 || y < 0 || w <= 0 || h <= 0 || x + w > width as i64 || y + h > height as i64 {
        return Err(TrackError::RegionOutside {
            path: path.to_path_buf(),
            roi: r,
            width,
            height,
        });
    }
    Ok([x as usize, y as usize, w as usize, h as usize])
}
