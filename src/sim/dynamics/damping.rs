//! Damping: the small-strain stiffness of every spring, the dashpot
//! coefficient set from it, and the dashpot forces.
//!
//! A dashpot acts along every spring, `f_i = c ((v_j - v_i) . u) u` with `u`
//! the current unit edge vector.
//! * [`DampingLaw::Critical`] (default): `c = zeta * 2 sqrt(k m_red)`,
//!   `m_red = m_i m_j / (m_i + m_j)`, a fraction `zeta` of the spring's
//!   critical value. `k` is the spring's small-strain stiffness
//!   ([`reference_edge_stiffness`]).
//! * [`DampingLaw::SudhamaniMerriliance`]: eq 5 of Sudhamani & Merriliance (2019),
//!   `d = sqrt(k (m_i + m_j)) / l0`. It is **not** a damping coefficient:
//!   `sqrt(k m)` is already N s/m, and the extra `1/l0` makes it N s/m^2, so
//!   the damping it gives depends on the unit of length and on the mesh size
//!   (a finer mesh is damped more). It is offered to reproduce that paper,
//!   not recommended.

use nalgebra::{Point3, Vector3};

use super::Dynamics;
use crate::sim::mesh::Mesh;
use crate::sim::springs::SpringModel;

/// How the dashpot coefficient of a spring is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DampingLaw {
    /// `c = fraction * 2 sqrt(k m_red)`.
    Critical(f64),
    /// Sudhamani & Merriliance (2019) eq 5, `d = sqrt(k (m_i + m_j)) / l0`
    /// (dimensionally inconsistent).
    SudhamaniMerriliance,
}

impl Default for DampingLaw {
    fn default() -> Self {
        DampingLaw::Critical(DEFAULT_DAMPING)
    }
}

/// Default fraction of a spring's critical damping.
pub const DEFAULT_DAMPING: f64 = 0.1;

/// Per-spring small-strain stiffness, N/m, of a spring model with modulus
/// `young_pa`: Van Gelder eq 1, Lloyd eq 4, and for TP MSS eq 16 (its
/// stiffness under equibiaxial strain, `Q0 (a0^2 - b0^2 + c0^2)` summed over
/// the triangles). Negative contributions (obtuse triangles) are kept; the
/// damping clamps the sum at zero.
pub fn reference_edge_stiffness(
    mesh: &Mesh,
    model: SpringModel,
    young_pa: f64,
    poisson: f64,
    thickness_m: f64,
) -> Vec<f64> {
    let (e, nu, t) = (young_pa, poisson, thickness_m);
    let mut k = vec![0.0; mesh.edges.len()];
    for (tri, te) in mesh.triangles.iter().zip(&mesh.triangle_edges) {
        let p = tri.map(|i| mesh.nodes[i as usize]);
        let area = (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0;
        let l2: [f64; 3] =
            std::array::from_fn(|s| (p[(s + 2) % 3] - p[(s + 1) % 3]).norm_squared());
        for s in 0..3 {
            let (a2, b2) = (l2[(s + 1) % 3], l2[(s + 2) % 3]);
            let c2 = l2[s];
            let ks = match model {
                SpringModel::VanGelder => {
                    e * t / (1.0 + nu) * area / c2
                        + e * t * nu / (1.0 - nu * nu) * (a2 + b2 - c2) / (8.0 * area)
                }
                SpringModel::Lloyd => e * t * area / c2,
                // the membrane model: TP MSS is the linear CST at small strain
                SpringModel::Tp | SpringModel::TpPaper | SpringModel::Membrane => {
                    e * t / (8.0 * (1.0 - nu) * area) * (a2 + b2 - c2)
                }
            };
            k[te[s] as usize] += ks;
        }
    }
    k
}

/// Dashpot coefficient per edge, N s/m.
pub fn edge_damping(mesh: &Mesh, k: &[f64], masses: &[f64], law: DampingLaw) -> Vec<f64> {
    mesh.edges
        .iter()
        .zip(k)
        .map(|(e, &k)| {
            let (mi, mj) = (masses[e[0] as usize], masses[e[1] as usize]);
            let k = k.max(0.0);
            match law {
                DampingLaw::Critical(z) => z * 2.0 * (k * mi * mj / (mi + mj)).sqrt(),
                DampingLaw::SudhamaniMerriliance => {
                    let l0 = (mesh.nodes[e[1] as usize] - mesh.nodes[e[0] as usize]).norm();
                    (k * (mi + mj)).sqrt() / l0
                }
            }
        })
        .collect()
}

impl Dynamics<'_> {
    /// The active dashpots at positions `x`: the edge's nodes `(i, j)`, its
    /// coefficient and the unit vector from `i` to `j` (edges without
    /// damping or of zero length are left out).
    pub(super) fn dashpots<'b>(
        &'b self,
        x: &'b [Point3<f64>],
    ) -> impl Iterator<Item = (usize, usize, f64, Vector3<f64>)> + 'b {
        self.mesh
            .edges
            .iter()
            .zip(&self.damping)
            .filter_map(|(e, &c)| {
                let (i, j) = (e[0] as usize, e[1] as usize);
                let d = x[j] - x[i];
                let l = d.norm();
                (c != 0.0 && l > 0.0).then(|| (i, j, c, d / l))
            })
    }

    /// Adds the dashpot forces at positions `x` and velocities `v` to `f`.
    pub fn add_damping(&self, x: &[Point3<f64>], v: &[Vector3<f64>], f: &mut [Vector3<f64>]) {
        add_dashpot_forces(self.dashpots(x), v, f);
    }
}

/// Adds the forces of `pots` (as [`Dynamics::dashpots`] lists them) at
/// velocities `v` to `f`: `c ((v_j - v_i) . u) u` on `i`, its opposite on `j`.
pub(super) fn add_dashpot_forces(
    pots: impl IntoIterator<Item = (usize, usize, f64, Vector3<f64>)>,
    v: &[Vector3<f64>],
    f: &mut [Vector3<f64>],
) {
    for (i, j, c, u) in pots {
        let fv = u * (c * (v[j] - v[i]).dot(&u));
        f[i] += fv;
        f[j] -= fv;
    }
}
