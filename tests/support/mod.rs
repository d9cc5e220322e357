#[cfg(feature = "opencv")]
pub mod closed_loop;
pub mod validation;
