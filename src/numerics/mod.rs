//! The numerical tools every stage shares, decided once: Brent's root
//! finder and minimiser over argmin ([`roots`]), and one seeded generator
//! ([`Rng`]) for the synthetic photos, the Monte Carlo and the tests.

mod rng;
pub mod roots;

pub use rng::Rng;
