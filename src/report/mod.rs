//! Tables, plots and the HTML report of a run.

#[cfg(feature = "plots")]
pub mod figures;
pub mod fit_outputs;
pub mod html;
#[cfg(feature = "plots")]
pub mod plot;
pub mod table;
