//! One integration-test binary that drives the real `bulge` executable in
//! temporary folders; one module per subcommand.

mod util;

mod bench;
mod calibrate;
mod dynamics;
mod fit;
mod heights;
mod heights_origin;
mod init;
mod mistakes;
mod run;
mod simulate;
mod stress;
mod study;
mod track;
mod video;
