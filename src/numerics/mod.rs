//! The numerical tools every stage shares, decided once: Brent's root
//! finder and minimiser over argmin ([`roots`]), the golden-section search
//! of the searches whose every point is a fit ([`golden`]), and one seeded
//! generator ([`Rng`]) for the synthetic photos, the Monte Carlo and the
//! tests.

pub mod golden;
mod rng;
pub mod roots;

pub use rng::Rng;
