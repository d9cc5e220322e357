//! # bulge
//!
//! Bubble-inflation (pressure-bulge) tests of thin elastic membranes, from
//! photos to a verdict on the material model. Each stage is a library entry
//! from its input to its output in memory; the `bulge` command line and
//! `pipeline::run` only chain them and write files.
//!
//! | stage | entry | in -> out |
//! |---|---|---|
//! | track | `track::track` (feature `opencv`) | photos -> apex height per photo |
//! | stress | [`mechanics::stress_strain`] | heights -> stress and strain (spherical cap) |
//! | fit | [`fit::fit_material`] | stress/strain -> [`Material`] with its [`fit::Provenance`] |
//! | simulate | [`DiscSolver`], [`sim::SceneSolver`] (mass-spring), [`axisym::solve_pressure`] (exact) | material -> heights |
//! | all of them | `pipeline::run` (feature `opencv`) | [`Experiment`] -> `pipeline::RunOutput` |
//!
//! The whole pipeline on the bundled demo experiment (16 photos):
//!
//! ```
//! # #[cfg(feature = "opencv")] {
//! use bulge::{Experiment, HeightModel, Settings, SpringModel};
//!
//! let exp = Experiment::read(concat!(env!("CARGO_MANIFEST_DIR"), "/data/demo/experiment.toml"))?;
//! let out = bulge::pipeline::run(&exp, &Settings::default())?;
//! for row in &out.comparison {
//!     let errors: Vec<String> = row.rel_errors().iter()
//!         .map(|e| e.map_or("-".into(), |e| format!("{:+.2} %", 100.0 * e))).collect();
//!     println!("{:7.1} Pa: {}", row.pressure_pa, errors.join("  "));
//! }
//! // TP MSS within 3 % of every measured height
//! let tp = out.rel_errors_of(HeightModel::Spring(SpringModel::Tp)).expect("TP MSS was run");
//! assert!(tp.iter().all(|(_, e)| e.is_some_and(|e| e.abs() < 0.03)));
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A disc of a given material, simulated without any photo:
//!
//! ```
//! use bulge::{DiscSolver, Material, Specimen, SpringModel};
//!
//! let latex = Specimen { radius_m: 0.0375, thickness_m: 0.35e-3, poisson: 0.45, prebulge_height_m: 0.0 };
//! let mut disc = DiscSolver::new(&latex, &Material::linear(1.0e6, 0.45), SpringModel::Tp)?;
//! disc.solve_to(5000.0)?;
//! println!("apex {:.2} mm", 1e3 * disc.apex_height_m());
//! # Ok::<(), bulge::sim::SimError>(())
//! ```
//!
//! ## Cargo features
//!
//! `opencv` (tracking, synthetic photos, annotated frames), `plots` (figures)
//! and `cli` (the `bulge` binary) are on by default. Without them
//! (`--no-default-features`) the library builds the stress, fit, simulate
//! and axisymmetric stages with neither OpenCV, libclang, plotters nor clap.

#![warn(missing_docs)]

pub mod axisym;
pub mod camera;
pub mod dome;
pub mod experiment;
pub mod fit;
pub mod heights;
pub mod io;
pub mod material;
pub mod mechanics;
pub(crate) mod numerics;
pub mod pipeline;
pub mod pressure_log;
pub mod report;
pub mod setting;
pub mod sim;
#[cfg(feature = "opencv")]
pub mod study;
#[cfg(feature = "opencv")]
pub mod track;

/// Whether an error is the user's input being refused or the work failing:
/// the one rule behind the command line's exit status (2: fix the input;
/// 1: the work failed on valid input). Every error type of the stages
/// implements it; an error that wraps another asks it.
pub trait Refusal {
    /// True when the input was refused (the message names what to fix),
    /// false when the work itself failed.
    fn is_bad_input(&self) -> bool;
}

pub use experiment::{Experiment, Specimen};
pub use material::{Material, Model, StrainMeasure};
pub use mechanics::{Modulus, ModulusStress, TrueStress};
pub use pipeline::{PipelineError, Settings, Stage};
#[cfg(feature = "opencv")]
pub use pipeline::{RunError, RunOutput};
pub use sim::{DiscSolver, HeightModel, SimError, SpringModel};
