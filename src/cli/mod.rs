//! The command line: clap derive, one module per subcommand. Each subcommand
//! turns raw flags into validated settings, calls the library stage and writes
//! its outputs whole or not at all.
//!
//! Exit status: 0 on success, 2 when the input was refused (a bad file, flag or
//! value: the message says which and how to fix it), 1 when the work itself
//! failed (a solver that diverged, an I/O failure while writing).

pub mod bench;
pub mod calibrate;
mod checks;
pub mod fit;
mod flags;
pub mod init;
pub mod run;
pub mod simulate;
pub mod stress;
pub mod study;
pub mod synth;
pub mod track;

use std::sync::Mutex;

use bulge::pipeline::{Observer, Stage, Timing};
pub use checks::*;
use clap::{Parser, Subcommand};
pub use flags::flag_of;
use indicatif::{ProgressBar, ProgressStyle};

/// bulge: bubble-inflation (pressure-bulge) tests of thin elastic membranes.
///
/// Photos -> apex heights (track) -> stress/strain (stress) -> material (fit)
/// -> simulated heights (simulate) -> report (run). Every stage reads and
/// writes plain CSV/TOML files with SI units in the column names.
#[derive(Debug, Parser)]
#[command(name = "bulge", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// The stage to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands, one per pipeline stage plus the whole pipeline.
/// (Parsed once per process: the size difference between variants is moot.)
#[derive(Debug, Subcommand)]
#[allow(clippy::large_enum_variant)]
pub enum Command {
    /// Photos -> experiment file: clamp plane, axis, region, template, scale, elevation.
    Init(init::Args),
    /// Photos -> apex height per photo (OpenCV template matching, sub-pixel).
    Track(track::Args),
    /// Chessboard photos -> the lens: focal lengths, principal point, distortion ([camera]).
    Calibrate(calibrate::Args),
    /// Write a synthetic experiment with known truth (photos, pressures, truth).
    Synth(synth::Args),
    /// Apex heights -> stress and strain (spherical-cap formulas).
    Stress(stress::Args),
    /// Stress/strain -> material (quartic secant modulus, hyperelastic models).
    Fit(fit::Args),
    /// Material -> simulated bubble heights (mass-spring models, axisymmetric reference).
    Simulate(simulate::Args),
    /// The whole pipeline on an experiment file, with the comparison report.
    Run(run::Args),
    /// One material across several specimens: each through the whole pipeline, then mean, scatter, interval.
    Study(study::Args),
    /// Speed against error of every solver and integrator.
    Bench(bench::Args),
}

/// Why a subcommand failed: the input was refused, or the work failed.
#[derive(Debug)]
pub enum Failure {
    /// A bad file, flag or value (exit status 2).
    BadInput(anyhow::Error),
    /// The work itself failed (exit status 1).
    Failed(anyhow::Error),
}

impl Failure {
    /// A library error, by the library's own rule ([`bulge::Refusal`]).
    pub fn of<E: bulge::Refusal + Into<anyhow::Error>>(e: E) -> Failure {
        if e.is_bad_input() {
            Failure::BadInput(e.into())
        } else {
            Failure::Failed(e.into())
        }
    }

    /// The process exit status for this failure.
    pub fn exit_code(&self) -> i32 {
        match self {
            Failure::BadInput(_) => 2,
            Failure::Failed(_) => 1,
        }
    }

    /// The error chain.
    pub fn error(&self) -> &anyhow::Error {
        match self {
            Failure::BadInput(e) | Failure::Failed(e) => e,
        }
    }
}

impl From<anyhow::Error> for Failure {
    fn from(e: anyhow::Error) -> Self {
        Failure::Failed(e)
    }
}

impl From<bulge::io::InputError> for Failure {
    fn from(e: bulge::io::InputError) -> Self {
        Failure::BadInput(e.into())
    }
}

/// Sorts a result's error into [`Failure::BadInput`] or [`Failure::Failed`].
pub trait Classify<T> {
    /// The error is the user's input being refused.
    fn bad_input(self) -> Result<T, Failure>;
    /// The error is a failure of the work.
    fn failed(self) -> Result<T, Failure>;
}

impl<T, E: Into<anyhow::Error>> Classify<T> for Result<T, E> {
    fn bad_input(self) -> Result<T, Failure> {
        self.map_err(|e| Failure::BadInput(e.into()))
    }
    fn failed(self) -> Result<T, Failure> {
        self.map_err(|e| Failure::Failed(e.into()))
    }
}

/// Runs a parsed command line.
pub fn dispatch(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Init(a) => init::run(a),
        Command::Track(a) => track::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Synth(a) => synth::run(a),
        Command::Stress(a) => stress::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Run(a) => run::run(a),
        Command::Study(a) => study::run(a),
        Command::Bench(a) => bench::run(a),
    }
}

/// A progress bar on stderr (hidden when stderr is not a terminal).
pub fn progress(len: u64, what: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{bar:40}] {pos}/{len} {elapsed_precise} eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// Progress bars and one line per stage of a run on stderr.
#[derive(Default)]
pub struct Console {
    bar: Mutex<Option<ProgressBar>>,
}

impl Console {
    /// Clears the progress bar left, if any.
    pub fn clear(&self) {
        if let Some(b) = self.bar.lock().expect("progress bar").take() {
            b.finish_and_clear();
        }
    }
}

impl Observer for Console {
    fn start(&self, stage: Stage, steps: u64) {
        let mut bar = self.bar.lock().expect("progress bar");
        if let Some(b) = bar.take() {
            b.finish_and_clear();
        }
        if steps > 0 {
            *bar = Some(progress(steps, stage.name()));
        }
    }

    fn tick(&self) {
        if let Some(b) = self.bar.lock().expect("progress bar").as_ref() {
            b.inc(1);
        }
    }

    fn note(&self, stage: Stage, message: &str) {
        // the simulate stage's notes are printed with the results
        if stage != Stage::Simulate {
            eprintln!("         {message}");
        }
    }

    fn done(&self, t: &Timing) {
        if let Some(b) = self.bar.lock().expect("progress bar").take() {
            b.finish_and_clear();
        }
        let files = match t.stage {
            Stage::Track => "heights.csv",
            Stage::Stress => "stress_strain.csv",
            Stage::Fit => "material.toml, fit.svg, fit.png",
            Stage::Simulate => "simulated.csv",
            Stage::Report => "heights.svg, heights.png, report.html, summary.md",
        };
        let step = Stage::ALL.iter().position(|s| *s == t.stage).unwrap_or(0) + 1;
        // measured heights (`[heights]`): the track stage writes nothing
        if !t.files {
            eprintln!("[{step}/5] {:<8} {}", t.stage.name(), t.what);
            return;
        }
        eprintln!("[{step}/5] {:<8} {} -> {files}", t.stage.name(), t.what);
    }
}
