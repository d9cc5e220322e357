//! `bulge synth`: a synthetic experiment with known truth.

use std::path::PathBuf;

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::track::image::Encoding;
use bulge::track::synth::{self, Framing, Look, SequenceSpec, Silhouette, SynthFrame};

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

    /// The camera's elevation above the clamp plane, degrees (default 0, a
    /// level side view; at most 30): the clamp ring is seen as an ellipse
    /// and the silhouette is the union of the dome's latitude circles.
    /// truth.csv's apex_y_px is the pole's projection, clamp_row_px the
    /// ring's centre.
    #[arg(long, default_value_t = 0.0)]
    pub elevation_deg: f64,

    /// A pinhole camera this far from the bubble's axis, m (default: an
    /// orthographic camera), looking down at the clamp ring's centre at
    /// --elevation-deg, its focal length the one that gives the scale there:
    /// the silhouette's top is the grazing ray (truth.csv's apex_y_px), the
    /// ring's top face an ellipse-like conic; the experiment file gets
    /// `[camera] distance_m`.
    #[arg(long)]
    pub camera_distance_m: Option<f64>,

    /// Uneven light: the relative change of the illumination across the
    /// frame (default 0; e.g. 0.3), a tilted plane and a fall-off.
    #[arg(long, default_value_t = 0.0)]
    pub uneven_light: f64,

    /// A specular highlight on the dome of this peak, grey levels (default
    /// 0: none; e.g. 90): a small light above the camera reflected 12
    /// degrees from the pole, nearer the apex as the bubble inflates.
    #[arg(long, default_value_t = 0.0)]
    pub highlight_grey: f64,

    /// Clutter behind the bubble: a dark shelf edge and a cable crossing
    /// the apex's path (placed from the seed).
    #[arg(long)]
    pub clutter: bool,

    /// The camera's tone curve: the scene's light is blurred by the lens,
    /// scaled by the exposure and the uneven light, then encoded by this
    /// curve (`srgb`, the default, as an ordinary camera; `linear`, pixel
    /// values proportional to light; or a gamma such as 2.2). The
    /// experiment file says it in `[camera] response`.
    #[arg(long, default_value = "srgb", value_parser = parse_response)]
    pub response: bulge::camera::Response,

    /// Grey level of the clamp ring's visible top face (default: 58, a
    /// dull face a little lighter than the ring's side at 38): e.g. 230
    /// for a machined metal ring lit from above, 20 for a face darker than
    /// its side. Drawn as light before the tone curve.
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub ring_face_grey: f64,

    /// Grey level of the bubble at its centre (default: 72, a dark
    /// membrane before a light wall): e.g. 215 with --background-grey 50
    /// for translucent latex lit in front of a dark wall.
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub bubble_grey: f64,

    /// Mean grey level of the background wall (default: 190, light).
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub background_grey: f64,

    /// Light from one side: the light is multiplied by 1 + S x, with x
    /// going from -1 to 1 across the disc's columns (held beyond it), so
    /// the dome and the background behind it are brighter on one side of
    /// the apex (default 0; e.g. 0.3; negative: lit from the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub side_light: f64,

    /// Defocus: the light is spread over a uniform disc of this radius, px
    /// (the pillbox point-spread function of a defocused lens), after the
    /// Gaussian blur (default 0: in focus).
    #[arg(long, default_value_t = 0.0)]
    pub defocus_px: f64,

    /// Motion blur: the light is spread along a line of this length, px
    /// (the camera or the specimen moving steadily during the exposure)
    /// (default 0: none).
    #[arg(long, default_value_t = 0.0)]
    pub motion_px: f64,

    /// Direction of the motion blur, degrees from the image's x axis
    /// towards its y axis, down (default 0: horizontal).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub motion_deg: f64,

    /// Vignetting: the lens's cos^4 fall-off of the light away from the
    /// picture's centre, given as the share of the light the corners lose
    /// (default 0: none; e.g. 0.3, corners at 70 % of the centre's light).
    #[arg(long, default_value_t = 0.0)]
    pub vignetting: f64,

    /// Radial distortion of the lens, k1 (OpenCV's model; e.g. -0.1 for a
    /// barrel distortion of about 1 % at the photo's edge with the default
    /// focal length): the photos are drawn through it, and experiment.toml
    /// gives the lens in `[camera]`. Off by default (a pinhole camera).
    #[arg(long, allow_hyphen_values = true)]
    pub lens_k1: Option<f64>,

    /// Radial distortion of the lens, k2 (with --lens-k1).
    #[arg(
        long,
        allow_hyphen_values = true,
        default_value_t = 0.0,
        requires = "lens_k1"
    )]
    pub lens_k2: f64,

    /// Focal length of the lens with --lens-k1, px (default: the photo's
    /// width; the principal point is the photo's centre).
    #[arg(long, requires = "lens_k1")]
    pub focal_px: Option<f64>,

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

/// Runs `bulge synth`.
fn parse_response(s: &str) -> Result<bulge::camera::Response, String> {
    s.parse()
}

pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out_dir, "OUT_DIR")?;
    let plan = bulge::io::OutputPlan::new().inputs(&args.material);
    super::guard(plan.output_as("OUT_DIR", &args.out_dir))?;
    let bad = |m: String| Failure::BadInput(anyhow!(m));
    if args.frames == 0 {
        return Err(bad("--frames 0: give at least one photo".into()));
    }
    if args.width < 64 || args.height < 48 {
        return Err(bad(format!(
            "--width {} --height {}: the picture must be at least 64x48 px",
            args.width, args.height
        )));
    }
    // drawn in double precision with a blurred copy and the encoded image
    let bytes = (args.width as f64) * (args.height as f64) * 25.0;
    if bytes > args.max_memory_gb * 1e9 {
        return Err(bad(format!(
            "--width {} --height {}: drawing one photo takes about {:.1} GB, above --max-memory-gb {}; make it smaller or raise the limit",
            args.width,
            args.height,
            bytes / 1e9,
            args.max_memory_gb
        )));
    }
    if args.frames > 100_000 {
        return Err(bad(format!(
            "--frames {}: at most 100000 photos (a test is a few to a few hundred)",
            args.frames
        )));
    }
    let blur_cap = 0.1 * args.width.min(args.height) as f64;
    if args.blur_px > blur_cap {
        return Err(bad(format!(
            "--blur-px {}: a blur wider than a tenth of the picture ({blur_cap} px) erases the bubble's edge and its kernel grows with it; use a few px",
            args.blur_px
        )));
    }
    for (name, v) in [
        ("--blur-px", args.blur_px),
        ("--noise", args.noise),
        ("--drift", args.drift),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(bad(format!("{name} {v} must be zero or positive")));
        }
    }
    if let Some(d) = args.camera_distance_m
        && !(d.is_finite() && d > 2.0 * args.radius_m)
    {
        return Err(bad(format!(
            "--camera-distance-m {d}: give the distance from the bubble's axis to the camera, m, more than the opening's diameter {}",
            2.0 * args.radius_m
        )));
    }
    if !(args.elevation_deg.is_finite() && (0.0..=30.0).contains(&args.elevation_deg)) {
        return Err(bad(format!(
            "--elevation-deg {}: give the camera's elevation above the clamp plane, 0 to 30 degrees",
            args.elevation_deg
        )));
    }
    if !(args.uneven_light.is_finite() && (0.0..=0.8).contains(&args.uneven_light)) {
        return Err(bad(format!(
            "--uneven-light {}: give a relative change of the light from 0 to 0.8",
            args.uneven_light
        )));
    }
    if !(args.highlight_grey.is_finite() && (0.0..=255.0).contains(&args.highlight_grey)) {
        return Err(bad(format!(
            "--highlight-grey {}: give the highlight's peak, 0 to 255 grey levels",
            args.highlight_grey
        )));
    }
    for (name, v, what) in [
        (
            "--ring-face-grey",
            args.ring_face_grey,
            "the ring face's grey level",
        ),
        ("--bubble-grey", args.bubble_grey, "the bubble's grey level"),
        (
            "--background-grey",
            args.background_grey,
            "the background's grey level",
        ),
    ] {
        if !(v.is_finite() && (0.0..=255.0).contains(&v)) {
            return Err(bad(format!(
                "{name} {v}: give {what}, 1 to 255 (0 keeps the default)"
            )));
        }
    }
    if !(args.side_light.is_finite() && args.side_light.abs() <= 0.9) {
        return Err(bad(format!(
            "--side-light {}: give the relative change of the light across the disc, -0.9 to 0.9",
            args.side_light
        )));
    }
    for (name, v) in [
        ("--defocus-px", args.defocus_px),
        ("--motion-px", args.motion_px),
    ] {
        if !(v.is_finite() && v >= 0.0 && v <= blur_cap) {
            return Err(bad(format!(
                "{name} {v}: give a spread of 0 to a tenth of the picture ({blur_cap} px); a few px is a strong blur"
            )));
        }
    }
    if !args.motion_deg.is_finite() {
        return Err(bad(format!(
            "--motion-deg {}: give the motion's direction in degrees",
            args.motion_deg
        )));
    }
    if !(args.vignetting.is_finite() && (0.0..=0.9).contains(&args.vignetting)) {
        return Err(bad(format!(
            "--vignetting {}: give the share of the light the corners lose, 0 to 0.9",
            args.vignetting
        )));
    }
    if let Some(m) = args.metres_per_pixel
        && !(m.is_finite() && m > 0.0)
    {
        return Err(bad(format!(
            "--metres-per-pixel {m}: give a positive scale, m per px (e.g. 1e-4)"
        )));
    }
    for (name, v) in [
        ("--axis-x-px", args.axis_x_px),
        ("--clamp-row-px", args.clamp_row_px),
    ] {
        if let Some(v) = v
            && !v.is_finite()
        {
            return Err(bad(format!("{name} {v} must be a finite pixel position")));
        }
    }
    if args.drift >= 1.0 {
        return Err(bad(format!(
            "--drift {} must be below 1 (a relative gain change)",
            args.drift
        )));
    }
    let encoding = match args.jpeg_quality {
        None => Encoding::Png,
        Some(q) if (1..=100).contains(&q) => Encoding::Jpeg(q),
        Some(q) => return Err(bad(format!("--jpeg-quality {q} must be in 1..=100"))),
    };
    if args.fps == 0 || args.fps > 1000 {
        return Err(bad(format!(
            "--fps {}: give 1 to 1000 photos per second",
            args.fps
        )));
    }
    if let Some(r) = args.log_rate_hz
        && !(r.is_finite() && r > 0.0 && r <= 1e4)
    {
        return Err(bad(format!(
            "--log-rate-hz {r}: give a sampling rate in Hz above 0 and at most 10000"
        )));
    }
    if let Some(o) = args.log_offset_s {
        if !o.is_finite() {
            return Err(bad(format!(
                "--log-offset-s {o} must be a finite time in seconds"
            )));
        }
        if args.log_rate_hz.is_none() {
            return Err(bad(
                "--log-offset-s is the clock offset of the pressure log: give --log-rate-hz too"
                    .into(),
            ));
        }
    }
    if let Some(v) = &args.video {
        if args.log_rate_hz.is_none() {
            return Err(bad(format!(
                "--video {}: a video's frames are joined to the pressures by time; give --log-rate-hz (e.g. 7) for the pressure log",
                v.display()
            )));
        }
        let plain = v.file_name().is_some_and(|n| n == v.as_os_str());
        let ext = v
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !plain || !matches!(ext.as_deref(), Some("avi" | "mp4")) {
            return Err(bad(format!(
                "--video {}: give a file name (no folder; it is written in OUT_DIR) ending in .avi (Motion JPEG) or .mp4",
                v.display()
            )));
        }
    }
    let window = match &args.window_semi_axes_m {
        None => bulge::experiment::Window::Circle,
        Some(v) => {
            if v.len() != 2 {
                return Err(bad(format!(
                    "--window-semi-axes-m {v:?}: give the two semi-axes in m, e.g. 0.0375,0.01875"
                )));
            }
            if args.prebulge_height_m != 0.0 {
                return Err(bad(
                    "--prebulge-height-m is for the disc; an elliptical window is flat".into(),
                ));
            }
            bulge::experiment::Window::Ellipse {
                semi_axes_m: [v[0], v[1]],
            }
        }
    };
    window.validate().map_err(bad)?;
    let specimen = Specimen {
        radius_m: match window {
            bulge::experiment::Window::Ellipse { semi_axes_m } => semi_axes_m[0],
            _ => args.radius_m,
        },
        thickness_m: args.thickness_m,
        poisson: args.poisson,
        prebulge_height_m: args.prebulge_height_m,
    };
    specimen
        .validate()
        .map_err(|m| bad(format!("specimen: {m}")))?;
    let material = match &args.material {
        Some(p) => Material::read(p)?,
        None => Material {
            model: Model::NeoHookean { c1_pa: 0.2e6 },
            poisson: 0.45,
            fit: None,
        },
    };
    let p_max = args.pressure_max_pa;
    let p_min = args.pressure_min_pa.unwrap_or(p_max / args.frames as f64);
    if !(p_max.is_finite() && p_max > 0.0 && p_min.is_finite() && p_min > 0.0 && p_min <= p_max) {
        return Err(bad(format!(
            "pressures {p_min}..{p_max} Pa: need 0 < --pressure-min-pa <= --pressure-max-pa"
        )));
    }
    let n = args.frames;
    let pressures: Vec<f64> = (0..n)
        .map(|k| {
            if n == 1 {
                p_max
            } else {
                p_min + (p_max - p_min) * k as f64 / (n - 1) as f64
            }
        })
        .collect();
    let mut frames = Vec::with_capacity(n);
    let pb = super::progress(n as u64, "solve");
    if !window.is_circle() {
        frames = window_frames(&specimen, &window, &material, &pressures).bad_input()?;
    }
    for &p in pressures.iter().filter(|_| window.is_circle()) {
        let frame = synth::axisym_frame(&material, &specimen, p, p)
            .map_err(|e| anyhow!("the bubble at {p} Pa: {e}"))
            .bad_input()?;
        frames.push(frame);
        pb.inc(1);
    }
    pb.finish_and_clear();
    let spec = SequenceSpec {
        width: args.width,
        height: args.height,
        seed: args.seed,
        blur_px: args.blur_px,
        noise_grey: args.noise,
        drift: args.drift,
        encoding,
        specimen,
        framing: Framing {
            metres_per_pixel: args.metres_per_pixel,
            axis_x_px: args.axis_x_px,
            clamp_row_px: args.clamp_row_px,
            random: args.random_framing,
        },
        look: Look {
            elevation_deg: args.elevation_deg,
            uneven_light: args.uneven_light,
            highlight_grey: args.highlight_grey,
            clutter: args.clutter,
            response: args.response,
            ring_face_grey: args.ring_face_grey,
            bubble_grey: args.bubble_grey,
            background_grey: args.background_grey,
            side_light: args.side_light,
            defocus_px: args.defocus_px,
            motion_px: args.motion_px,
            motion_deg: args.motion_deg,
            vignetting: args.vignetting,
            camera_distance_m: args.camera_distance_m.unwrap_or(0.0),
            lens: args.lens_k1.map(|k1| {
                let f = args.focal_px.unwrap_or(args.width as f64);
                let (cx, cy) = (
                    (args.width as f64 - 1.0) / 2.0,
                    (args.height as f64 - 1.0) / 2.0,
                );
                bulge::track::lens::Lens {
                    k1,
                    k2: args.lens_k2,
                    image_size_px: Some([args.width, args.height]),
                    ..bulge::track::lens::Lens::pinhole(f, f, cx, cy)
                }
            }),
        },
        window,
    };
    let w = synth::write_sequence(&args.out_dir, &spec, &frames).map_err(|e| {
        if e.is_bad_input() {
            Failure::BadInput(e.into())
        } else {
            Failure::Failed(e.into())
        }
    })?;
    let extra = write_timed(&args, &spec, &w, &frames, &pressures)?;
    let hmax = w.truth.iter().map(|t| t.height_m).fold(0.0, f64::max);
    println!(
        "wrote {n} {}x{} {} photos ({:.2} MB) of a {} bubble, {:.0}..{:.0} Pa, apex height up to {:.4e} m ({:.1} px), {:.4e} m/px, + pressure.csv, truth.csv, experiment.toml{extra} -> {}",
        args.width,
        args.height,
        encoding.extension().to_uppercase(),
        w.photo_bytes as f64 / 1e6,
        material.model.name(),
        p_min,
        p_max,
        hmax,
        hmax / w.scene.metres_per_pixel,
        w.scene.metres_per_pixel,
        args.out_dir.display()
    );
    Ok(())
}

/// The outputs of --log-rate-hz and --video: pressure_log.csv,
/// experiment_log.toml, the video and experiment_video.toml. Returns their
/// part of the summary line (empty without those flags).
fn write_timed(
    args: &Args,
    spec: &SequenceSpec,
    w: &synth::Written,
    frames: &[SynthFrame],
    pressures: &[f64],
) -> Result<String, Failure> {
    let Some(rate) = args.log_rate_hz else {
        return Ok(String::new());
    };
    let failed = |e: bulge::track::TrackError| {
        if e.is_bad_input() {
            Failure::BadInput(e.into())
        } else {
            Failure::Failed(e.into())
        }
    };
    let write = |name: &str, bytes: &[u8]| -> Result<(), Failure> {
        let p = args.out_dir.join(name);
        bulge::io::write_atomic(&p, bytes)
            .map_err(|e| Failure::Failed(anyhow!("cannot write {}: {e}", p.display())))
    };
    let interval = 1.0 / f64::from(args.fps);
    let offset = args.log_offset_s.unwrap_or(0.0);
    let log = synth::pressure_log_csv(pressures, interval, rate, offset);
    let bytes = log.into_bytes();
    let rows = bytes.iter().filter(|&&b| b == b'\n').count() - 1;
    write("pressure_log.csv", &bytes)?;
    let pressure = format!(
        "csv = \"pressure_log.csv\" # columns time_s,pressure_pa\noffset_s = {offset:?} # logger time = frame time + offset_s\n"
    );
    let ext = spec.encoding.extension();
    let toml = synth::experiment_toml(
        spec,
        &w.scene,
        &w.layout,
        &format!(
            "dir = \"photos\"\nglob = \"*.{ext}\"\ninterval_s = {interval:?} # photo k at start_s + k * interval_s\n"
        ),
        &pressure,
    );
    write("experiment_log.toml", toml.as_bytes())?;
    let mut extra = format!(
        ", pressure_log.csv ({rows} rows at {rate} Hz, logger time = camera time + {offset} s), experiment_log.toml"
    );
    if let Some(v) = &args.video {
        let quality = args.jpeg_quality.unwrap_or(95);
        let bytes = synth::write_video(&args.out_dir.join(v), spec, frames, args.fps, quality)
            .map_err(failed)?;
        let name = v.to_string_lossy();
        let toml = synth::experiment_toml(
            spec,
            &w.scene,
            &w.layout,
            &format!("video = \"{name}\"\nevery = 1\n"),
            &pressure,
        );
        write("experiment_video.toml", toml.as_bytes())?;
        extra += &format!(
            ", {name} ({:.2} MB, {} frames at {} frames/s), experiment_video.toml",
            bytes as f64 / 1e6,
            frames.len(),
            args.fps
        );
    }
    Ok(extra)
}

/// The frames of a non-circular window: the membrane model swept over the
/// pressures, and at each its section through the long axis (the nodes on
/// `y = 0`, `x >= 0`, which stay on that mirror plane), pole first.
fn window_frames(
    specimen: &Specimen,
    window: &bulge::experiment::Window,
    material: &Material,
    pressures: &[f64],
) -> anyhow::Result<Vec<SynthFrame>> {
    use bulge::sim::scene::Scene;
    use bulge::sim::{SceneSolver, SpringModel};
    let scene = Scene::from_window(specimen, window, material.clone(), pressures.to_vec());
    let mesh = scene.build_mesh()?;
    let section: Vec<usize> = (0..mesh.nodes.len())
        .filter(|&i| mesh.nodes[i].y.abs() < 1e-12 && mesh.nodes[i].x >= 0.0)
        .collect();
    let mut s = SceneSolver::on_mesh(&scene, mesh, SpringModel::Membrane)?;
    let mut frames = Vec::with_capacity(pressures.len());
    let done = s.sweep(pressures, |solver, q| {
        let x = solver.positions();
        let mut pts: Vec<(f64, f64)> = section.iter().map(|&i| (x[i].x, x[i].z)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        frames.push(SynthFrame {
            pressure_pa: q.pressure_pa,
            silhouette: Silhouette {
                rho_m: pts.iter().map(|p| p.0).collect(),
                z_m: pts.iter().map(|p| p.1).collect(),
            },
        });
    });
    if let Err((_, stop)) = done {
        anyhow::bail!("the bubble at {} Pa: {}", stop.pressure_pa, stop.error);
    }
    Ok(frames)
}
