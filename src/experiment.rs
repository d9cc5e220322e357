//! The experiment file (`experiment.toml`): the specimen, and for later stages
//! the photos, the calibration and the pressure log.
//!
//! ```toml
//! [specimen]
//! radius_m = 0.0375          # free radius a of the clamped disc
//! thickness_m = 0.00035      # initial thickness t
//! poisson = 0.45             # Poisson ratio nu, in [0, 0.5)
//! prebulge_height_m = 0.0    # apex height h0 at p = 0+ (default 0)
//! thickness_std_m = 1e-5     # standard deviation of t (default 0: exact)
//! radius_std_m = 1e-4        # standard deviation of a (default 0: exact)
//!
//! [window]                   # optional: a non-circular clamped opening
//! shape = "ellipse"          # circle (default) | ellipse | rectangle
//! semi_axes_m = [0.0375, 0.01875]   # ellipse; rectangle: length_m, width_m
//! ```
//!
//! With a non-circular `[window]`, `bulge run` simulates the window with the
//! membrane model and corrects the law to the heights through it (the
//! stress stage's spherical-cap formulas take `radius_m`, best the
//! window's half-width: their law is only the correction's start).
//!
//! The standard deviations of the inputs (`[specimen] thickness_std_m`,
//! `radius_std_m`; `[pressure] std_pa`, `relative_std`; `[calibration]
//! metres_per_pixel_std`, `clamp_row_std_px`) are gathered by
//! [`Experiment::uncertainty`] and carried to the fitted parameters
//! ([`crate::fit::uncertainty`]).
//!
//! Names may grow, never change. Paths inside the file are relative to the
//! file's own folder.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::io::{BadValue, InputError, read_toml};

#[cfg(test)]
mod tests;

/// The clamped disc under test. All lengths in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Specimen {
    /// Free radius `a` of the clamped disc, m (> 0).
    pub radius_m: f64,
    /// Initial thickness `t`, m (> 0).
    pub thickness_m: f64,
    /// Poisson ratio, in [0, 0.5).
    pub poisson: f64,
    /// Height `h0` of the stress-free shape over the clamp plane, m (>= 0,
    /// default 0: a flat disc; a slack membrane's stress-free shape is a
    /// spherical cap of this height). In an experiment file `"fit"` asks
    /// `bulge run` to estimate it from the heights (read as NaN here until
    /// [`Experiment::read`] takes it out).
    #[serde(default, deserialize_with = "height_or_fit")]
    pub prebulge_height_m: f64,
}

/// A height in metres, or the word `fit` (as NaN).
fn height_or_fit<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum HeightOrFit {
        Number(f64),
        Word(String),
    }
    match HeightOrFit::deserialize(d)? {
        HeightOrFit::Number(v) => Ok(v),
        HeightOrFit::Word(w) if w == "fit" => Ok(f64::NAN),
        HeightOrFit::Word(w) => Err(serde::de::Error::custom(format!(
            "prebulge_height_m = \"{w}\": give a height in metres (e.g. 0.0035) or \"fit\" (estimated from the heights by bulge run)"
        ))),
    }
}

/// `[window]`: the shape of the clamped opening (default a circle of the
/// specimen's `radius_m`). The window is centred on the apex, its first
/// axis along x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "shape", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Window {
    /// The circle of radius `radius_m` (the exact axisymmetric path).
    #[default]
    Circle,
    /// An ellipse.
    Ellipse {
        /// Semi-axes, m.
        semi_axes_m: [f64; 2],
    },
    /// A rectangle.
    Rectangle {
        /// Side along x, m.
        length_m: f64,
        /// Side along y, m.
        width_m: f64,
    },
}

impl Window {
    /// True for the circular window.
    pub fn is_circle(&self) -> bool {
        matches!(self, Window::Circle)
    }

    /// Checks the sizes; the message names the key, the value and the fix.
    pub fn validate(&self) -> Result<(), BadValue> {
        let bad = |key: &'static str, v: f64| {
            BadValue::new(
                key,
                format!("[window] {key} = {v} must be a positive length in metres"),
            )
        };
        match *self {
            Window::Circle => Ok(()),
            Window::Ellipse { semi_axes_m } => {
                match semi_axes_m.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
                    Some(v) => Err(bad("semi_axes_m", *v)),
                    None => Ok(()),
                }
            }
            Window::Rectangle { length_m, width_m } => {
                for (k, v) in [("length_m", length_m), ("width_m", width_m)] {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(bad(k, v));
                    }
                }
                Ok(())
            }
        }
    }
}

/// `[specimen]` as the file has it: the specimen and the standard
/// deviations of its dimensions.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecimenFile {
    radius_m: f64,
    thickness_m: f64,
    poisson: f64,
    #[serde(default, deserialize_with = "height_or_fit")]
    prebulge_height_m: f64,
    #[serde(default)]
    thickness_std_m: Option<f64>,
    #[serde(default)]
    radius_std_m: Option<f64>,
}

impl SpecimenFile {
    fn specimen(&self) -> Specimen {
        Specimen {
            radius_m: self.radius_m,
            thickness_m: self.thickness_m,
            poisson: self.poisson,
            prebulge_height_m: self.prebulge_height_m,
        }
    }

    /// The standard deviations, checked: zero or positive, and below the
    /// dimension itself.
    fn std(&self) -> Result<SpecimenStd, BadValue> {
        for (key, sd, of) in [
            ("thickness_std_m", self.thickness_std_m, self.thickness_m),
            ("radius_std_m", self.radius_std_m, self.radius_m),
        ] {
            if let Some(v) = sd
                && !(v.is_finite() && v >= 0.0 && v < of)
            {
                return Err(BadValue::new(
                    key,
                    format!(
                        "{key} = {v} must be a standard deviation in metres, zero or positive and below the dimension itself ({of} m); e.g. 1e-5 for a thickness measured to 10 micrometres"
                    ),
                ));
            }
        }
        Ok(SpecimenStd {
            thickness_std_m: self.thickness_std_m.unwrap_or(0.0),
            radius_std_m: self.radius_std_m.unwrap_or(0.0),
        })
    }
}

/// The standard deviations of the specimen's dimensions, m (0: exact).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SpecimenStd {
    /// Of the thickness.
    pub thickness_std_m: f64,
    /// Of the free radius.
    pub radius_std_m: f64,
}

fn specimen_of_file<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Specimen, D::Error> {
    SpecimenFile::deserialize(d).map(|f| f.specimen())
}

/// A `[specimen]` field out of its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpecimenError {
    /// The free radius is not a positive length.
    #[error(
        "radius_m = {0} must be a positive length in metres (the free radius of the disc, e.g. 0.0375)"
    )]
    Radius(f64),
    /// The thickness is not a positive length.
    #[error("thickness_m = {0} must be a positive length in metres (e.g. 0.00035)")]
    Thickness(f64),
    /// The Poisson ratio is outside [0, 0.5).
    #[error(
        "poisson = {0} must be in [0, 0.5) (rubber: 0.45 to 0.499; 0.5 is singular in the plane-stress formulas)"
    )]
    Poisson(f64),
    /// The pre-bulge height is negative or not finite.
    #[error("prebulge_height_m = {0} must be zero or a positive height in metres")]
    Prebulge(f64),
    /// `prebulge_height_m = "fit"` where a number is needed.
    #[error(
        "prebulge_height_m = \"fit\" is estimated from the heights by `bulge run` (from photos, or from measured heights with [heights] csv = \"heights.csv\"); this command needs it as a number (the value bulge run reports in its notes and material.toml, [fit.refined] prebulge_height_m)"
    )]
    PrebulgeToFit,
}

impl SpecimenError {
    /// The key of the field at fault, as the experiment file spells it.
    pub fn field(&self) -> &'static str {
        match self {
            SpecimenError::Radius(_) => "radius_m",
            SpecimenError::Thickness(_) => "thickness_m",
            SpecimenError::Poisson(_) => "poisson",
            SpecimenError::Prebulge(_) | SpecimenError::PrebulgeToFit => "prebulge_height_m",
        }
    }
}

impl Specimen {
    /// The latex disc of Tudruj et al. (2023): a = 37.5 mm, t = 0.35 mm,
    /// nu = 0.45, flat (the tests' specimen).
    #[cfg(test)]
    pub(crate) fn latex() -> Specimen {
        Specimen {
            radius_m: 0.0375,
            thickness_m: 3.5e-4,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        }
    }

    /// Checks every field; the error names the field, the value and the fix.
    pub fn validate(&self) -> Result<(), SpecimenError> {
        let Specimen {
            radius_m,
            thickness_m,
            poisson,
            prebulge_height_m,
        } = *self;
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(SpecimenError::Radius(radius_m));
        }
        if !(thickness_m.is_finite() && thickness_m > 0.0) {
            return Err(SpecimenError::Thickness(thickness_m));
        }
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(SpecimenError::Poisson(poisson));
        }
        if prebulge_height_m.is_nan() {
            return Err(SpecimenError::PrebulgeToFit);
        }
        if !(prebulge_height_m.is_finite() && prebulge_height_m >= 0.0) {
            return Err(SpecimenError::Prebulge(prebulge_height_m));
        }
        Ok(())
    }
}

/// `[photos]`: where the photos are and what to look for in them: a folder
/// of photos (`dir`, `glob`) or a video (`video`, with `every` or `times_s`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhotosConfig {
    /// Folder of the photos, relative to the experiment file.
    #[serde(default)]
    pub dir: Option<PathBuf>,
    /// File-name pattern, e.g. `*.png` (default `*`); files are taken in
    /// natural sort order.
    #[serde(default)]
    pub glob: Option<String>,
    /// Or a video file, relative to the experiment file (read with OpenCV's
    /// video module).
    #[serde(default)]
    pub video: Option<PathBuf>,
    /// Video only: take every N-th frame (frames 0, N, 2N, ...; default 1).
    #[serde(default)]
    pub every: Option<usize>,
    /// Video only: take the frame nearest each of these times, s.
    #[serde(default)]
    pub times_s: Option<Vec<f64>>,
    /// Photo folder only: time between consecutive photos (in file-name
    /// order), s; gives each photo a time for a pressure log by time.
    #[serde(default)]
    pub interval_s: Option<f64>,
    /// Photo folder only: time of the first photo, s (default 0; with
    /// `interval_s`).
    #[serde(default)]
    pub start_s: Option<f64>,
    /// Region where the apex can move: `[x, y, width, height]` in pixels.
    pub roi_px: [i32; 4],
    /// Template image file, relative to the experiment file.
    #[serde(default)]
    pub template: Option<PathBuf>,
    /// Or the template cut from the reference frame: `[x, y, width, height]`.
    #[serde(default)]
    pub template_rect_px: Option<[i32; 4]>,
    /// Index of the reference frame (default 0).
    #[serde(default)]
    pub reference_frame: usize,
    /// Apex position inside the template, `[dx, dy]` px (default: its centre).
    #[serde(default)]
    pub apex_in_template_px: Option<[f64; 2]>,
}

impl PhotosConfig {
    /// The file-name pattern of a photo folder (`*` when not given).
    pub fn glob(&self) -> &str {
        self.glob.as_deref().unwrap_or("*")
    }
}

/// `[calibration]`: pixels to metres and the clamp plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CalibrationConfig {
    /// Scale, m per pixel.
    #[serde(default)]
    pub metres_per_pixel: Option<f64>,
    /// Or two image points a known distance apart.
    #[serde(default)]
    pub points_px: Option<[[f64; 2]; 2]>,
    /// Distance between `points_px`, m.
    #[serde(default)]
    pub distance_m: Option<f64>,
    /// Image row of the clamp plane, px, when known (with a camera above
    /// the clamp plane, the row of the clamp ring's centre).
    #[serde(default)]
    pub clamp_row_px: Option<f64>,
    /// Elevation of the camera above the clamp plane, degrees (0 to 30;
    /// absent: a level camera): the heights are corrected for it.
    #[serde(default)]
    pub elevation_deg: Option<f64>,
    /// Standard deviation of the scale, m per pixel (however the scale is
    /// given): every height is wrong in the same proportion.
    #[serde(default)]
    pub metres_per_pixel_std: Option<f64>,
    /// Standard deviation of the clamp row, px (or, without `clamp_row_px`,
    /// of the reference photo's apex): every height is wrong by the same
    /// offset.
    #[serde(default)]
    pub clamp_row_std_px: Option<f64>,
}

impl CalibrationConfig {
    /// The scale, m per pixel, from `metres_per_pixel` or from the two
    /// points and their distance; `None` when neither is complete.
    pub fn scale(&self) -> Option<f64> {
        match (self.metres_per_pixel, self.points_px, self.distance_m) {
            (Some(s), _, _) => Some(s),
            (None, Some([p, q]), Some(d)) => {
                let len = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                (len > 0.0).then(|| d / len)
            }
            _ => None,
        }
    }
}

/// `[camera]`: what the camera does to the light before the photo is written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// The tone curve from light to pixel values: `"srgb"` (the default:
    /// ordinary 8-bit photos), `"linear"` (raw or 16-bit photos), or a gamma
    /// such as 2.2. Edges are located in linear light.
    #[serde(default)]
    pub response: Option<crate::camera::Response>,
    /// Focal lengths `[fx, fy]`, px, from `bulge calibrate` (with
    /// `principal_point_px` and `distortion`: the tracker and `bulge init`
    /// undistort the points they measure, and heights are in the
    /// undistorted pinhole image's pixels).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focal_px: Option<[f64; 2]>,
    /// Principal point `[cx, cy]`, px (image coordinates of the photos).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub principal_point_px: Option<[f64; 2]>,
    /// Distortion coefficients `[k1, k2, p1, p2, k3]` (OpenCV's order).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distortion: Option<[f64; 5]>,
    /// The photo size the calibration was made at, `[width, height]` px:
    /// photos of another size are refused.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image_size_px: Option<[usize; 2]>,
    /// The calibration's RMS reprojection error, px (for the record).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reprojection_rms_px: Option<f64>,
    /// Horizontal distance from the bubble's axis to the camera's centre
    /// (the lens's entrance pupil), m: the camera is a pinhole at that
    /// distance, `[calibration] elevation_deg` the angle at which it looks
    /// down at the clamp ring's centre, and the apex height is read from the
    /// silhouette's top through the ray tangent to the dome
    /// (docs/theory.md, section 10). Absent: an orthographic camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance_m: Option<f64>,
}

impl CameraConfig {
    /// The tone curve (sRGB when not given).
    pub fn response(&self) -> crate::camera::Response {
        self.response.unwrap_or_default()
    }

    /// Whether a lens calibration is given (any of its keys).
    pub fn has_lens(&self) -> bool {
        self.focal_px.is_some() || self.principal_point_px.is_some() || self.distortion.is_some()
    }

    /// The lens calibration's keys checked: `Ok(None)` without one, an error
    /// naming the missing or bad key and the fix.
    #[allow(clippy::type_complexity)]
    pub fn lens_keys(&self) -> Result<Option<([f64; 2], [f64; 2], [f64; 5])>, String> {
        if !self.has_lens() {
            return Ok(None);
        }
        let (Some(f), Some(c), Some(d)) = (self.focal_px, self.principal_point_px, self.distortion)
        else {
            return Err("[camera] gives part of a lens calibration: focal_px, principal_point_px and distortion go together; paste the whole [camera] table written by `bulge calibrate`".into());
        };
        if !(f[0].is_finite() && f[1].is_finite() && f[0] > 0.0 && f[1] > 0.0) {
            return Err(format!(
                "[camera] focal_px = {f:?}: the focal lengths must be positive, px; calibrate again with `bulge calibrate`"
            ));
        }
        if !(c.iter().chain(d.iter()).all(|v| v.is_finite())) {
            return Err(format!(
                "[camera] principal_point_px = {c:?} or distortion = {d:?} is not finite; calibrate again with `bulge calibrate`"
            ));
        }
        Ok(Some((f, c, d)))
    }
}

/// `[pressure]`: the pressure log, joined per photo (columns
/// `file,pressure_pa`) or by time (columns `time_s,pressure_pa`, interpolated
/// linearly at each frame's time).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureConfig {
    /// The CSV, relative to the experiment file.
    pub csv: PathBuf,
    /// Clock offset of a log by time, s: logger time = frame time +
    /// `offset_s` (the logger's clock reads `offset_s` when the camera's
    /// reads 0). Default 0.
    #[serde(default)]
    pub offset_s: Option<f64>,
    /// Standard deviation of each reading's noise, Pa, independent from
    /// reading to reading (default 0).
    #[serde(default)]
    pub std_pa: Option<f64>,
    /// Standard deviation of the gauge's gain, as a fraction of the reading
    /// (a gauge "accurate to 0.25 % of the reading": 0.0025), one factor
    /// shared by every reading (default 0).
    #[serde(default)]
    pub relative_std: Option<f64>,
}

/// `[heights]`: measured apex heights instead of photos (a laser gauge,
/// 3D digital image correlation): a CSV with columns `pressure_pa`,
/// `height_m` and optionally `height_std_m` ([`crate::heights`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeightsConfig {
    /// The CSV, relative to the experiment file.
    pub csv: PathBuf,
    /// What the heights are measured from (default the clamp plane).
    #[serde(default)]
    pub origin: HeightsOrigin,
}

/// What the heights of a `[heights]` file are measured from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HeightsOrigin {
    /// Above the clamp plane (a flat disc is at 0).
    #[default]
    Clamp,
    /// Above a reference state of the stress-free (possibly slack, domed)
    /// membrane: the apex stands at `height + prebulge_height_m`.
    Reference,
}

/// A whole experiment file. Stages read the tables they need and ignore the
/// rest; `[simulate]` and `[report]` hold settings for `bulge run`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    /// The specimen (required).
    #[serde(deserialize_with = "specimen_of_file")]
    pub specimen: Specimen,
    /// Photos (needed by `track`).
    #[serde(default)]
    pub photos: Option<PhotosConfig>,
    /// Measured heights, in place of `[photos]` (`bulge run`, `bulge study`).
    #[serde(default)]
    pub heights: Option<HeightsConfig>,
    /// Calibration (needed by `track`).
    #[serde(default)]
    pub calibration: Option<CalibrationConfig>,
    /// Pressure log (needed by `track`).
    #[serde(default)]
    pub pressure: Option<PressureConfig>,
    /// The camera (default: an 8-bit camera with the sRGB tone curve).
    #[serde(default)]
    pub camera: Option<CameraConfig>,
    /// The clamped opening (default the circle of the specimen's radius).
    #[serde(default)]
    pub window: Window,
    /// Other tables (settings of later stages), kept as TOML.
    #[serde(flatten)]
    pub other: toml::Table,
    /// Folder of the experiment file; relative paths resolve against it.
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// The file it was read from.
    #[serde(skip)]
    pub path: PathBuf,
    /// `prebulge_height_m = "fit"`: the stress-free dome height is to be
    /// estimated from the heights (the specimen then holds 0 until it is).
    #[serde(skip)]
    pub prebulge_fit: bool,
    /// The standard deviations of the specimen's dimensions.
    #[serde(skip)]
    pub specimen_std: SpecimenStd,
}

impl Experiment {
    /// Reads and validates an experiment file.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, InputError> {
        let path = path.as_ref();
        let mut e: Experiment = read_toml(path)?;
        if e.specimen.prebulge_height_m.is_nan() {
            e.prebulge_fit = true;
            e.specimen.prebulge_height_m = 0.0;
        }
        e.specimen
            .validate()
            .map_err(|m| InputError::file(path, format!("[specimen] {m}")))?;
        e.window
            .validate()
            .map_err(|m| InputError::from_value(path, m))?;
        if e.heights.is_some() && e.photos.is_some() {
            return Err(InputError::file(
                path,
                "[heights] and [photos] are both given: the heights come from one of them; remove [photos] to use the measured heights, or [heights] to track the photos",
            ));
        }
        if e.heights.is_some() {
            for (table, given) in [
                ("pressure", e.pressure.is_some()),
                ("calibration", e.calibration.is_some()),
                ("camera", e.camera.is_some()),
            ] {
                if given {
                    return Err(InputError::file(
                        path,
                        format!(
                            "[{table}] describes photos and [heights] gives the heights: remove [{table}] (the pressures are the heights file's pressure_pa column)"
                        ),
                    ));
                }
            }
        }
        e.specimen_std = read_specimen_file(path)?
            .std()
            .map_err(|m| InputError::file(path, format!("[specimen] {m}")))?;
        let positive = |table: &str, key: &str, v: Option<f64>, example: &str| match v {
            Some(v) if !(v.is_finite() && v >= 0.0) => Err(InputError::file(
                path,
                format!(
                    "[{table}] {key} = {v} must be a standard deviation, zero or positive (e.g. {example})"
                ),
            )),
            _ => Ok(()),
        };
        if let Some(p) = &e.pressure {
            positive("pressure", "std_pa", p.std_pa, "5.0")?;
            positive("pressure", "relative_std", p.relative_std, "0.0025")?;
        }
        if let Some(c) = &e.calibration {
            positive(
                "calibration",
                "metres_per_pixel_std",
                c.metres_per_pixel_std,
                "2e-7",
            )?;
            positive("calibration", "clamp_row_std_px", c.clamp_row_std_px, "0.5")?;
        }
        e.base_dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        e.path = path.to_path_buf();
        Ok(e)
    }

    /// Only the `[specimen]` of an experiment file (the other tables are
    /// not read, so a file for a simulation or a fit needs no photos).
    pub fn read_specimen(path: impl AsRef<Path>) -> Result<Specimen, InputError> {
        let path = path.as_ref();
        let spec = read_specimen_file(path)?.specimen();
        spec.validate()
            .map_err(|e| InputError::file(path, format!("[specimen] {e}")))?;
        Ok(spec)
    }

    /// Only the `[window]` of an experiment file (the circle when there is
    /// none).
    pub fn read_window(path: impl AsRef<Path>) -> Result<Window, InputError> {
        #[derive(Deserialize)]
        struct Only {
            #[serde(default)]
            window: Window,
        }
        let path = path.as_ref();
        let only: Only = crate::io::read_toml(path)?;
        only.window
            .validate()
            .map_err(|m| InputError::from_value(path, m))?;
        Ok(only.window)
    }

    /// The files this experiment reads, resolved: the experiment file, the
    /// pressure log, the template image and the video (the photos are listed
    /// by the tracker, which knows their pattern), and the photo folder.
    pub fn input_files(&self) -> (Vec<PathBuf>, Option<PathBuf>) {
        let mut files = vec![self.path.clone()];
        if let Some(p) = &self.pressure {
            files.push(self.resolve(&p.csv));
        }
        if let Some(h) = &self.heights {
            files.push(self.resolve(&h.csv));
        }
        let mut folder = None;
        if let Some(ph) = &self.photos {
            if let Some(t) = &ph.template {
                files.push(self.resolve(t));
            }
            if let Some(v) = &ph.video {
                files.push(self.resolve(v));
            }
            folder = ph.dir.as_ref().map(|d| self.resolve(d));
        }
        (files, folder)
    }

    /// The uncertainty of the inputs besides the heights' own: the
    /// specimen's dimensions, the pressure reading and gauge, the scale and
    /// the clamp row (converted to metres with the scale).
    pub fn uncertainty(&self) -> crate::fit::uncertainty::Sources {
        let (scale, cal) = match &self.calibration {
            Some(c) => (c.scale(), Some(c)),
            None => (None, None),
        };
        let scale_relative_std = match (scale, cal.and_then(|c| c.metres_per_pixel_std)) {
            (Some(s), Some(sd)) if s > 0.0 => sd / s,
            _ => 0.0,
        };
        let height_offset_std_m = match (scale, cal.and_then(|c| c.clamp_row_std_px)) {
            (Some(s), Some(px)) => s * px,
            _ => 0.0,
        };
        crate::fit::uncertainty::Sources {
            pressure_std_pa: self.pressure.as_ref().and_then(|p| p.std_pa).unwrap_or(0.0),
            pressure_relative_std: self
                .pressure
                .as_ref()
                .and_then(|p| p.relative_std)
                .unwrap_or(0.0),
            thickness_std_m: self.specimen_std.thickness_std_m,
            radius_std_m: self.specimen_std.radius_std_m,
            scale_relative_std,
            height_offset_std_m,
            // found with the dome height, when it is (`bulge run`)
            prebulge_std_m: 0.0,
            prebulge_in_heights: false,
        }
    }

    /// Resolves a path written in the file against the file's folder.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }
}

/// The `[specimen]` table of an experiment file, its other tables not read.
fn read_specimen_file(path: &Path) -> Result<SpecimenFile, InputError> {
    #[derive(Deserialize)]
    struct Only {
        specimen: Option<SpecimenFile>,
    }
    let only: Only = crate::io::read_toml(path)?;
    only.specimen.ok_or_else(|| {
        InputError::file(
            path,
            "no [specimen] table: give radius_m, thickness_m and poisson under [specimen]",
        )
    })
}
