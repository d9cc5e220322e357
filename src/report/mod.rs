//! Tables, plots and the HTML report, and the pipeline that `bulge run`
//! chains ([`pipeline`]).

pub mod closed_loop;
pub mod figures;
pub mod html;
pub mod pipeline;
pub mod plot;
pub mod table;
