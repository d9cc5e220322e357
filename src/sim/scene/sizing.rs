//! Mesh sizing by the accuracy wanted: the number of rings of a disc that
//! keeps each spring model's discretisation error below a target.

use super::super::mesh::{self, Mesh};
use super::super::springs::SpringModel;
use super::SimError;

/// Default disc rings (a 60 degree sector of 16 rings: 153 nodes).
pub const DEFAULT_DISC_RINGS: usize = 16;

/// Default rings of the ellipse (the whole hexagonal disc, scaled: 1801 nodes).
pub const DEFAULT_ELLIPSE_RINGS: usize = 24;

/// Default cells across the rectangle's half-width.
pub const DEFAULT_RECTANGLE_HALF_CELLS: usize = 8;

/// Default divisions of the sphere octant's edges.
pub const DEFAULT_SPHERE_DIVISIONS: usize = 16;

/// Relative height error of the disc against the mesh-converged height of the
/// same model, `C n^-1.7` for `n` rings. Measured (benches/sim.rs tables,
/// docs/simulate.md) on the latex disc at 5000-8940 Pa (h/a = 0.6-0.8), as the
/// largest error over the three pressures: TP MSS (and tp-paper)
/// `C = 0.045`, Van Gelder `0.27`, Lloyd `0.5`.
pub fn disc_error_constant(model: SpringModel) -> f64 {
    match model {
        SpringModel::Tp | SpringModel::TpPaper => 0.045,
        SpringModel::VanGelder => 0.27,
        SpringModel::Lloyd => 0.5,
        // measured like TP's (docs/axisym.md: 16 rings -0.50 % from its own limit at 8940 Pa)
        SpringModel::Membrane => 0.045,
    }
}

/// Rings of the disc mesh for a relative height error `acc` (against the
/// mesh-converged height of the same model) for every model in `models`
/// (all four when empty): `n = (C / acc)^(1/1.7)`, at least 4.
pub fn disc_rings_for_accuracy(acc: f64, models: &[SpringModel]) -> usize {
    let c = if models.is_empty() {
        &SpringModel::ALL[..]
    } else {
        models
    }
    .iter()
    .map(|m| disc_error_constant(*m))
    .fold(0.0, f64::max);
    ((c / acc).powf(1.0 / 1.7).ceil() as usize).max(4)
}

/// The disc's mesh of `rings` rings (a sector or the whole), on the dome of
/// height `dome_height_m` when it is positive (a slack membrane).
pub fn disc_mesh(
    radius_m: f64,
    dome_height_m: f64,
    rings: usize,
    sector: bool,
) -> Result<Mesh, SimError> {
    let mut m = mesh::disc(mesh::DiscOptions {
        radius_m,
        rings,
        sector,
    })?;
    if dome_height_m > 0.0 {
        mesh::lift_to_cap(&mut m, radius_m, dome_height_m);
    }
    Ok(m)
}
