//! Tables, plots and the HTML report of a run, and of a study across specimens.

#[cfg(feature = "plots")]
pub(crate) mod figures;
pub mod fit_command;
pub mod fit_outputs;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub(crate) mod html;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub(crate) mod laws;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub mod out_dir;
#[cfg(feature = "plots")]
pub mod plot;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub mod run_dir;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub mod run_files;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub mod study_files;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub(crate) mod table;
