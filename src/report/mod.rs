//! Tables, plots and the HTML report of a run.

#[cfg(feature = "plots")]
pub mod figures;
pub mod fit_outputs;
pub mod html;
#[cfg(feature = "plots")]
pub mod plot;
#[cfg(all(feature = "plots", feature = "opencv"))]
pub mod run_files;
pub mod table;
