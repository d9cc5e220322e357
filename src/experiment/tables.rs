//! The tables of an experiment file besides `[specimen]` and `[window]`:
//! where the photos are (`[photos]`), how pixels become metres
//! (`[calibration]`), the camera (`[camera]`), the pressure log
//! (`[pressure]`) and measured heights in place of photos (`[heights]`).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

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
    /// A folder of photos, `glob` in it, the region and template not yet
    /// set (all zero).
    pub fn folder(dir: impl Into<PathBuf>, glob: &str) -> Self {
        PhotosConfig {
            dir: Some(dir.into()),
            glob: Some(glob.to_string()),
            ..Self::source()
        }
    }

    /// A video, every `every`-th frame (`None`: every frame), the region and
    /// template not yet set.
    pub fn video(path: impl Into<PathBuf>, every: Option<usize>) -> Self {
        PhotosConfig {
            video: Some(path.into()),
            every,
            ..Self::source()
        }
    }

    fn source() -> Self {
        PhotosConfig {
            dir: None,
            glob: None,
            video: None,
            every: None,
            times_s: None,
            interval_s: None,
            start_s: None,
            roi_px: [0; 4],
            template: None,
            template_rect_px: None,
            reference_frame: 0,
            apex_in_template_px: None,
        }
    }

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
    /// Standard deviation of the scale, m per pixel (however the scale is
    /// given): every height is wrong in the same proportion.
    #[serde(default)]
    pub metres_per_pixel_std: Option<f64>,
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
    /// Standard deviation of the clamp row, px (or, without `clamp_row_px`,
    /// of the reference photo's apex): every height is wrong by the same
    /// offset.
    #[serde(default)]
    pub clamp_row_std_px: Option<f64>,
    /// The scale's relative change per px that the clamp row lies lower,
    /// 1/px (`bulge init` writes it when the scale is read on the opening
    /// at the clamp row): a clamp row `d` px off then puts a height `h`
    /// off by `d (mpp + h scale_per_clamp_row)` m, the two parts of one
    /// error, instead of by `d mpp` besides an independent scale error.
    #[serde(default)]
    pub scale_per_clamp_row: Option<f64>,
    /// Elevation of the camera above the clamp plane, degrees (0 to 30;
    /// absent: a level camera): the heights are corrected for it.
    #[serde(default)]
    pub elevation_deg: Option<f64>,
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

impl PressureConfig {
    /// A pressure log read from `csv`, without stated errors.
    pub fn file(csv: impl Into<PathBuf>) -> Self {
        PressureConfig {
            csv: csv.into(),
            offset_s: None,
            std_pa: None,
            relative_std: None,
        }
    }
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
