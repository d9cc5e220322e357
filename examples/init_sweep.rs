//! `bulge init` + `bulge track` over the tracker sweep's synthetic world
//! (`bulge::track::synth::sweep`: photo size, noise, blur, JPEG or PNG, a
//! random framing; a lighter or darker clamp ring face, a light bubble on a
//! dark wall, light from one side, defocus, motion blur, vignetting;
//! neo-Hookean, Mooney-Rivlin, Ogden or Gent membranes; 5-16 photos up to
//! 0.6-0.97 of the limit pressure), each seen by a pinhole camera placed
//! as labs place it: 0.25-1 m from the bubble's axis, 0-5 degrees above the
//! clamp ring's centre (both drawn from the seed). The set-up is found from
//! the photos and `2a` alone (the camera's distance given), the heights
//! tracked with the experiment file it wrote and compared with the truth.
//! `--clean N` sequences (seeds 1..N) and `--dirty N` with clutter, a
//! highlight and uneven light (seeds 1_000_001..; photos the tracker
//! refuses are left out, as `--skip-bad-frames` does).
//!
//! The table gives per level of every factor (and of the camera's distance
//! and elevation): sequences, set-ups refused (clean, dirty), RMS(scale
//! error / its stated deviation, the clamp row's part included) and the
//! share within 1.96, the largest scale error and the largest height
//! error, %, and RMS(height error / all stated terms) over the photos
//! tracked, and the set-ups whose heights are off by more than 3 of all
//! their stated deviations (RMS over their photos: the set-up itself
//! wrong). `--verbose` lists every refusal with its message; `--keep
//! DIR --seed S` runs the one sequence of seed `S` in `DIR` and keeps its
//! photos and `init.toml`.
//!
//! Run: `cargo run --release --features harness --example init_sweep --
//! --clean 120 --dirty 60 [--sizes 640x480,800x600] [--verbose]`

use std::collections::BTreeMap;

use bulge::track::synth::sweep::{self, FACTORS};
use bulge::track::synth::trial::{InitTrial, init_and_track};

#[path = "common/args.rs"]
mod args;

/// A sequence's seed, whether dirty, its factor levels and what init and
/// track gave (or why the set-up was refused).
type Outcome = (u64, bool, Levels, Result<InitTrial, String>);

#[derive(Default)]
struct Tally {
    sequences: usize,
    refused: [usize; 2],
    scale_z: Vec<f64>,
    scale: f64,
    heights: f64,
    z2: f64,
    photos: usize,
    /// Set-ups whose heights are off by more than 3 stated deviations, RMS
    /// over their photos.
    misstated: usize,
}

impl Tally {
    fn add(&mut self, dirty: bool, t: &Result<InitTrial, String>) {
        self.sequences += 1;
        match t {
            Err(_) => self.refused[usize::from(dirty)] += 1,
            Ok(t) => {
                self.scale_z.push(t.scale / t.scale_std_all);
                self.scale = self.scale.max(t.scale.abs());
                self.heights = self.heights.max(t.heights);
                self.z2 += t.rms_z_all.powi(2) * t.tracked[0] as f64;
                self.photos += t.tracked[0];
                self.misstated += usize::from(t.rms_z_all > 3.0);
            }
        }
    }

    fn row(&self, factor: &str, level: &str) -> String {
        let n = self.scale_z.len().max(1) as f64;
        let rms = (self.scale_z.iter().map(|z| z * z).sum::<f64>() / n).sqrt();
        let within = self.scale_z.iter().filter(|z| z.abs() < 1.96).count() as f64 / n;
        format!(
            "| {factor} | {level} | {} | {} | {} | {rms:.2} | {:.0} % | {:.3} | {:.3} | {:.2} | {} |",
            self.sequences,
            self.refused[0],
            self.refused[1],
            100.0 * within,
            100.0 * self.scale,
            100.0 * self.heights,
            (self.z2 / self.photos.max(1) as f64).sqrt(),
            self.misstated,
        )
    }
}

/// The sequence of `seed` (dirty from 1_000_001 on) seen by its camera,
/// and its factor levels with the camera's.
fn case(seed: u64, sizes: &[(usize, usize)]) -> Result<(sweep::Case, Levels), String> {
    let mut case = sweep::draw(seed, seed > 1_000_000, sizes).map_err(|e| e.to_string())?;
    // The camera, from the seed (independently of the look).
    let mut r = bulge::track::synth::Rng::new(seed ^ 0x00CA_3E7A);
    let distance = 0.25 + 0.75 * r.uniform();
    let elevation = 5.0 * r.uniform();
    case.spec.look.camera_distance_m = distance;
    case.spec.look.elevation_deg = elevation;
    let mut levels: Levels = case
        .levels
        .iter()
        .map(|(f, l)| (f.to_string(), l.clone()))
        .collect();
    levels.push((
        "camera distance".into(),
        ["0.25-0.5 m", "0.5-0.75 m", "0.75-1 m"][((distance - 0.25) / 0.25) as usize].into(),
    ));
    levels.push((
        "above the ring".into(),
        ["0-1.7 deg", "1.7-3.3 deg", "3.3-5 deg"][(elevation / 5.0 * 3.0) as usize].into(),
    ));
    Ok((case, levels))
}

type Levels = Vec<(String, String)>;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let clean = args::number(&args, "--clean", 40)?;
    let dirty = args::number(&args, "--dirty", 20)?;
    let verbose = args.iter().any(|a| a == "--verbose");
    let sizes = args::sizes(&args)?;
    if let Some(i) = args.iter().position(|a| a == "--keep") {
        let dir = std::path::PathBuf::from(args.get(i + 1).ok_or("--keep needs a folder")?);
        let (case, levels) = case(args::number(&args, "--seed", 1)?, &sizes)?;
        std::fs::create_dir_all(&dir)?;
        println!("{levels:?}");
        match init_and_track(&dir, &case.spec, &case.frames, false) {
            Ok(t) => println!("{t:#?}"),
            Err(e) => println!("refused: {e:#}"),
        }
        return Ok(());
    }
    let results: Vec<Outcome> =
        sweep::for_each_seed(&sweep::seeds(clean, dirty), |seed, dirty| {
            let (case, levels) = match case(seed, &sizes) {
                Ok(c) => c,
                Err(e) => {
                    eprintln!("seed {seed}: not drawn: {e}");
                    return None;
                }
            };
            let out = tempfile::tempdir()
                .map_err(|e| format!("no temporary folder: {e}"))
                .and_then(|dir| {
                    init_and_track(dir.path(), &case.spec, &case.frames, false)
                        .map_err(|e| format!("{e:#}"))
                });
            Some((seed, dirty, levels, out))
        })?
        .into_iter()
        .flatten()
        .collect();
    let mut all = Tally::default();
    let mut by: BTreeMap<(usize, String, String), Tally> = BTreeMap::new();
    for (_, dirty, levels, t) in &results {
        all.add(*dirty, t);
        for (name, level) in levels {
            let i = FACTORS
                .iter()
                .position(|f| f == name)
                .unwrap_or(FACTORS.len());
            by.entry((i, name.clone(), level.clone()))
                .or_default()
                .add(*dirty, t);
        }
    }
    println!(
        "| factor | level | sequences | set-ups refused (clean) | set-ups refused (dirty) | RMS(scale error / std) | scale within 1.96 std | largest scale error, % | largest height error, % | RMS(height error / all stated) | set-ups beyond 3 stated |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    println!("{}", all.row("all", "all"));
    for ((_, name, level), t) in &by {
        if name != "sequence" {
            println!("{}", t.row(name, level));
        }
    }
    if verbose {
        for (seed, dirty, levels, t) in &results {
            let look = levels
                .iter()
                .filter(|(f, l)| f != "sequence" && l != "none")
                .map(|(f, l)| format!("{f} {l}"))
                .collect::<Vec<String>>()
                .join("; ");
            match t {
                Err(e) => println!(
                    "seed {seed} ({}): refused: {} [{look}]",
                    if *dirty { "dirty" } else { "clean" },
                    e.replace('\n', " ")
                ),
                Ok(t) if t.heights > 0.003 || (t.scale / t.scale_std_all).abs() > 3.0 => println!(
                    "seed {seed}: scale {:+.3} % ({:.2} std), heights up to {:.3} % (RMS {:.2} stated) [{look}]",
                    100.0 * t.scale,
                    t.scale / t.scale_std_all,
                    100.0 * t.heights,
                    t.rms_z_all
                ),
                Ok(_) => {}
            }
        }
    }
    Ok(())
}
