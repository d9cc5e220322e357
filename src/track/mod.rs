//! Photos -> apex heights (the only module that uses OpenCV).
//!
//! Tudruj et al. (2023), section 7 (Fig. 13): a template showing the border between the
//! bubble's top and the background is found in every photo inside an
//! elongated region where the apex moves; its position in pixels becomes a
//! height in metres. Here:
//!
//! 1. every photo is decoded to grayscale (in parallel, rayon) and cropped to
//!    the region `roi_px`;
//! 2. the template is matched with OpenCV's `TM_CCOEFF_NORMED`, only in a
//!    window around the position predicted from the last two frames, widened
//!    to the whole region when the score is poor;
//! 3. the peak is refined to sub-pixel precision by a 2-D quadratic fit of
//!    the 3x3 scores around it, and then (default) the apex row is measured
//!    directly by a local edge fit: the edge row of each column near the apex
//!    (centroid of the vertical intensity differences) and a least-squares
//!    parabola through them. The template is cut from one frame, while the
//!    apex curvature changes from frame to frame, which biases the match
//!    itself by a fraction of a pixel; the edge fit has no such bias;
//! 4. pixels become metres with the calibration: `height = (clamp_row - y) *
//!    scale`, or relative to the reference frame plus the pre-bulge height.
//!
//! Image coordinates: the centre of the top-left pixel is (0, 0), x to the
//! right, y down (OpenCV's convention).

pub mod annotate;
pub mod image;
pub(crate) mod matcher;
pub mod synth;

use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::experiment::Experiment;
use crate::io::Table;
use image::{Decoded, Gray};
use matcher::{EdgeFit, EdgeSettings, Match};

/// Why tracking refused its input or failed.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The file cannot be read or decoded.
    #[error("{}: cannot read the image: {reason}; replace the file or remove it from the folder", path.display())]
    Unreadable {
        /// The photo.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The file ends early.
    #[error("{}: the image is truncated: {reason}; copy it again from the camera or remove it", path.display())]
    Truncated {
        /// The photo.
        path: PathBuf,
        /// What is missing.
        reason: String,
    },
    /// Photos of different sizes.
    #[error(
        "{}: the photo is {width}x{height} px but the reference photo {} is {ref_width}x{ref_height} px; all photos of an experiment must have the same size (remove or re-export the odd ones)",
        path.display(), reference.display()
    )]
    MixedSizes {
        /// The odd photo.
        path: PathBuf,
        /// Its size.
        width: usize,
        /// Its size.
        height: usize,
        /// The reference photo.
        reference: PathBuf,
        /// The reference size.
        ref_width: usize,
        /// The reference size.
        ref_height: usize,
    },
    /// The region (or the template rectangle) is not inside the image.
    #[error(
        "{}: the rectangle [x, y, width, height] = {roi:?} px is not inside the {width}x{height} px image; fix `roi_px` (or `template_rect_px`) in [photos] so that x >= 0, y >= 0, x + width <= {width} and y + height <= {height}",
        path.display()
    )]
    RegionOutside {
        /// The photo it was checked against.
        path: PathBuf,
        /// The rectangle.
        roi: [i64; 4],
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
    },
    /// The template does not fit in the region.
    #[error(
        "{}: the template is {tw}x{th} px but the region roi_px = {roi:?} is only {rw}x{rh} px; the template must fit inside the region: enlarge `roi_px` or use a smaller template",
        experiment.display(), rw = roi[2], rh = roi[3]
    )]
    TemplateLargerThanRegion {
        /// The experiment file.
        experiment: PathBuf,
        /// Template width.
        tw: usize,
        /// Template height.
        th: usize,
        /// The region.
        roi: [i64; 4],
    },
    /// A photo has no row in the pressure log.
    #[error(
        "{}: no pressure for photo `{file}`; add a row `{file},<pressure in Pa>` (columns file,pressure_pa) or remove the photo",
        csv.display()
    )]
    NoPressure {
        /// The photo's file name.
        file: String,
        /// The pressure log.
        csv: PathBuf,
    },
    /// The photo folder is empty.
    #[error("{}: the photo folder is empty; put the photos there or fix `dir` in [photos]", dir.display())]
    EmptyFolder {
        /// The folder.
        dir: PathBuf,
    },
    /// The glob is not a valid pattern.
    #[error(
        "{}: glob = \"{glob}\" is not a valid pattern ({reason}); fix `glob` in [photos] (`*`, `?`, `[a-z]`, `[!a-z]`)",
        dir.display()
    )]
    BadGlob {
        /// The folder.
        dir: PathBuf,
        /// The pattern.
        glob: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The glob matches no file.
    #[error(
        "{}: no file matches glob = \"{glob}\" (the folder holds {count} files, e.g. {examples}); fix `glob` in [photos]",
        dir.display()
    )]
    GlobNoMatch {
        /// The folder.
        dir: PathBuf,
        /// The pattern.
        glob: String,
        /// How many files the folder holds.
        count: usize,
        /// A few of them.
        examples: String,
    },
    /// The template was not found well enough in a frame.
    #[error(
        "{}: frame {frame}: the best template match scores {score:.3} < --min-score {min:.3}; the apex is not where the template says (check the photo), or lower --min-score, or pass --skip-bad-frames to leave such frames out",
        path.display()
    )]
    LowScore {
        /// The photo.
        path: PathBuf,
        /// Frame index.
        frame: usize,
        /// Best score.
        score: f64,
        /// The threshold.
        min: f64,
    },
    /// The experiment file lacks or contradicts a setting.
    #[error("{}: {message}", path.display())]
    Config {
        /// The experiment file.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The pressure log itself is malformed.
    #[error(transparent)]
    Input(#[from] crate::io::InputError),
    /// An output file could not be written.
    #[error("{}: cannot write: {reason}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// OpenCV failed on valid input.
    #[error("OpenCV failed: {0}")]
    OpenCv(String),
}

impl TrackError {
    /// True when the error is the user's input being refused (exit 2), false
    /// when the work itself failed.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, TrackError::OpenCv(_) | TrackError::Write { .. })
    }
}

/// One photo to track.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Path of the photo.
    pub path: PathBuf,
    /// Its file name (the key into the pressure log).
    pub file: String,
    /// Pressure at the photo, Pa.
    pub pressure_pa: f64,
}

/// Where heights are measured from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeightOrigin {
    /// The clamp plane is this image row, px.
    ClampRow(f64),
    /// Heights relative to the reference frame's apex, plus the pre-bulge
    /// height `h0` of the specimen.
    Reference {
        /// Apex height at the reference frame, m.
        prebulge_height_m: f64,
    },
}

/// Pixels to metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    /// Scale, m per px.
    pub metres_per_pixel: f64,
    /// Origin of heights.
    pub origin: HeightOrigin,
}

/// Where the template comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum TemplateSource {
    /// An image file.
    File(PathBuf),
    /// A rectangle `[x, y, w, h]` of the reference frame.
    Rect([i64; 4]),
}

/// Everything `track` needs, resolved from the experiment file.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// The experiment file (for error messages).
    pub experiment: PathBuf,
    /// Photos in natural order, with their pressures.
    pub frames: Vec<Frame>,
    /// Region where the apex moves, `[x, y, w, h]` px.
    pub roi: [i64; 4],
    /// The template.
    pub template: TemplateSource,
    /// Index of the reference frame.
    pub reference_frame: usize,
    /// Apex position inside the template, px (None: its centre).
    pub apex_in_template: Option<[f64; 2]>,
    /// Pixels to metres.
    pub calibration: Calibration,
}

/// How the apex position is refined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Refine {
    /// The integer-pixel peak of the match score (OpenCV's minMaxLoc alone).
    Integer,
    /// A 2-D quadratic fit of the 3x3 scores around the peak.
    Quadratic,
    /// Template match, then the edge fit: the row from a parabola through the
    /// top edge near the apex, the column from the edge's mirror symmetry.
    Edge,
}

impl Refine {
    /// The name as settings files and the command line spell it.
    pub fn name(self) -> &'static str {
        match self {
            Refine::Integer => "integer",
            Refine::Quadratic => "quadratic",
            Refine::Edge => "edge",
        }
    }
}

/// Settings of a tracking run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Refinement of the apex position.
    pub refine: Refine,
    /// Frames whose best score is below this are bad.
    pub min_score: f64,
    /// Leave bad frames out (and report them) instead of failing.
    pub skip_bad_frames: bool,
    /// Margin of the search window around the predicted position, px.
    pub search_margin_px: usize,
    /// Half-width of the edge fit's span of columns, px (`None`: half the
    /// template width).
    pub edge_span_px: Option<usize>,
    /// Half-height of each column's edge window, px.
    pub edge_window_px: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            refine: Refine::Edge,
            min_score: 0.5,
            skip_bad_frames: false,
            search_margin_px: 8,
            edge_span_px: None,
            edge_window_px: 4,
        }
    }
}

/// The result for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameResult {
    /// Index of the photo in natural order (0-based).
    pub frame: usize,
    /// File name.
    pub file: String,
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex column, px (image coordinates).
    pub apex_x_px: f64,
    /// Apex row, px (image coordinates).
    pub apex_y_px: f64,
    /// TM_CCOEFF_NORMED at the best match.
    pub score: f64,
    /// Apex height above the clamp plane, m (`h + h0`, with `h0` the pre-bulge height).
    pub height_m: f64,
    /// 1-sigma uncertainty of `height_m` from the image measurement alone, m.
    pub height_std_m: f64,
    /// Statistical uncertainty of `apex_y_px`, px.
    pub apex_y_std_px: f64,
    /// Apex by the integer match, px (image coordinates).
    pub apex_integer_px: [f64; 2],
    /// Apex by the quadratic peak fit, px (image coordinates).
    pub apex_quadratic_px: [f64; 2],
    /// The edge fit, when it succeeded (image coordinates).
    pub edge: Option<EdgeFit>,
}

/// A frame left out.
#[derive(Debug, Clone, PartialEq)]
pub struct Skipped {
    /// Frame index.
    pub frame: usize,
    /// File name.
    pub file: String,
    /// Its best score.
    pub score: f64,
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracked {
    /// One row per tracked frame, in frame order.
    pub rows: Vec<FrameResult>,
    /// Frames left out with `skip_bad_frames`.
    pub skipped: Vec<Skipped>,
    /// Image size, px.
    pub image_size: [usize; 2],
    /// Time spent matching and fitting (the sequential part), s.
    pub locate_seconds: f64,
}

impl Tracked {
    /// `heights.csv`: `frame,file,pressure_pa,apex_x_px,apex_y_px,score,
    /// height_m,height_std_m`, one row per tracked frame.
    pub fn heights_csv(&self) -> crate::io::CsvOut {
        use crate::io::fmt_num;
        let mut out = crate::io::CsvOut::new(&[
            "frame",
            "file",
            "pressure_pa",
            "apex_x_px",
            "apex_y_px",
            "score",
            "height_m",
            "height_std_m",
        ]);
        for r in &self.rows {
            out.row(&[
                r.frame.to_string(),
                r.file.clone(),
                fmt_num(Some(r.pressure_pa)),
                fmt_num(Some(r.apex_x_px)),
                fmt_num(Some(r.apex_y_px)),
                format!("{:.4}", r.score),
                fmt_num(Some(r.height_m)),
                fmt_num(Some(r.height_std_m)),
            ]);
        }
        out
    }
}

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
    let rd = std::fs::read_dir(dir).map_err(|e| TrackError::Unreadable {
        path: dir.to_path_buf(),
        reason: format!("cannot list the photo folder: {e}"),
    })?;
    let mut names: Vec<String> = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| TrackError::Unreadable {
            path: dir.to_path_buf(),
            reason: format!("cannot list the photo folder: {e}"),
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
        cfg("no [photos] table: add one with `dir`, `glob` and `roi_px` (see docs/track.md)".into())
    })?;
    let cal = e.calibration.as_ref().ok_or_else(|| {
        cfg("no [calibration] table: add `metres_per_pixel` (or `points_px` and `distance_m`) and `clamp_row_px`".into())
    })?;
    let pressure = e.pressure.as_ref().ok_or_else(|| {
        cfg("no [pressure] table: add `csv = \"pressure.csv\"` (columns file,pressure_pa)".into())
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

    let dir = e.resolve(&photos.dir);
    let paths = list_photos(&dir, &photos.glob)?;
    let csv = e.resolve(&pressure.csv);
    let pressures = read_pressures(&csv)?;
    let mut frames = Vec::with_capacity(paths.len());
    for p in paths {
        let file = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let pressure_pa = *pressures.get(&file).ok_or_else(|| TrackError::NoPressure {
            file: file.clone(),
            csv: csv.clone(),
        })?;
        frames.push(Frame {
            path: p,
            file,
            pressure_pa,
        });
    }
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
        reference_frame: photos.reference_frame,
        apex_in_template: photos.apex_in_template_px,
        calibration: Calibration {
            metres_per_pixel: scale,
            origin,
        },
    })
}

fn check_rect(
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

/// Systematic error of the edge fit that its residuals do not show, px: the
/// RMS apex-row error measured on clean synthetic sequences (background
/// texture and shading gradients across the edge; docs/track.md) is 0.015 px,
/// rounded up. Added in quadrature to every edge-fit uncertainty.
pub const EDGE_BIAS_FLOOR_PX: f64 = 0.02;

/// Per-frame measurement in region coordinates, before calibration.
struct Located {
    m: Match,
    edge: Option<EdgeFit>,
    /// Axis column from the edge's mirror symmetry and its standard error, px.
    axis: Option<(f64, f64)>,
}

/// Tracks every frame of `setup`; `tick` is called once per frame done.
pub fn track(
    setup: &Setup,
    opts: &Options,
    tick: &(dyn Fn() + Sync),
) -> Result<Tracked, TrackError> {
    // The photos are decoded in parallel by rayon; OpenCV's own thread pool
    // would only compete with it for the cores.
    opencv::core::set_num_threads(1).map_err(|e| TrackError::OpenCv(e.to_string()))?;
    let n = setup.frames.len();
    let r = setup.roi;
    let roi_req = (r[0] >= 0 && r[1] >= 0 && r[2] > 0 && r[3] > 0)
        .then(|| [r[0] as usize, r[1] as usize, r[2] as usize, r[3] as usize]);
    // The pipeline: the rayon pool decodes the photos roughly in order
    // (`par_bridge`), the reference photo first (its region and the
    // template's rectangle), and sends them through a bounded channel; this thread takes
    // them back in frame order and tracks them one by one (each search
    // starts from the previous frame's position). No barrier stops the
    // decoders, and memory holds only a few regions at a time.
    // A deep queue (up to 128 MB of regions) keeps the decoders running
    // when the matching thread waits for a core on a busy machine.
    let crop_bytes = roi_req.map_or(1 << 20, |r| (r[2] * r[3]).max(1));
    let depth =
        ((128usize << 20) / crop_bytes).clamp(2 * rayon::current_num_threads().max(1) + 2, 1024);
    let (tx, rx) = std::sync::mpsc::sync_channel::<(usize, Result<Decoded, TrackError>)>(depth);
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let reference = &setup.frames[setup.reference_frame];
    std::thread::scope(|scope| {
        let cancel = &cancel;
        scope.spawn(move || {
            // The reference photo first, cropped to the region and the
            // template's rectangle, then the others' regions.
            let r = setup.reference_frame;
            let order = std::iter::once(r).chain((0..n).filter(|&i| i != r));
            order.par_bridge().for_each(|i| {
                if cancel.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                let path = &setup.frames[i].path;
                let decoded = match (i == r, reference_box(setup)) {
                    (true, Some(b)) => decode_frame(path, Some(b)),
                    (true, None) => image::read_gray(path, None),
                    (false, _) => decode_frame(path, roi_req),
                };
                // A closed channel means the matching stopped on an error.
                let _ = tx.send((i, decoded));
            });
        });
        let result = match_frames(setup, opts, tick, reference, rx);
        if result.is_err() {
            cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        result
    })
}

/// The sequential half of [`track`]: the reference photo, the template, then
/// every frame's region in order from `rx`.
fn match_frames(
    setup: &Setup,
    opts: &Options,
    tick: &(dyn Fn() + Sync),
    reference: &Frame,
    rx: std::sync::mpsc::Receiver<(usize, Result<Decoded, TrackError>)>,
) -> Result<Tracked, TrackError> {
    let n = setup.frames.len();
    // Decoded photos that arrived before their turn.
    let mut early = std::collections::BTreeMap::new();
    let mut take = |i: usize| -> Result<Decoded, TrackError> {
        if let Some(d) = early.remove(&i) {
            return d;
        }
        loop {
            match rx.recv() {
                Ok((k, d)) if k == i => return d,
                Ok((k, d)) => {
                    early.insert(k, d);
                }
                Err(_) => {
                    return Err(TrackError::OpenCv(format!(
                        "the decoding of photo {} stopped early",
                        setup.frames[i].path.display()
                    )));
                }
            }
        }
    };
    let full = take(setup.reference_frame)?;
    let (width, height) = (full.width, full.height);
    // The reference arrives cropped to `reference_box` (or whole).
    let [bx, by] = match reference_box(setup) {
        Some(b) => [b[0], b[1]],
        None => [0, 0],
    };
    let roi = check_rect(&reference.path, setup.roi, width, height)?;
    let templ: Gray = match &setup.template {
        TemplateSource::File(p) => image::read_gray(p, None)?.crop,
        TemplateSource::Rect(r) => {
            let [x, y, w, h] = check_rect(&reference.path, *r, width, height)?;
            full.crop.crop(x - bx, y - by, w, h)
        }
    };
    let ref_crop = full.crop.crop(roi[0] - bx, roi[1] - by, roi[2], roi[3]);
    drop(full);
    if templ.width > roi[2] || templ.height > roi[3] {
        return Err(TrackError::TemplateLargerThanRegion {
            experiment: setup.experiment.clone(),
            tw: templ.width,
            th: templ.height,
            roi: setup.roi,
        });
    }
    let (tmin, tmax) = templ
        .data
        .iter()
        .fold((255u8, 0u8), |(a, b), &v| (a.min(v), b.max(v)));
    if tmax <= tmin {
        return Err(TrackError::Config {
            path: setup.experiment.clone(),
            message: format!(
                "the template ({}x{} px) is uniform (grey level {tmin}): it must show the border between the bubble's top and the background",
                templ.width, templ.height
            ),
        });
    }
    let apex_in_t = setup.apex_in_template.unwrap_or([
        (templ.width as f64 - 1.0) / 2.0,
        (templ.height as f64 - 1.0) / 2.0,
    ]);
    let edge_settings = EdgeSettings {
        half_span_px: opts.edge_span_px.unwrap_or(templ.width / 2).max(3),
        half_window_px: opts.edge_window_px,
    };
    let mut state = Tracker {
        templ: &templ,
        opts,
        edge_settings,
        apex_in_t,
        reduced: {
            // Coarse search on a template about 64-128 px wide; 32-64 px
            // when the edge fit refines (it needs only a seed within a few
            // px, and OpenCV's matching then costs a fraction of decoding).
            let min_width = if opts.refine == Refine::Edge { 32 } else { 64 };
            let mut f = 1;
            while templ.width / (2 * f) >= min_width && templ.height / (2 * f) >= 16 {
                f *= 2;
            }
            match f {
                1 => None,
                f => Some((f, matcher::reduce(&templ, f)?)),
            }
        },
        // A template cut from the reference photo says where the search
        // starts: no search of the whole region for the first frame.
        last: match &setup.template {
            TemplateSource::Rect(r) => {
                Some([(r[0] - roi[0] as i64) as f64, (r[1] - roi[1] as i64) as f64])
            }
            TemplateSource::File(_) => None,
        },
        prev: None,
        curvature: 0.0,
    };
    let mut located: Vec<Option<Located>> = Vec::with_capacity(n);
    let mut skipped = Vec::new();
    let mut locate_time = 0.0;
    while located.len() < n {
        let i = located.len();
        let f = &setup.frames[i];
        let crop_owned;
        let crop: &Gray = if i == setup.reference_frame {
            &ref_crop
        } else {
            let dec = take(i)?;
            if (dec.width, dec.height) != (width, height) {
                return Err(TrackError::MixedSizes {
                    path: f.path.clone(),
                    width: dec.width,
                    height: dec.height,
                    reference: reference.path.clone(),
                    ref_width: width,
                    ref_height: height,
                });
            }
            crop_owned = dec.crop;
            &crop_owned
        };
        let t0 = std::time::Instant::now();
        let loc = state.locate(crop)?;
        locate_time += t0.elapsed().as_secs_f64();
        if loc.m.score < opts.min_score || !loc.m.score.is_finite() {
            if !opts.skip_bad_frames {
                return Err(TrackError::LowScore {
                    path: f.path.clone(),
                    frame: i,
                    score: loc.m.score,
                    min: opts.min_score,
                });
            }
            skipped.push(Skipped {
                frame: i,
                file: f.file.clone(),
                score: loc.m.score,
            });
            state.last = None;
            state.prev = None;
            state.curvature = 0.0;
            located.push(None);
        } else {
            // The next search starts from this frame's refined apex (the
            // template alone slides along a flat top).
            let (apex, _) = state.apex(&loc);
            state.prev = state.last;
            state.last = Some([apex[0] - apex_in_t[0], apex[1] - apex_in_t[1]]);
            state.curvature = loc.edge.map_or(0.0, |e| e.curvature);
            located.push(Some(loc));
        }
        tick();
    }

    // Apex in image coordinates and its statistical uncertainty, px.
    let apex_of = |l: &Located| -> ([f64; 2], f64, [f64; 2], [f64; 2], Option<EdgeFit>) {
        let (off_x, off_y) = (roi[0] as f64, roi[1] as f64);
        let shift = |p: [f64; 2]| [p[0] + off_x, p[1] + off_y];
        let (apex, std) = state.apex(l);
        let int = [l.m.integer[0] + apex_in_t[0], l.m.integer[1] + apex_in_t[1]];
        let quad = [
            l.m.quadratic[0] + apex_in_t[0],
            l.m.quadratic[1] + apex_in_t[1],
        ];
        let edge = l.edge.map(|e| EdgeFit {
            y: e.y + off_y,
            x_vertex: e.x_vertex + off_x,
            ..e
        });
        (shift(apex), std, shift(int), shift(quad), edge)
    };
    let mpp = setup.calibration.metres_per_pixel;
    let (origin_row, origin_std, offset_m) = match setup.calibration.origin {
        HeightOrigin::ClampRow(r) => (r, 0.0, 0.0),
        HeightOrigin::Reference { prebulge_height_m } => {
            let l = located[setup.reference_frame].as_ref().ok_or_else(|| TrackError::Config {
                path: setup.experiment.clone(),
                message: format!(
                    "the reference frame {} ({}) was skipped as bad, and heights are measured from it (no clamp_row_px in [calibration]); choose another reference_frame or give clamp_row_px",
                    setup.reference_frame, reference.file
                ),
            })?;
            let (apex, std, ..) = apex_of(l);
            (apex[1], std, prebulge_height_m)
        }
    };
    let mut rows = Vec::with_capacity(n);
    for (i, l) in located.iter().enumerate() {
        let Some(l) = l else { continue };
        let f = &setup.frames[i];
        let (apex, std, int, quad, edge) = apex_of(l);
        let is_ref_frame = matches!(setup.calibration.origin, HeightOrigin::Reference { .. })
            && i == setup.reference_frame;
        let std_total = if is_ref_frame {
            0.0
        } else {
            std.hypot(origin_std)
        };
        rows.push(FrameResult {
            frame: i,
            file: f.file.clone(),
            pressure_pa: f.pressure_pa,
            apex_x_px: apex[0],
            apex_y_px: apex[1],
            score: l.m.score,
            height_m: (origin_row - apex[1]) * mpp + offset_m,
            height_std_m: std_total * mpp,
            apex_y_std_px: std,
            apex_integer_px: int,
            apex_quadratic_px: quad,
            edge,
        });
    }
    Ok(Tracked {
        rows,
        skipped,
        image_size: [width, height],
        locate_seconds: locate_time,
    })
}

/// The part of the reference photo tracking needs: the smallest rectangle
/// holding the region and the template's rectangle (`None`, the whole photo,
/// when either is not a rectangle of non-negative position and positive
/// size: the checks against the photo's size then name it). When the box
/// does not fit in the photo, neither does one of the two, which the same
/// checks report.
fn reference_box(setup: &Setup) -> Option<[usize; 4]> {
    let valid = |r: [i64; 4]| r[0] >= 0 && r[1] >= 0 && r[2] > 0 && r[3] > 0;
    let mut b = setup.roi;
    if !valid(b) {
        return None;
    }
    if let TemplateSource::Rect(t) = setup.template {
        if !valid(t) {
            return None;
        }
        let x0 = b[0].min(t[0]);
        let y0 = b[1].min(t[1]);
        let x1 = (b[0] + b[2]).max(t[0] + t[2]);
        let y1 = (b[1] + b[3]).max(t[1] + t[3]);
        b = [x0, y0, x1 - x0, y1 - y0];
    }
    Some(b.map(|v| v as usize))
}

/// Reads one photo and crops the region (an empty crop when the region does
/// not fit: the size check against the reference photo then names the file).
fn decode_frame(path: &Path, roi: Option<[usize; 4]>) -> Result<Decoded, TrackError> {
    let bytes = std::fs::read(path).map_err(|e| TrackError::Unreadable {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    image::decode_gray_lenient(path, &bytes, roi)
}

struct Tracker<'a> {
    templ: &'a Gray,
    opts: &'a Options,
    edge_settings: EdgeSettings,
    /// Apex position inside the template, px.
    apex_in_t: [f64; 2],
    /// Reduction factor and reduced template for the coarse search, when the
    /// template is wider than 128 px.
    reduced: Option<(usize, Gray)>,
    /// Template position (region coordinates) in the last two tracked frames.
    last: Option<[f64; 2]>,
    prev: Option<[f64; 2]>,
    /// Edge curvature of the last tracked frame, 1/px (0: none yet).
    curvature: f64,
}

impl Tracker<'_> {
    /// Template search in `img` (full or reduced resolution): around the
    /// position predicted from the last two frames, widened (four times the
    /// margin, then the whole image) on a poor score or a peak on the
    /// window's border.
    fn search(
        &self,
        img: &Gray,
        templ: &Gray,
        last: Option<[f64; 2]>,
        prev: Option<[f64; 2]>,
        margin_px: f64,
    ) -> Result<Match, TrackError> {
        let (tw, th) = (templ.width, templ.height);
        let (rw, rh) = (img.width, img.height);
        let whole = [0, 0, rw, rh];
        let Some(last) = last else {
            return matcher::match_in_window(img, templ, whole);
        };
        let vel = prev.map_or([0.0, 0.0], |p| [last[0] - p[0], last[1] - p[1]]);
        let pred = [last[0] + vel[0], last[1] + vel[1]];
        let margin = margin_px + 0.5 * vel[0].abs().max(vel[1].abs());
        // The window of positions within `margin` of the prediction.
        let window = |margin: f64| {
            let x0 = (pred[0] - margin).floor().clamp(0.0, (rw - tw) as f64) as usize;
            let y0 = (pred[1] - margin).floor().clamp(0.0, (rh - th) as f64) as usize;
            let x1 = ((pred[0] + margin).ceil().max(0.0) as usize + tw).clamp(x0 + tw, rw);
            let y1 = ((pred[1] + margin).ceil().max(0.0) as usize + th).clamp(y0 + th, rh);
            [x0, y0, x1 - x0, y1 - y0]
        };
        // A good match: a high score, and a peak off the window's top and
        // bottom borders (where the apex could have moved past). A peak on
        // a side border with a high score is the template sliding along a
        // flat top, which the edge fit resolves; widening would only let it
        // slide further.
        let good = |m: &Match, win: [usize; 4]| {
            let (lo, hi) = (win[1], win[1] + win[3] - th);
            let y = m.integer[1];
            let on_border = (y <= lo as f64 && lo > 0) || (y >= hi as f64 && hi < rh - th);
            m.score >= self.opts.min_score.max(0.8) && !on_border
        };
        // Widened in two steps on a poor match: four times the margin, then
        // the whole region.
        let wins = [window(margin), window(4.0 * margin), whole];
        for (k, &win) in wins.iter().enumerate() {
            if k > 0 && win == wins[k - 1] {
                continue;
            }
            let m = matcher::match_in_window(img, templ, win)?;
            if win == whole || good(&m, win) {
                return Ok(m);
            }
        }
        unreachable!("the last window is the whole region")
    }

    /// The apex of a located frame in region coordinates and its
    /// statistical uncertainty, px, as `opts.refine` asks.
    fn apex(&self, l: &Located) -> ([f64; 2], f64) {
        let t = self.apex_in_t;
        let int = [l.m.integer[0] + t[0], l.m.integer[1] + t[1]];
        let quad = [l.m.quadratic[0] + t[0], l.m.quadratic[1] + t[1]];
        // Without an edge fit, the error bound of a peak on the pixel grid.
        let grid = 0.5;
        // The edge fit's statistical error plus its bias floor.
        let edge_std = |e: &EdgeFit| e.y_std.hypot(EDGE_BIAS_FLOOR_PX);
        match (self.opts.refine, l.edge) {
            // The column from the edge's symmetry, else the parabola's
            // vertex when the edge's curvature pins it down at all: the
            // template sees mostly a horizontal edge, so its column follows
            // the background texture (errors of several px measured).
            (Refine::Edge, Some(e)) if l.axis.is_some_and(|(_, s)| s < e.x_std) => {
                ([l.axis.map_or(e.x_vertex, |a| a.0), e.y], edge_std(&e))
            }
            (Refine::Edge, Some(e)) if e.x_std < 0.5 * self.edge_settings.half_span_px as f64 => {
                ([e.x_vertex, e.y], edge_std(&e))
            }
            (Refine::Edge, Some(e)) => ([quad[0], e.y], edge_std(&e)),
            (Refine::Edge, None) | (Refine::Quadratic, None) => (quad, grid),
            (Refine::Integer, None) => (int, grid),
            // The template's own bias is the gap to the edge fit.
            (Refine::Quadratic, Some(e)) => (quad, edge_std(&e).hypot(quad[1] - e.y)),
            (Refine::Integer, Some(e)) => (int, edge_std(&e).hypot(int[1] - e.y)),
        }
    }

    fn locate(&self, crop: &Gray) -> Result<Located, TrackError> {
        let margin = self.opts.search_margin_px as f64;
        let m = match &self.reduced {
            None => self.search(crop, self.templ, self.last, self.prev, margin)?,
            Some((f, small_t)) => {
                // Coarse search at 1/f resolution, then the full-resolution
                // match in a window of +-(f + 2) px around it.
                let f = *f;
                let fl = f as f64;
                let small = matcher::reduce(crop, f)?;
                let down = |p: [f64; 2]| [p[0] / fl, p[1] / fl];
                let mc = self.search(
                    &small,
                    small_t,
                    self.last.map(down),
                    self.prev.map(down),
                    (margin / fl).max(2.0),
                )?;
                if self.opts.refine == Refine::Edge {
                    // The edge fit needs a seed within a few px, not the
                    // full-resolution match: report the coarse one scaled up.
                    let up = |p: [f64; 2]| [p[0] * fl, p[1] * fl];
                    Match {
                        integer: up(mc.integer),
                        quadratic: up(mc.quadratic),
                        score: mc.score,
                    }
                } else {
                    let (tw, th) = (self.templ.width, self.templ.height);
                    let r = f + 2;
                    let cx = (mc.quadratic[0] * fl).round() as i64;
                    let cy = (mc.quadratic[1] * fl).round() as i64;
                    let x0 = (cx - r as i64).clamp(0, (crop.width - tw) as i64) as usize;
                    let y0 = (cy - r as i64).clamp(0, (crop.height - th) as i64) as usize;
                    let x1 = (x0 + tw + 2 * r).min(crop.width);
                    let y1 = (y0 + th + 2 * r).min(crop.height);
                    matcher::match_in_window(crop, self.templ, [x0, y0, x1 - x0, y1 - y0])?
                }
            }
        };
        // The edge fit runs in every mode: in the integer and quadratic modes
        // it only serves to state their uncertainty.
        let apex = [
            m.quadratic[0] + self.apex_in_t[0],
            m.quadratic[1] + self.apex_in_t[1],
        ];
        let mut cols = matcher::Columns::new(crop, self.edge_settings.half_window_px);
        let edge = matcher::edge_fit_in(
            &mut cols,
            apex[0],
            apex[1],
            self.curvature,
            self.edge_settings,
        );
        // The axis over the whole region's width (less the slope margin).
        let axis = edge.and_then(|e| {
            let half = (crop.width / 2).saturating_sub(1);
            matcher::axis_fit_in(&mut cols, &e, half)
        });
        Ok(Located { m, edge, axis })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order() {
        let mut v = vec!["img10.png", "img2.png", "img1.png", "img02.png", "a.png"];
        v.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            v,
            ["a.png", "img1.png", "img02.png", "img2.png", "img10.png"]
        );
    }

    #[test]
    fn globs() {
        assert!(glob_match("*.png", "frame_001.png"));
        assert!(!glob_match("*.png", "frame_001.jpg"));
        assert!(glob_match("frame_??.jp*g", "frame_12.jpeg"));
        assert!(glob_match("f[0-9]*", "f7x"));
        assert!(!glob_match("f[!0-9]*", "f7x"));
        assert!(glob_match("*", "anything"));
    }

    fn write_tiny_experiment(dir: &Path) {
        let spec = spec(301, 0.0, 0.0, image::Encoding::Png);
        let spec = synth::SequenceSpec {
            width: 160,
            height: 120,
            ..spec
        };
        synth::write_sequence(dir, &spec, &synth::cap_frames(0.0375, 0.015, 3)).unwrap();
    }

    #[test]
    fn truncated_files_are_caught_before_decoding() {
        let g = image::Gray {
            width: 16,
            height: 8,
            data: (0..128).map(|v| v as u8).collect(),
        };
        for enc in [image::Encoding::Png, image::Encoding::Jpeg(90)] {
            let bytes = image::encode(&g, enc).unwrap();
            assert!(image::check_complete(Path::new("a"), &bytes).is_ok());
            let cut = &bytes[..bytes.len() - 5];
            let e = image::check_complete(Path::new("a.img"), cut).unwrap_err();
            assert!(matches!(e, TrackError::Truncated { .. }), "{e}");
            let e = image::decode_gray(Path::new("b.img"), cut, None).unwrap_err();
            assert!(
                e.to_string().contains("b.img") && e.to_string().contains("truncated"),
                "{e}"
            );
        }
        let e = image::decode_gray(Path::new("c.png"), b"not an image", None).unwrap_err();
        assert!(matches!(e, TrackError::Unreadable { .. }), "{e}");
    }

    #[test]
    fn empty_folder_and_unmatched_glob_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let e = list_photos(d.path(), "*.png").unwrap_err();
        assert!(matches!(e, TrackError::EmptyFolder { .. }), "{e}");
        std::fs::write(d.path().join("a1.jpg"), b"x").unwrap();
        let e = list_photos(d.path(), "*.png").unwrap_err();
        assert!(e.to_string().contains("`a1.jpg`"), "{e}");
        assert_eq!(list_photos(d.path(), "a?.jpg").unwrap().len(), 1);
        let e = list_photos(d.path(), "a[1.jpg").unwrap_err();
        assert!(matches!(e, TrackError::BadGlob { .. }), "{e}");
    }

    #[test]
    fn pressure_log_must_cover_every_photo_once() {
        let d = tempfile::tempdir().unwrap();
        write_tiny_experiment(d.path());
        let exp = d.path().join("experiment.toml");
        std::fs::write(
            d.path().join("pressure.csv"),
            "file,pressure_pa\nframe_001.png,100\nframe_002.png,200\n",
        )
        .unwrap();
        let e = setup_from_experiment(&Experiment::read(&exp).unwrap()).unwrap_err();
        assert!(
            e.to_string()
                .contains("no pressure for photo `frame_003.png`"),
            "{e}"
        );
        std::fs::write(
            d.path().join("pressure.csv"),
            "file,pressure_pa\nframe_001.png,100\nframe_001.png,200\n",
        )
        .unwrap();
        let e = setup_from_experiment(&Experiment::read(&exp).unwrap()).unwrap_err();
        assert!(
            e.to_string().contains("line 3") && e.to_string().contains("already"),
            "{e}"
        );
    }

    #[test]
    fn region_and_template_are_checked_against_the_image() {
        let d = tempfile::tempdir().unwrap();
        write_tiny_experiment(d.path());
        let exp = Experiment::read(d.path().join("experiment.toml")).unwrap();
        let mut setup = setup_from_experiment(&exp).unwrap();
        setup.roi = [100, 50, 100, 20];
        let e = track(&setup, &Options::default(), &|| {}).unwrap_err();
        assert!(
            matches!(
                e,
                TrackError::RegionOutside {
                    width: 160,
                    height: 120,
                    ..
                }
            ),
            "{e}"
        );
        setup.roi = [60, 40, 10, 40];
        let e = track(&setup, &Options::default(), &|| {}).unwrap_err();
        assert!(
            matches!(
                e,
                TrackError::TemplateLargerThanRegion { tw: 16, th: 8, .. }
            ),
            "{e}"
        );
    }

    /// Writes a cap sequence, tracks it, returns the apex errors.
    fn accuracy(spec: &synth::SequenceSpec, n: usize, refine: Refine) -> synth::ApexErrors {
        let dir = tempfile::tempdir().unwrap();
        let frames = synth::cap_frames(spec.specimen.radius_m, 0.6 * spec.specimen.radius_m, n);
        let w = synth::write_sequence(dir.path(), spec, &frames).unwrap();
        let e = Experiment::read(dir.path().join("experiment.toml")).unwrap();
        let setup = setup_from_experiment(&e).unwrap();
        let opts = Options {
            refine,
            ..Options::default()
        };
        let t = track(&setup, &opts, &|| {}).unwrap();
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
        synth::SequenceSpec {
            width: 640,
            height: 480,
            seed,
            blur_px: blur,
            noise_grey: noise,
            drift: 0.03,
            encoding: enc,
            specimen: crate::experiment::Specimen {
                radius_m: 0.0375,
                thickness_m: 0.00035,
                poisson: 0.45,
                prebulge_height_m: 0.0,
            },
        }
    }

    // Seeds 101.. are used by tests only; the benchmarks use seeds 1..=3.
    #[test]
    fn sub_pixel_apex_without_noise() {
        let a = accuracy(&spec(101, 0.0, 0.0, image::Encoding::Png), 10, Refine::Edge);
        assert_row_rms(&a, 0.05);
    }

    /// A 1280x960 sequence: the 128 px template is searched at a quarter of
    /// the resolution for the edge fit's seed; the integer mode searches at
    /// half resolution first, then matches at full resolution near the
    /// coarse peak.
    #[test]
    fn coarse_to_fine_search_on_larger_photos() {
        let s = synth::SequenceSpec {
            width: 1280,
            height: 960,
            ..spec(103, 1.5, 3.0, image::Encoding::Jpeg(85))
        };
        let a = accuracy(&s, 6, Refine::Edge);
        assert_row_rms(&a, 0.1);
        // The full-resolution integer match (after the coarse search at
        // half resolution) is right to a pixel.
        let i = accuracy(&s, 6, Refine::Integer);
        assert!(
            i.integer[1] <= 1.0,
            "integer match row error {} px",
            i.integer[1]
        );
    }

    /// 4000x3000 photos (the 400 px template searched at 1/8 of the
    /// resolution for the edge fit's seed). Slow in a debug build (drawing
    /// the photos): `cargo test --lib -- --ignored large_photos`.
    #[test]
    #[ignore]
    fn sub_pixel_apex_on_large_photos() {
        let s = synth::SequenceSpec {
            width: 4000,
            height: 3000,
            ..spec(104, 1.0, 2.0, image::Encoding::Jpeg(90))
        };
        let a = accuracy(&s, 6, Refine::Edge);
        assert_row_rms(&a, 0.1);
    }

    #[test]
    fn sub_pixel_apex_with_noise_blur_and_jpeg() {
        let a = accuracy(
            &spec(102, 1.5, 3.0, image::Encoding::Jpeg(85)),
            10,
            Refine::Edge,
        );
        assert_row_rms(&a, 0.1);
    }
}
