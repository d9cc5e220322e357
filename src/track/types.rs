//! What tracking is told (set-up, options) and what it finds (per frame,
//! the heights table).

use std::path::PathBuf;

use super::matcher::EdgeFit;
use super::pole::{PoleMeasure, pole_curvature_mean};

/// One photo (or video frame) to track.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Path of the photo (of the video, for a video frame).
    pub path: PathBuf,
    /// Its file name (the key into a pressure log by file), or `frame
    /// NNNNNN` for a video frame.
    pub file: String,
    /// Pressure at the photo, Pa.
    pub pressure_pa: f64,
    /// Time of the frame on the camera's clock, s, when known.
    pub time_s: Option<f64>,
    /// Index of the frame in the video (0-based), for a video frame.
    pub video_frame: Option<usize>,
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
    /// The camera's elevation above the clamp plane, when not level.
    pub elevation: Option<Elevation>,
    /// Free radius of the specimen, m: the dome's opening, against which
    /// the curvature of the top edge found is checked.
    pub opening_radius_m: f64,
    /// Horizontal distance from the axis to the camera's centre, m
    /// (`[camera] distance_m`): a pinhole camera, see [`super::persp`].
    /// `None`: orthographic.
    pub camera_distance_m: Option<f64>,
}

/// A camera raised above the clamp plane (see [`Elevation::height_px`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elevation {
    /// Elevation angle, rad.
    pub radians: f64,
    /// Free radius of the specimen, m (for the spherical-cap radius when
    /// the edge's curvature is not measured).
    pub radius_m: f64,
}

impl Elevation {
    /// The apex height `h`, px, from the height `t` (px) of the
    /// silhouette's top above the clamp ring's centre. An orthographic
    /// camera raised by `e` sees `(x, y, z)` (z up the axis, y away from
    /// the camera) at image height `y sin e + z cos e`; near its pole the
    /// dome is a sphere of radius `R` (by symmetry the pole is an umbilic
    /// point), whose outline tops out at the latitude of polar angle `e`:
    /// `t = (h - R) cos e + R`, so `h = (t - R (1 - cos e)) / cos e`.
    ///
    /// `1 / R` is the inverse-variance mean of two estimates: one measured
    /// (`measured`: the edge fit's curvature at the top, value and standard
    /// error, 1/px, the outline of a sphere being a circle of its radius
    /// from any direction; or the flattening pooled over a sequence's
    /// photos), and the membrane's, [`super::pole_flattening`] times the
    /// spherical cap's `(a^2 + h^2) / (2 h)` through the rim (`a_px` the
    /// free radius in px), with its deviation; solved for `h`
    /// by fixed-point iteration. Returns `h` and its standard deviation
    /// from the curvature's, px.
    pub fn height_px(&self, t: f64, measured: Option<PoleMeasure>, a_px: f64) -> (f64, f64) {
        let (h, std, _) = self.solve_px(t, measured, a_px);
        (h, std)
    }

    /// [`Elevation::height_px`] with the top's own standard deviation
    /// `t_std` (px) joined: the height's whole standard deviation, px.
    /// The top's row and a measured pole radius come from one fit of the
    /// top edge, whose errors go together ([`PoleMeasure`]): the
    /// covariance joins the two parts, `var = (t_std / cos e)^2 +
    /// pole^2 + 2 cov`.
    pub fn height_and_std_px(
        &self,
        t: f64,
        t_std: f64,
        measured: Option<PoleMeasure>,
        a_px: f64,
    ) -> (f64, f64) {
        let (h, std, cov) = self.solve_px(t, measured, a_px);
        let c = self.radians.cos();
        let var = (t_std / c).powi(2) + std * std + 2.0 * cov;
        (h, var.max(0.0).sqrt())
    }

    /// The height, the pole's part of its standard deviation and that
    /// part's covariance with the top's, px^2: `h = (t - (1 - cos e) / k)
    /// / cos e` moves by `d t / cos e` and by `(1 - cos e) / (cos e k^2)
    /// d k`; the mean curvature moves with the measured one's relative
    /// error times its weight, and a top found low (`d t` negative) comes
    /// with a flatter outline.
    fn solve_px(&self, t: f64, measured: Option<PoleMeasure>, a_px: f64) -> (f64, f64, f64) {
        let (s, c) = (1.0 - self.radians.cos(), self.radians.cos());
        let pole = |h: f64| {
            let r_cap = (a_px * a_px + h * h) / (2.0 * h);
            let m = measured.and_then(|m| m.outline().or(m.flattening_curvature(r_cap)));
            let (k, k_std, share) = pole_curvature_mean(r_cap, h / a_px, m);
            // cov(row, k), px/px: the row is `-t`.
            let cov = share * m.map_or(0.0, |m| m.0) * measured.map_or(0.0, |m| m.row_cov());
            (k, k_std, cov)
        };
        let mut h = t;
        for _ in 0..200 {
            let (k, ..) = pole(h.max(1e-9));
            let next = ((t - s / k) / c).max(1e-6 * a_px);
            if (next - h).abs() < 1e-10 * a_px {
                h = next;
                break;
            }
            h = next;
        }
        let (k, k_std, cov_row_k) = pole(h);
        let per_k = s / (c * k * k);
        (h, per_k * k_std, -per_k * cov_row_k / c)
    }
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
    /// Photos in natural order (video frames in time order), with their
    /// pressures.
    pub frames: Vec<Frame>,
    /// The video the frames come from (`None`: photo files).
    pub video: Option<PathBuf>,
    /// Region where the apex moves, `[x, y, w, h]` px.
    pub roi: [i64; 4],
    /// The template.
    pub template: TemplateSource,
    /// Index of the reference frame.
    pub reference_frame: usize,
    /// Apex position inside the template, px (None: its centre).
    pub apex_in_template: Option<[f64; 2]>,
    /// The camera's tone curve: edges are located in linear light.
    pub response: crate::camera::Response,
    /// Pixels to metres.
    pub calibration: Calibration,
    /// The lens (`[camera]` from `bulge calibrate`): the apex is undistorted,
    /// and heights are in the undistorted image's pixels. `None`: the
    /// photos are taken as a pinhole camera's.
    pub lens: Option<super::lens::Lens>,
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
    /// Leave bad frames (a low score, an implausible apex) out, and report
    /// them with the reason, instead of failing.
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
            edge_window_px: 3,
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
    /// Time of the frame on the camera's clock, s, when known.
    pub time_s: Option<f64>,
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
    /// Why it was left out (a score below `--min-score`, or an apex that
    /// the plausibility guards refused).
    pub reason: String,
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Tracked {
    /// One row per tracked frame, in frame order.
    pub rows: Vec<FrameResult>,
    /// Frames left out with `skip_bad_frames`.
    pub skipped: Vec<Skipped>,
    /// Frames kept that break only the trend rule (the apex far from the
    /// row extrapolated from the frames before, which no membrane law
    /// bounds), one line each naming the frame and the photo.
    pub warnings: Vec<String>,
    /// Image size, px.
    pub image_size: [usize; 2],
    /// Time spent matching and fitting (the sequential part), s.
    pub locate_seconds: f64,
}

impl Tracked {
    /// `heights.csv`: `frame,file,pressure_pa,apex_x_px,apex_y_px,score,
    /// height_m,height_std_m`, one row per tracked frame, and `time_s` last
    /// when the frames' times are known (a video, or photos with
    /// `interval_s`).
    pub fn heights_csv(&self) -> crate::io::CsvOut {
        use crate::io::fmt_num;
        let timed = self.rows.iter().any(|r| r.time_s.is_some());
        let mut header = vec![
            "frame",
            "file",
            "pressure_pa",
            "apex_x_px",
            "apex_y_px",
            "score",
            "height_m",
            "height_std_m",
        ];
        if timed {
            header.push("time_s");
        }
        let mut out = crate::io::CsvOut::new(&header);
        for r in &self.rows {
            let mut row = vec![
                r.frame.to_string(),
                r.file.clone(),
                fmt_num(Some(r.pressure_pa)),
                fmt_num(Some(r.apex_x_px)),
                fmt_num(Some(r.apex_y_px)),
                format!("{:.4}", r.score),
                fmt_num(Some(r.height_m)),
                fmt_num(Some(r.height_std_m)),
            ];
            if timed {
                row.push(fmt_num(r.time_s));
            }
            out.row(&row);
        }
        out
    }
}
