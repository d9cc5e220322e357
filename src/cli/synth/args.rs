//! The flags of `bulge synth` and their help.

use std::path::PathBuf;

use super::*;

/// Flags of `bulge synth`.
///
/// Writes OUT_DIR/photos/frame_NNN.{png,jpg}, OUT_DIR/pressure.csv
/// (file,pressure_pa), OUT_DIR/experiment.toml (ready for `bulge track`) and
/// OUT_DIR/truth.csv (file,pressure_pa,height_m,apex_x_px,apex_y_px). The
/// bubble is the exact axisymmetric solution for the material at each
/// pressure (with --window-semi-axes-m the membrane model's on an elliptical
/// window), seen from the side, drawn with exact pixel-area anti-aliasing
/// over a textured background and a clamp fixture. With --log-rate-hz, also
/// a pressure log by time (pressure_log.csv, experiment_log.toml); with
/// --video, also the photos as a video (experiment_video.toml). The same
/// flags and seed give the same files.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder (created if missing; files of the same names are replaced).
    pub out_dir: PathBuf,

    /// Material file (material.toml format: `model = "neo-hookean"`,
    /// `c1_pa = ...`, `poisson = ...`). Default: neo-Hookean with
    /// C1 = 0.2 MPa, a latex-like rubber.
    #[arg(long)]
    pub material: Option<PathBuf>,

    /// Number of photos (default 12).
    #[arg(long, default_value_t = 12)]
    pub frames: usize,

    /// Highest pressure, Pa (default 3700: apex height about 0.53 a for the
    /// default material and specimen, below its limit point).
    #[arg(long, default_value_t = 3700.0)]
    pub pressure_max_pa: f64,

    /// Lowest pressure, Pa (default: --pressure-max-pa / --frames); the
    /// pressures are evenly spaced from it to --pressure-max-pa.
    #[arg(long)]
    pub pressure_min_pa: Option<f64>,

    /// Free radius a of the disc, m (default 0.0375, Tudruj et al.'s (2023) specimen).
    #[arg(long, default_value_t = 0.0375)]
    pub radius_m: f64,

    /// Initial thickness t, m (default 0.00035).
    #[arg(long, default_value_t = 0.00035)]
    pub thickness_m: f64,

    /// Poisson ratio written into [specimen] (default 0.45, Tudruj et al. (2023)).
    #[arg(long, default_value_t = 0.45)]
    pub poisson: f64,

    /// A slack membrane: its stress-free shape is a spherical cap of this
    /// height over the clamp, m (default 0: a flat, stress-free disc). The
    /// heights are above the clamp plane, as the flat disc's clamp row gives
    /// them; written into [specimen] prebulge_height_m.
    #[arg(long, default_value_t = 0.0)]
    pub prebulge_height_m: f64,

    /// An elliptical window instead of the disc: its semi-axes A,B in m
    /// (A along the picture, B towards the camera). The bubble is then the
    /// membrane model's (`--model membrane`, 24 rings of the scaled
    /// hexagonal disc), seen from the side: its section through the long
    /// axis. [specimen] radius_m becomes A (the extent drawn) and
    /// experiment.toml gets the [window] table; --radius-m and
    /// --prebulge-height-m do not apply.
    #[arg(long, value_delimiter = ',', value_name = "A,B")]
    pub window_semi_axes_m: Option<Vec<f64>>,

    /// Image width, px (default 640; the disc spans 70 % of it).
    #[arg(long, default_value_t = 640)]
    pub width: usize,

    /// Image height, px (default 480; the clamp plane at 80 % of it).
    #[arg(long, default_value_t = 480)]
    pub height: usize,

    /// Seed of the placement, background texture and noise (default 1).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,

    /// Scale, m per px (default: the disc spans 70 % of the width, or
    /// drawn with --random-framing).
    #[arg(long)]
    pub metres_per_pixel: Option<f64>,

    /// Column of the bubble's axis, px (default: the middle of the width,
    /// or drawn with --random-framing).
    #[arg(long)]
    pub axis_x_px: Option<f64>,

    /// Row of the clamp plane (the clamp ring's centre), px (default: 80 %
    /// of the height, or drawn with --random-framing).
    #[arg(long)]
    pub clamp_row_px: Option<f64>,

    /// Draw the scale, axis and clamp row not given from the seed: the disc
    /// spans 35-80 % of the width (less if the bubble would not fit), the
    /// bubble anywhere it fits, the clamp ring in the picture.
    #[arg(long)]
    pub random_framing: bool,

    /// How the camera sees the scene and how it is lit.
    #[command(flatten)]
    pub look: LookFlags,

    /// Gaussian blur standard deviation, px (default 0).
    #[arg(long, default_value_t = 0.0)]
    pub blur_px: f64,

    /// Sensor noise standard deviation, grey levels of 255 (default 0).
    #[arg(long, default_value_t = 0.0)]
    pub noise: f64,

    /// Exposure drift: the gain goes linearly from 1 - drift on the first
    /// photo to 1 + drift on the last (default 0).
    #[arg(long, default_value_t = 0.0)]
    pub drift: f64,

    /// Write JPEG photos of this quality (1-100) instead of PNG.
    #[arg(long)]
    pub jpeg_quality: Option<u8>,

    /// Also write the photos as a video of this file name in OUT_DIR: `.avi`
    /// (Motion JPEG, OpenCV's own writer, always available; JPEG quality
    /// --jpeg-quality, default 95) or `.mp4` (when OpenCV's FFmpeg back-end
    /// can write it), frame k at k / --fps s; with
    /// OUT_DIR/experiment_video.toml, which reads it with the pressures of
    /// --log-rate-hz (required with it).
    #[arg(long, value_name = "NAME")]
    pub video: Option<PathBuf>,

    /// Photos per second of the test (default 2): photo k is taken at
    /// k / fps s on the camera's clock; the video's frame rate and the
    /// `interval_s` of experiment_log.toml.
    #[arg(long, default_value_t = 2)]
    pub fps: u32,

    /// Also write OUT_DIR/pressure_log.csv (time_s,pressure_pa): a logger at
    /// this rate, Hz, on its own clock, sampling a smooth pressure ramp
    /// through the photos' pressures; and OUT_DIR/experiment_log.toml, the
    /// photo folder with `interval_s` and this log.
    #[arg(long)]
    pub log_rate_hz: Option<f64>,

    /// The logger's clock reads this when the camera's reads 0, s (default
    /// 0): logger time = camera time + offset; written as `offset_s` in
    /// [pressure] of experiment_log.toml and experiment_video.toml.
    #[arg(long, allow_hyphen_values = true)]
    pub log_offset_s: Option<f64>,

    /// Largest memory a photo may take while it is drawn, GB (default 2):
    /// larger pictures are refused before any work.
    #[arg(long, default_value_t = 2.0)]
    pub max_memory_gb: f64,
}
