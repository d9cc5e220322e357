//! The tracker over the synthetic world: seeded random experiments of
//! `bulge::track::synth::sweep` (size 640x480-1280x960, noise, blur, JPEG or
//! PNG, random framing; a lighter or darker clamp ring face, a light bubble
//! on a dark wall, light from one side, defocus, motion blur, vignetting;
//! neo-Hookean, Mooney-Rivlin, Ogden or Gent membranes; 5-16 photos up to
//! 0.6-0.97 of the limit pressure), `--clean N` of them without clutter or
//! gloss (seeds 1..N) and `--dirty N` with clutter behind the bubble, a
//! specular highlight and uneven light (seeds 1_000_001..). Each is tracked
//! with the true set-up and `--skip-bad-frames` and compared with the truth.
//!
//! The table gives per level of every factor: sequences, photos, photos
//! refused in clean and in dirty sequences (goal 0 for clean ones), photos
//! written more than 4 of their stated standard deviations off (goal 0),
//! the RMS of error / stated std (goal 0.8-1.2), the share within 1.96
//! stated std (goal 93-97 %) and the RMS apex-row error, px.
//!
//! Run: `cargo run --release --example track_sweep -- --clean 300 --dirty 300
//! [--sizes 640x480,800x600] [--verbose]` (`--sizes`: the photo sizes drawn
//! from, by default 640x480, 800x600, 1024x768 and 1280x960; `--verbose`
//! lists the worst photos with their looks and every refusal; `--csv PATH`
//! writes every photo: seed, frame, error and stated std in px, the refusal,
//! the sequence's factor levels, the true apex row, the edge fit's
//! columns and its residual RMS); `--keep DIR --seed S` draws and
//! tracks the one sequence of seed `S` (dirty from 1_000_001 on) into
//! `DIR` and keeps its photos, `experiment.toml` and `truth.csv`, to look
//! at a photo the table lists).

use std::collections::BTreeMap;

use bulge::track::synth::sweep::{self, FACTORS, Photo};

#[path = "common/args.rs"]
mod args;

/// A sequence's seed, whether dirty, its factor levels and its photos.
type Outcome = (u64, bool, Vec<(&'static str, String)>, Vec<Photo>);

#[derive(Default)]
struct Tally {
    sequences: usize,
    photos: usize,
    refused_clean: usize,
    refused_dirty: usize,
    written: usize,
    beyond4: usize,
    within196: usize,
    z2: f64,
    e2: f64,
}

impl Tally {
    fn add(&mut self, dirty: bool, photos: &[Photo]) {
        self.sequences += 1;
        for p in photos {
            self.photos += 1;
            match p.written {
                Some((e, s)) => {
                    let z = e / s;
                    self.written += 1;
                    self.beyond4 += usize::from(z.abs() > 4.0);
                    self.within196 += usize::from(z.abs() <= 1.96);
                    self.z2 += z * z;
                    self.e2 += e * e;
                }
                None if dirty => self.refused_dirty += 1,
                None => self.refused_clean += 1,
            }
        }
    }

    fn row(&self, factor: &str, level: &str) -> String {
        let w = self.written.max(1) as f64;
        format!(
            "| {factor} | {level} | {} | {} | {} | {} | {} | {:.2} | {:.1} % | {:.3} |",
            self.sequences,
            self.photos,
            self.refused_clean,
            self.refused_dirty,
            self.beyond4,
            (self.z2 / w).sqrt(),
            100.0 * self.within196 as f64 / w,
            (self.e2 / w).sqrt()
        )
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--keep") {
        let dir = args.get(i + 1).ok_or("--keep needs a folder")?;
        let seed = args::number(&args, "--seed", 1)?;
        let case = sweep::draw(seed, seed > 1_000_000, &args::sizes(&args)?)?;
        std::fs::create_dir_all(dir)?;
        for p in sweep::run(&case, std::path::Path::new(dir)) {
            match (p.written, p.refused) {
                (Some((e, s)), _) => {
                    println!("frame {}: error {e:+.4} px, stated {s:.4} px", p.frame)
                }
                (_, Some(why)) => println!("frame {}: refused: {why}", p.frame),
                _ => {}
            }
        }
        return Ok(());
    }
    let clean = args::number(&args, "--clean", 40)?;
    let dirty = args::number(&args, "--dirty", 40)?;
    let verbose = args.iter().any(|a| a == "--verbose");
    let csv = args
        .iter()
        .position(|a| a == "--csv")
        .map(|i| args.get(i + 1).cloned().ok_or("--csv needs a path"))
        .transpose()?;
    let sizes = args::sizes(&args)?;
    let results: Vec<Outcome> = sweep::for_each_seed(
        &sweep::seeds(clean, dirty),
        |seed, dirty| match sweep::draw(seed, dirty, &sizes) {
            Ok(case) => {
                let photos = match tempfile::tempdir() {
                    Ok(dir) => sweep::run(&case, dir.path()),
                    Err(e) => vec![Photo {
                        frame: 0,
                        written: None,
                        refused: Some(format!("no temporary folder: {e}")),
                        truth_row_px: None,
                        columns: None,
                        edge_rms_px: None,
                    }],
                };
                (seed, dirty, case.levels, photos)
            }
            Err(e) => {
                eprintln!("seed {seed}: not drawn: {e}");
                (seed, dirty, Vec::new(), Vec::new())
            }
        },
    )?;
    let mut all = Tally::default();
    let mut by: BTreeMap<(usize, String), Tally> = BTreeMap::new();
    for (_, dirty, levels, photos) in &results {
        if levels.is_empty() {
            continue;
        }
        all.add(*dirty, photos);
        for (name, level) in levels {
            let i = FACTORS.iter().position(|f| f == name).unwrap_or(0);
            by.entry((i, level.clone()))
                .or_default()
                .add(*dirty, photos);
        }
    }
    println!(
        "| factor | level | sequences | photos | refused (clean) | refused (dirty) | beyond 4 std | RMS error/std | within 1.96 std | apex row RMS error, px |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    println!("{}", all.row("all", "all"));
    for ((i, level), t) in &by {
        println!("{}", t.row(FACTORS[*i], level));
    }
    if let Some(path) = csv {
        write_csv(&path, &results)?;
    }
    if verbose {
        let look = |levels: &[(&'static str, String)]| {
            levels
                .iter()
                .skip(1)
                .filter(|(_, l)| l != "none")
                .map(|(f, l)| format!("{f} {l}"))
                .collect::<Vec<String>>()
                .join("; ")
        };
        let mut worst: Vec<(f64, u64, bool, usize, f64, f64, String)> = results
            .iter()
            .flat_map(|(seed, dirty, levels, photos)| {
                let look = look(levels);
                photos.iter().filter_map(move |p| {
                    p.written
                        .map(|(e, s)| ((e / s).abs(), *seed, *dirty, p.frame, e, s, look.clone()))
                })
            })
            .collect();
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        eprintln!("worst photos written (|error| / stated std):");
        for (z, seed, dirty, frame, e, s, look) in worst.iter().take(25) {
            let kind = if *dirty { "dirty" } else { "clean" };
            eprintln!(
                "  seed {seed} ({kind}), frame {frame}: error {e:+.3} px, std {s:.3} px, {z:.1} std [{look}]"
            );
        }
        eprintln!("photos refused:");
        for (seed, dirty, levels, photos) in &results {
            for p in photos {
                if let Some(why) = &p.refused {
                    let kind = if *dirty { "dirty" } else { "clean" };
                    let look: Vec<String> = levels
                        .iter()
                        .skip(1)
                        .filter(|(_, l)| l != "none")
                        .map(|(f, l)| format!("{f} {l}"))
                        .collect();
                    eprintln!(
                        "  seed {seed} ({kind}), frame {}: {why} [{}]",
                        p.frame,
                        look.join("; ")
                    );
                }
            }
        }
    }
    Ok(())
}

/// Every photo of the sweep as a CSV row, for analysis beyond the table.
fn write_csv(path: &str, results: &[Outcome]) -> Result<(), Box<dyn std::error::Error>> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "seed",
        "dirty",
        "frame",
        "error_px",
        "std_px",
        "refused",
        "levels",
        "truth_row_px",
        "columns",
        "edge_rms_px",
    ])?;
    for (seed, dirty, levels, photos) in results {
        let look: Vec<String> = levels.iter().map(|(f, l)| format!("{f}={l}")).collect();
        for p in photos {
            let (e, s) = p.written.map_or((String::new(), String::new()), |(e, s)| {
                (format!("{e:.5}"), format!("{s:.5}"))
            });
            w.write_record([
                seed.to_string(),
                dirty.to_string(),
                p.frame.to_string(),
                e,
                s,
                p.refused.clone().unwrap_or_default(),
                look.join(";"),
                p.truth_row_px.map_or(String::new(), |r| format!("{r:.4}")),
                p.columns.map_or(String::new(), |c| c.to_string()),
                p.edge_rms_px.map_or(String::new(), |r| format!("{r:.5}")),
            ])?;
        }
    }
    w.flush()?;
    Ok(())
}
