//! `bulge track`: photos -> apex height per photo.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;

use super::{Classify, Failure};
use bulge::experiment::Experiment;
use bulge::io::OutputPlan;
use bulge::track::{self, Options, Refine, TrackError};

/// Flags of `bulge track`.
///
/// Reads `[photos]` (a folder of photos, or a video's frames), `[calibration]`
/// and `[pressure]` (by file name, or a log by time interpolated at each
/// frame's time) of the experiment file, finds the bubble's apex in every
/// frame and writes
/// `frame,file,pressure_pa,apex_x_px,apex_y_px,score,height_m,height_std_m`,
/// and `time_s` last when the frames' times are known.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The experiment file (TOML with [specimen], [photos], [calibration], [pressure]).
    pub experiment: PathBuf,

    /// Output CSV of heights (written whole or not at all).
    #[arg(short, long, default_value = "heights.csv")]
    pub output: PathBuf,

    /// Minimum TM_CCOEFF_NORMED score (in [-1, 1]) for a frame to count; a
    /// frame below it fails the run, naming the photo, unless
    /// --skip-bad-frames. Default 0.5: well-lit photos of a moving dome score
    /// above 0.9; below 0.5 the template has usually locked on something else.
    #[arg(long, default_value_t = 0.5)]
    pub min_score: f64,

    /// Leave frames below --min-score, and frames whose apex the
    /// plausibility guards refuse (below the clamp plane, against the
    /// pressure, an edge that is not the dome's), out of the output (they
    /// are listed on stderr with the reason) instead of failing. A frame
    /// that breaks only a rule no physics bounds (a jump beyond the trend,
    /// an edge residual above the frames' before) is kept either way, with
    /// a warning naming the photo.
    #[arg(long)]
    pub skip_bad_frames: bool,

    /// How the apex is located: `edge` (default: template match, then a local
    /// parabola fit of the bubble's top edge for the row), `quadratic`
    /// (2-D quadratic fit of the match score peak) or `integer` (the
    /// integer-pixel match alone, as OpenCV's minMaxLoc).
    #[arg(long, value_enum, default_value_t = Refine::Edge)]
    pub refine: Refine,

    /// Search margin around the predicted template position, px (default 8);
    /// the search widens to the whole region on a poor score.
    #[arg(long, default_value_t = 8)]
    pub search_margin_px: usize,

    /// Half-width of the span of columns of the edge fit, px (default: half
    /// the template width).
    #[arg(long)]
    pub edge_span_px: Option<usize>,

    /// Half-height of the window in which each column's edge row is located,
    /// px (default 3: covers +-2 standard deviations of a 1.5 px blur; a
    /// wider window gathers more noise, background gradient and the light
    /// of a highlight inside the dome).
    #[arg(long, default_value_t = 3)]
    pub edge_window_px: usize,
}

/// Runs `bulge track`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let start = Instant::now();
    if !(-1.0..=1.0).contains(&args.min_score) {
        return Err(Failure::BadInput(anyhow::anyhow!(
            "--min-score {} is outside [-1, 1], the range of TM_CCOEFF_NORMED scores",
            args.min_score
        )));
    }
    if args.edge_window_px < 2 {
        return Err(Failure::BadInput(anyhow::anyhow!(
            "--edge-window-px {} is too small: give at least 2 px (more than twice the blur)",
            args.edge_window_px
        )));
    }
    let exp = Experiment::read(&args.experiment)?;
    let plan = OutputPlan::new().inputs(super::experiment_inputs(&exp));
    super::guard(plan.output_as("-o", &args.output))?;
    let setup = track::setup_from_experiment(&exp).map_err(classify)?;
    let opts = Options {
        refine: args.refine,
        min_score: args.min_score,
        skip_bad_frames: args.skip_bad_frames,
        search_margin_px: args.search_margin_px,
        edge_span_px: args.edge_span_px,
        edge_window_px: args.edge_window_px,
    };
    let pb = super::progress(setup.frames.len() as u64, "track");
    let tracked = track::track(&setup, &opts, &|| pb.inc(1)).map_err(classify)?;
    pb.finish_and_clear();

    let out = tracked.heights_csv();
    if tracked.rows.is_empty() {
        return Err(Failure::BadInput(anyhow::anyhow!(
            "every one of the {} frames scored below --min-score {}: nothing to write; check the template and the region",
            setup.frames.len(),
            args.min_score
        )));
    }
    out.write(&args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))
        .failed()?;

    for w in &tracked.warnings {
        eprintln!("warning: {w}");
    }
    for s in &tracked.skipped {
        eprintln!("skipped frame {} ({}): {}", s.frame, s.file, s.reason);
    }
    if setup.lens.is_none() {
        eprintln!("{}", track::lens::UNCALIBRATED_NOTE);
    }
    let secs = start.elapsed().as_secs_f64();
    let n = tracked.rows.len();
    let (hmin, hmax) = tracked
        .rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.height_m), b.max(r.height_m))
        });
    let smin = tracked
        .rows
        .iter()
        .map(|r| r.score)
        .fold(f64::INFINITY, f64::min);
    let mut stds: Vec<f64> = tracked.rows.iter().map(|r| r.height_std_m).collect();
    stds.sort_by(f64::total_cmp);
    println!(
        "tracked {n} of {} photos ({} skipped) of {}x{} px in {secs:.2} s ({:.1} photos/s, matching {:.2} ms/photo): height {:.4e}..{:.4e} m, median height_std {:.2e} m, lowest score {smin:.3} -> {}",
        setup.frames.len(),
        tracked.skipped.len(),
        tracked.image_size[0],
        tracked.image_size[1],
        setup.frames.len() as f64 / secs.max(1e-9),
        1e3 * tracked.locate_seconds / setup.frames.len() as f64,
        hmin,
        hmax,
        stds[stds.len() / 2],
        args.output.display()
    );
    Ok(())
}

fn classify(e: TrackError) -> Failure {
    Failure::of(e)
}
