//! Checks shared by the subcommands, made before any work: output paths
//! against the inputs and of the right kind, flag names added to library
//! messages, the parsers of flag values.

use std::path::{Path, PathBuf};

use anyhow::anyhow;
use bulge::experiment::Experiment;
use bulge::fit::FitModel;
use bulge::io::OutputPlan;

use super::Failure;

/// Refuses, before any work, an output that is an input, holds one or lies
/// in an input folder, or two outputs on one file (exit 2).
pub fn guard(plan: OutputPlan) -> Result<(), Failure> {
    plan.check()
        .map_err(|e| Failure::BadInput(anyhow!("{e} (inputs are never overwritten)")))
}

/// Every file an experiment reads: its file, the pressure log, the template
/// and each photo.
pub fn experiment_inputs(exp: &Experiment) -> Vec<PathBuf> {
    bulge::study::input_files(exp)
}

/// A library error about a setting, with the flag that sets it named: the
/// `(setting, flag)` whose setting the error is about adds "(flag)".
pub fn with_flags(e: bulge::io::InputError, flags: &[(&str, &str)]) -> bulge::io::InputError {
    match flags.iter().find(|(key, _)| e.setting == Some(*key)) {
        Some((_, flag)) => bulge::io::InputError {
            message: format!("{} ({flag})", e.message),
            ..e
        },
        None => e,
    }
}

/// Refuses an output file path that names a folder (the user's mistake,
/// exit 2), before any work.
pub fn output_file(path: &Path, flag: &str) -> Result<(), Failure> {
    if path.is_dir() {
        return Err(Failure::BadInput(anyhow!(
            "{flag} {} is a folder: give a file name (e.g. {})",
            path.display(),
            path.join("out.csv").display()
        )));
    }
    Ok(())
}

/// Refuses an output folder path that names an existing file (exit 2).
pub fn output_folder(path: &Path, flag: &str) -> Result<(), Failure> {
    if path.exists() && !path.is_dir() {
        return Err(Failure::BadInput(anyhow!(
            "{flag} {} is a file: give a folder for the outputs",
            path.display()
        )));
    }
    Ok(())
}

/// Parses a camera's tone curve (`srgb`, `linear`, a gamma).
pub fn parse_response(s: &str) -> Result<bulge::camera::Response, bulge::camera::ResponseError> {
    s.parse()
}

/// Parses a fit model name (`quartic`, `mooney-rivlin`, `ogden-3`, ...).
pub fn parse_fit_model(s: &str) -> Result<FitModel, bulge::fit::UnknownFitModel> {
    s.parse()
}
