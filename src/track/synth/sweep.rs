//! The tracker swept over the synthetic world: one seed draws a whole
//! experiment (the camera of [`random_camera`], the look of a lab, the
//! membrane's law and the photos' pressures), which is written, tracked
//! with the true set-up and `skip_bad_frames`, and compared photo by photo
//! with the truth. `cargo run --release --example track_sweep` tabulates
//! many; the test suite runs a few small ones.
//!
//! Every factor is drawn independently from the seed, so a table per
//! factor level averages over the others:
//! - size (from the sizes given), Gaussian blur 0.8-2 px, noise 1-4 grey
//!   levels, JPEG quality 80-95 or PNG (one in three), random framing;
//! - the clamp ring's top face as drawn by default, lighter than the
//!   background (a lit metal ring, grey 225) or darker than the ring's side
//!   (grey 20);
//! - a dark bubble on a light wall (default) or a light one (grey 205) on a
//!   dark wall (grey 45);
//! - light from one side (`Look::side_light` 0.15-0.45 either way) or not;
//! - defocus (a pillbox of radius 1-3 px) or not; motion blur (a line of
//!   1-4 px in any direction) or not; vignetting (corners losing 20-50 % of
//!   the light) or not;
//! - dirty sequences only: clutter behind the bubble, a specular highlight
//!   (grey 40-100; 8-20 degrees from the pole, 40 degrees either side, a
//!   size of 0.03 rad up to 0.08 rad or a third of its polar angle, a
//!   Gaussian or a heavy-tailed lobe: [`HighlightShape`]) and uneven light
//!   (0.1-0.4);
//! - the law: neo-Hookean (C1 = 0.2 MPa), Mooney-Rivlin (C2/C1 0.05-0.3,
//!   the same initial shear modulus), Ogden (Treloar's rubber, Ogden 1972)
//!   or Gent (mu = 0.4 MPa, Jm 10-40), all with Poisson 0.45;
//! - 5-16 photos, evenly spaced in pressure up to 0.6, 0.8 or 0.97 of the
//!   law's limit (pressure maximum, [`crate::axisym::limit_point`]), or of
//!   the pressure at pole stretch 2 when the law has none.
//!
//! Ogden, R. W. (1972), "Large deformation isotropic elasticity - on the
//! correlation of theory and experiment for incompressible rubberlike
//! solids", Proc. R. Soc. Lond. A 326, 565-584, doi:10.1098/rspa.1972.0026.

use std::path::Path;

use super::{
    Framing, HighlightShape, Look, Rng, SequenceSpec, SynthFrame, axisym_frame, random_camera,
};
use crate::experiment::Experiment;
use crate::material::{Material, Model};
use crate::track::image::Encoding;
use crate::track::{Options, setup_from_experiment, track};

/// One drawn experiment.
#[derive(Debug, Clone)]
pub struct Case {
    /// Its seed.
    pub seed: u64,
    /// With clutter, a highlight and uneven light.
    pub dirty: bool,
    /// The camera and the look.
    pub spec: SequenceSpec,
    /// The membrane's law.
    pub material: Material,
    /// The photos' pressures and profiles.
    pub frames: Vec<SynthFrame>,
    /// The level of every factor, by factor name.
    pub levels: Vec<(&'static str, String)>,
}

/// What became of one photo.
#[derive(Debug, Clone, PartialEq)]
pub struct Photo {
    /// Frame index.
    pub frame: usize,
    /// Apex-row error and stated standard deviation, px, when written.
    pub written: Option<(f64, f64)>,
    /// Why it was left out, when refused (or why the sequence failed).
    pub refused: Option<String>,
    /// The true apex row, px, when written.
    pub truth_row_px: Option<f64>,
    /// The columns of the edge fit, when written.
    pub columns: Option<usize>,
    /// The edge fit's residual RMS, px, when written: what the guards
    /// compare between photos.
    pub edge_rms_px: Option<f64>,
}

/// The names of the factors, in the order of [`Case::levels`].
pub const FACTORS: [&str; 15] = [
    "sequence",
    "size",
    "encoding",
    "noise",
    "blur",
    "ring face",
    "bubble",
    "side light",
    "defocus",
    "motion",
    "vignetting",
    "highlight",
    "law",
    "photos",
    "top pressure",
];

/// The law drawn for a sweep's case whose bubble cannot be solved.
#[derive(Debug, thiserror::Error)]
#[error("seed {seed}, {law}: {source}")]
pub struct DrawError {
    /// The case's seed.
    pub seed: u64,
    /// The law drawn, as the sweep's table names it.
    pub law: String,
    /// Why the axisymmetric solution failed.
    #[source]
    pub source: crate::axisym::AxisymError,
}

/// Draws the experiment of `seed` (`dirty`: with clutter, a highlight and
/// uneven light) at one of `sizes`. Fails, saying why, when the law's
/// bubble cannot be solved.
pub fn draw(seed: u64, dirty: bool, sizes: &[(usize, usize)]) -> Result<Case, DrawError> {
    let mut rng = Rng::new(seed ^ 0x5EE9_0D1E);
    let mut pick = |n: u64| (rng.next_u64() % n) as usize;
    let ring = pick(3);
    let light_bubble = pick(3) == 0;
    let side = pick(2) == 1;
    let defocus = pick(2) == 1;
    let motion = pick(2) == 1;
    let vignetting = pick(2) == 1;
    let png = pick(3) == 0;
    let law = pick(4);
    let n = 5 + pick(12);
    let top = [0.6, 0.8, 0.97][pick(3)];
    let mut u = Rng::new(seed ^ 0x0A11_CE55);
    let mut uni = |lo: f64, hi: f64| lo + (hi - lo) * u.uniform();
    let mut look = Look {
        ring_face_grey: [0.0, 225.0, 20.0][ring],
        ..Look::default()
    };
    if light_bubble {
        look.bubble_grey = 205.0;
        look.background_grey = 45.0;
    }
    if side {
        look.side_light = uni(0.15, 0.45) * if uni(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
    }
    if defocus {
        look.defocus_px = uni(1.0, 3.0);
    }
    if motion {
        look.motion_px = uni(1.0, 4.0);
        look.motion_deg = uni(0.0, 180.0);
    }
    if vignetting {
        look.vignetting = uni(0.2, 0.5);
    }
    if dirty {
        look.clutter = true;
        look.highlight_grey = uni(40.0, 100.0);
        look.uneven_light = uni(0.1, 0.4);
    }
    // The highlight's place, size and lobe, from a stream of their own (a
    // seed's other factors are drawn as they were before it varied): 8-20
    // degrees from the pole, 40 degrees either side, a size of 0.03 rad up
    // to 0.08 rad or a third of its polar angle (a spot on the outline
    // itself is a spot on the edge, which other tests draw), either lobe.
    let mut h = Rng::new(seed ^ 0x0016_6117);
    let mut hu = |lo: f64, hi: f64| lo + (hi - lo) * h.uniform();
    let polar_deg = hu(8.0, 20.0);
    let highlight = HighlightShape {
        polar_deg,
        azimuth_deg: hu(-40.0, 40.0),
        size_rad: hu(0.03, 0.08f64.min(polar_deg.to_radians() / 3.0)),
        heavy_tail: hu(0.0, 1.0) < 0.5,
    };
    if dirty {
        look.highlight = highlight;
    }
    let mut spec = random_camera(seed, sizes, look);
    if png {
        spec.encoding = Encoding::Png;
    }
    let (model, law_name) = match law {
        0 => (
            Model::NeoHookean { c1_pa: 0.2e6 },
            "neo-Hookean".to_string(),
        ),
        1 => {
            let r = uni(0.05, 0.3);
            let c1 = 0.2e6 / (1.0 + r);
            (
                Model::MooneyRivlin {
                    c1_pa: c1,
                    c2_pa: r * c1,
                },
                "Mooney-Rivlin".to_string(),
            )
        }
        2 => (
            Model::Ogden {
                mu_pa: vec![0.63e6, 0.0012e6, -0.01e6],
                alpha: vec![1.3, 5.0, -2.0],
            },
            "Ogden".to_string(),
        ),
        _ => (
            Model::Gent {
                mu_pa: 0.4e6,
                jm: uni(10.0, 40.0),
            },
            "Gent".to_string(),
        ),
    };
    let material = Material {
        model,
        poisson: 0.45,
        fit: None,
    };
    let opts = crate::axisym::Options::default();
    let why = |source| DrawError {
        seed,
        law: law_name.to_string(),
        source,
    };
    let limit = match crate::axisym::limit_point(&material, &spec.specimen, &opts).map_err(why)? {
        Some(s) => s.pressure_pa,
        None => {
            crate::axisym::solve_pole_stretch(&material, &spec.specimen, 2.0, &opts)
                .map_err(why)?
                .pressure_pa
        }
    };
    let frames = (1..=n)
        .map(|k| {
            let p = top * limit * k as f64 / n as f64;
            axisym_frame(&material, &spec.specimen, p, p).map_err(why)
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The scale of the random camera leaves the tallest bubble out of the
    // picture: the framing draws a scale that fits.
    if spec.scene(&frames).is_err() {
        spec.framing = Framing {
            random: true,
            ..Framing::default()
        };
    }
    let bin = |v: f64, edges: &[f64]| {
        let i = edges.iter().take_while(|&&e| v >= e).count();
        match i {
            0 => format!("< {}", edges[0]),
            i if i == edges.len() => format!(">= {}", edges[i - 1]),
            i => format!("{}-{}", edges[i - 1], edges[i]),
        }
    };
    let onoff = |on: bool, text: String| if on { text } else { "none".to_string() };
    let levels = vec![
        (
            "sequence",
            if dirty { "dirty" } else { "clean" }.to_string(),
        ),
        ("size", format!("{}x{}", spec.width, spec.height)),
        (
            "encoding",
            match spec.encoding {
                Encoding::Png => "PNG".to_string(),
                Encoding::Jpeg(_) => "JPEG 80-95".to_string(),
            },
        ),
        (
            "noise",
            format!("{} grey", bin(spec.noise_grey, &[2.0, 3.0])),
        ),
        ("blur", format!("sigma {} px", bin(spec.blur_px, &[1.4]))),
        (
            "ring face",
            ["default (58, side 38)", "lighter (225)", "darker (20)"][ring].to_string(),
        ),
        (
            "bubble",
            if light_bubble {
                "light (205) on a dark wall (45)"
            } else {
                "dark (72) on a light wall (190)"
            }
            .to_string(),
        ),
        ("side light", onoff(side, "0.15-0.45".into())),
        (
            "defocus",
            onoff(
                defocus,
                format!("radius {} px", bin(look.defocus_px, &[2.0])),
            ),
        ),
        ("motion", onoff(motion, "1-4 px".into())),
        ("vignetting", onoff(vignetting, "0.2-0.5".into())),
        (
            "highlight",
            onoff(
                dirty,
                if highlight.heavy_tail {
                    "heavy tail (GGX)"
                } else {
                    "Gaussian"
                }
                .into(),
            ),
        ),
        ("law", law_name),
        ("photos", if n <= 8 { "5-8" } else { "9-16" }.to_string()),
        ("top pressure", format!("{top} of the limit")),
    ];
    Ok(Case {
        seed,
        dirty,
        spec,
        material,
        frames,
        levels,
    })
}

/// Writes `case` into `dir`, tracks it with the true set-up and
/// `skip_bad_frames`, and says what became of every photo. A sequence
/// that cannot be written or tracked has all its photos refused with the
/// reason. Call it outside rayon's global pool (`track` decodes on it and
/// waits for it).
pub fn run(case: &Case, dir: &Path) -> Vec<Photo> {
    let n = case.frames.len();
    let fail = |why: String| {
        (0..n)
            .map(|frame| Photo {
                frame,
                written: None,
                refused: Some(why.clone()),
                truth_row_px: None,
                columns: None,
                edge_rms_px: None,
            })
            .collect()
    };
    let w = match super::write_sequence(dir, &case.spec, &case.frames) {
        Ok(w) => w,
        Err(e) => return fail(format!("not written: {e}")),
    };
    let opts = Options {
        skip_bad_frames: true,
        ..Options::default()
    };
    let tracked = Experiment::read(dir.join("experiment.toml"))
        .map_err(|e| e.to_string())
        .and_then(|e| setup_from_experiment(&e).map_err(|e| e.to_string()))
        .and_then(|s| track(&s, &opts, &|| {}).map_err(|e| e.to_string()));
    let t = match tracked {
        Ok(t) => t,
        Err(e) => return fail(format!("tracking failed: {e}")),
    };
    w.truth
        .iter()
        .enumerate()
        .map(|(frame, truth)| {
            if let Some(r) = t.rows.iter().find(|r| r.file == truth.file) {
                Photo {
                    frame,
                    written: Some((r.apex_y_px - truth.apex_y_px, r.apex_y_std_px)),
                    refused: None,
                    truth_row_px: Some(truth.apex_y_px),
                    columns: r.edge.map(|e| e.columns),
                    edge_rms_px: r.edge.map(|e| e.rms),
                }
            } else {
                let why = t
                    .skipped
                    .iter()
                    .find(|s| s.file == truth.file)
                    .map_or_else(|| "missing".to_string(), |s| s.reason.clone());
                Photo {
                    frame,
                    written: None,
                    refused: Some(why),
                    truth_row_px: None,
                    columns: None,
                    edge_rms_px: None,
                }
            }
        })
        .collect()
}

/// The photo sizes the sweeps draw from when none are given.
pub const SIZES: [(usize, usize); 4] = [(640, 480), (800, 600), (1024, 768), (1280, 960)];

/// Photo sizes from a list such as `640x480,800x600`; the error names the
/// item that is not `WIDTHxHEIGHT`.
pub fn parse_sizes(list: &str) -> Result<Vec<(usize, usize)>, String> {
    list.split(',')
        .map(|wh| {
            let bad = || format!("{wh} is not WIDTHxHEIGHT (such as 640x480)");
            let (w, h) = wh.split_once('x').ok_or_else(bad)?;
            Ok((w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?))
        })
        .collect()
}

/// The seeds of `clean` sequences (1 on) and of `dirty` ones (1_000_001
/// on), with whether each is dirty.
pub fn seeds(clean: u64, dirty: u64) -> Vec<(u64, bool)> {
    (1..=clean)
        .map(|s| (s, false))
        .chain((1..=dirty).map(|s| (1_000_000 + s, true)))
        .collect()
}

/// `f(seed, dirty)` for every seed, in parallel, in the seeds' order,
/// saying on stderr every tenth sequence done. The sequences run on a pool
/// of their own: `track` decodes on rayon's global pool and waits for it,
/// so it must not run on that pool itself.
pub fn for_each_seed<T: Send>(
    seeds: &[(u64, bool)],
    f: impl Fn(u64, bool) -> T + Sync,
) -> Result<Vec<T>, rayon::ThreadPoolBuildError> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let (total, done) = (seeds.len(), AtomicUsize::new(0));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(rayon::current_num_threads())
        .build()?;
    Ok(pool.install(|| {
        seeds
            .par_iter()
            .map(|&(seed, dirty)| {
                let out = f(seed, dirty);
                let k = done.fetch_add(1, Ordering::Relaxed) + 1;
                if k.is_multiple_of(10) || k == total {
                    eprintln!("{k} of {total} sequences");
                }
                out
            })
            .collect()
    }))
}
