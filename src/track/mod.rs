//! Photos -> apex heights (the only module that uses OpenCV).
//!
//! Tudruj et al. (2023), section 7 (Fig. 13): a template showing the border between the
//! bubble's top and the background is found in every photo inside an
//! elongated region where the apex moves; its position in pixels becomes a
//! height in metres. Here:
//!
//! 1. every photo is decoded to grayscale (in parallel, rayon) and cropped to
//!    the region `roi_px`; OpenCV's own thread pool is set to one thread, for
//!    the whole process, at this module's first OpenCV call (a program that
//!    sets OpenCV's thread count itself should do so after it);
//! 2. the template is matched with OpenCV's `TM_CCOEFF_NORMED`, only in a
//!    window around the position predicted from the last two frames, widened
//!    to the whole region when the score is poor;
//! 3. the peak is refined to sub-pixel precision by a 2-D quadratic fit of
//!    the 3x3 scores around it, and then (default) the apex row is measured
//!    directly by a local edge fit: the edge row of each column near the apex
//!    (centroid of the vertical intensity differences) and a least-squares
//!    parabola through them. The template is cut from one frame, while the
//!    apex curvature changes from frame to frame, which biases the match
//!    itself by a fraction of a pixel; the edge fit has no such bias;
//! 4. pixels become metres with the calibration: `height = (clamp_row - y) *
//!    scale`, or relative to the reference frame plus the pre-bulge height.
//!
//! Image coordinates: the centre of the top-left pixel is (0, 0), x to the
//! right, y down (OpenCV's convention).

pub mod annotate;
pub mod calibrate;
pub mod image;
pub mod init;
pub mod lens;
pub(crate) mod matcher;
pub mod persp;
pub mod synth;
pub mod video;

mod decode;
mod error;
mod exif_time;
mod guards;
mod pole;
mod setup;
mod tracker;
mod types;

pub use error::*;
pub use pole::{FLATTENING_SLOPE, PoleMeasure, pole_flattening, pooled_flattening};
pub use setup::*;
pub use tracker::*;
pub use types::*;

#[cfg(test)]
mod init_tests;
#[cfg(test)]
mod persp_tests;
#[cfg(test)]
mod tests;
