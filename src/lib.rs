//! # bulge
//!
//! Bubble-inflation (pressure-bulge) tests of thin elastic membranes, from
//! photos to a verdict on the material model:
//!
//! 1. [`track`]: a folder of photos -> apex height per photo;
//! 2. [`mechanics`]: heights -> stress and strain (spherical-cap formulas);
//! 3. [`fit`]: stress/strain -> material (quartic secant modulus, hyperelastic models);
//! 4. [`sim`]: material -> simulated heights (TP MSS, Van Gelder, Lloyd springs);
//!    [`axisym`]: the exact axisymmetric reference;
//! 5. [`report`]: simulated against measured heights.
//!
//! Each stage is a pure function from its input table to its output table, so
//! that `bulge run` only chains them and a test can enter at any stage.

pub mod axisym;
pub mod experiment;
pub mod fit;
pub mod io;
pub mod material;
pub mod mechanics;
pub mod pipeline;
pub mod report;
pub mod sim;
#[cfg(feature = "opencv")]
pub mod track;
