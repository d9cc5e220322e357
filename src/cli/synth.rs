//! `bulge synth`: a synthetic experiment with known truth.

use std::path::PathBuf;

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::axisym;
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::track::image::Encoding;
use bulge::track::synth::{self, SequenceSpec, Silhouette, SynthFrame};

/// Flags of `bulge synth`.
///
/// Writes OUT_DIR/photos/frame_NNN.{png,jpg}, OUT_DIR/pressure.csv
/// (file,pressure_pa), OUT_DIR/experiment.toml (ready for `bulge track`) and
/// OUT_DIR/truth.csv (file,pressure_pa,height_m,apex_x_px,apex_y_px). The
/// bubble is the exact axisymmetric solution for the material at each
/// pressure, seen from the side, drawn with exact pixel-area anti-aliasing
/// over a textured background and a clamp fixture. The same flags and seed
/// give the same files.
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

    /// Image width, px (default 640; the disc spans 70 % of it).
    #[arg(long, default_value_t = 640)]
    pub width: usize,

    /// Image height, px (default 480; the clamp plane at 80 % of it).
    #[arg(long, default_value_t = 480)]
    pub height: usize,

    /// Seed of the placement, background texture and noise (default 1).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,

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

    /// Largest memory a photo may take while it is drawn, GB (default 2):
    /// larger pictures are refused before any work.
    #[arg(long, default_value_t = 2.0)]
    pub max_memory_gb: f64,
}

/// Runs `bulge synth`.
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
    let specimen = Specimen {
        radius_m: args.radius_m,
        thickness_m: args.thickness_m,
        poisson: args.poisson,
        prebulge_height_m: 0.0,
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
    let opts = axisym::Options::default();
    let mut frames = Vec::with_capacity(n);
    let pb = super::progress(n as u64, "solve");
    for &p in &pressures {
        let sol = axisym::solve_pressure(&material, &specimen, p, &opts)
            .map_err(|e| anyhow!("the bubble at {p} Pa: {e}"))
            .bad_input()?;
        frames.push(SynthFrame {
            pressure_pa: p,
            silhouette: Silhouette {
                rho_m: sol.profile.rho_m.clone(),
                z_m: sol.profile.z_m.clone(),
            },
        });
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
    };
    let w = synth::write_sequence(&args.out_dir, &spec, &frames).map_err(|e| {
        if e.is_bad_input() {
            Failure::BadInput(e.into())
        } else {
            Failure::Failed(e.into())
        }
    })?;
    let hmax = w.truth.iter().map(|t| t.height_m).fold(0.0, f64::max);
    println!(
        "wrote {n} {}x{} {} photos ({:.2} MB) of a {} bubble, {:.0}..{:.0} Pa, apex height up to {:.4e} m ({:.1} px), {:.4e} m/px, + pressure.csv, truth.csv, experiment.toml -> {}",
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
