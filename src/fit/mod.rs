//! Stress/strain -> material: the quartic secant modulus and hyperelastic fits.
