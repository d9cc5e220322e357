//! Tables, plots and the HTML report.

pub mod plot;
