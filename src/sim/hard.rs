//! Helpers for the hard cases (docs/dynamics.md, "Hard cases"): the limit
//! pressure of a disc from the exact axisymmetric solution, springs left in
//! compression, and the memory a mesh takes.

use nalgebra::Point3;

use super::mesh::Mesh;
use super::springs::{Membrane, SpringModel};
use crate::experiment::Specimen;
use crate::material::Material;

/// The pressure maximum (limit point) of a clamped disc of this material,
/// from the exact axisymmetric solution: `(pressure_pa, apex height_m)`;
/// `None` when the inflation has no maximum up to a pole stretch of 4 (a
/// linear or stiffening material) or the reference cannot be computed.
pub fn disc_limit_point(
    material: &Material,
    radius_m: f64,
    thickness_m: f64,
) -> Option<(f64, f64)> {
    // The exact solution takes the Poisson ratio from the material (and
    // needs none for the incompressible hyperelastic models, whose 0.5 a
    // specimen refuses): the specimen's is not used.
    let spec = Specimen {
        radius_m,
        thickness_m,
        poisson: 0.0,
        prebulge_height_m: 0.0,
    };
    crate::axisym::limit_point(material, &spec, &crate::axisym::Options::default())
        .ok()
        .flatten()
        .map(|s| (s.pressure_pa, s.height_m))
}

/// A sentence for a failed disc solve: the limit pressure when there is one.
pub fn limit_note(
    material: &Material,
    radius_m: f64,
    thickness_m: f64,
    pressure_pa: f64,
) -> Option<String> {
    let (pl, hl) = disc_limit_point(material, radius_m, thickness_m)?;
    Some(if pressure_pa > pl {
        format!(
            "this disc's limit pressure is {pl:.6e} Pa (exact axisymmetric solution, apex height {hl:.4e} m): above it a pressure-controlled membrane has no equilibrium (it snaps through and keeps growing); ask for pressures below {pl:.6e} Pa"
        )
    } else {
        format!(
            "this law's limit pressure for the disc is {pl:.6e} Pa (exact axisymmetric solution); {} Pa is below it, so the law has an equilibrium there, but a spring model softer than the law (its heights above the exact ones at the pressures before) reaches its own limit point sooner and then has none: compare its heights with the exact solution's; otherwise add intermediate pressures or raise the iteration cap",
            crate::io::fmt_short(pressure_pa)
        )
    })
}

/// Warnings about a mesh for a spring model: triangles that are not acute
/// (TP MSS's derivation assumes acute ones) and springs whose small-strain
/// stiffness is negative (Van Gelder's eq 1 and TP's eq 16 opposite an
/// obtuse angle; summed over the edge's triangles): a lattice with negative
/// springs may have no stable equilibrium.
pub fn mesh_warnings(
    mesh: &Mesh,
    model: SpringModel,
    material: &Material,
    thickness_m: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    let q = mesh.quality();
    if q.non_acute_share > 0.0 && matches!(model, SpringModel::Tp | SpringModel::TpPaper) {
        out.push(format!(
            "{:.1} % of the triangles are not acute (largest angle {:.1} deg): TP MSS's derivation assumes acute triangles",
            100.0 * q.non_acute_share,
            q.max_angle_deg
        ));
    }
    if model == SpringModel::VanGelder {
        let e0 = super::springs::ModulusLaw::from_material(material)
            .map(|l| l.young(1.0).1)
            .unwrap_or(1.0);
        let k = super::dynamics::reference_edge_stiffness(
            mesh,
            model,
            e0,
            material.poisson,
            thickness_m,
        );
        let neg = k.iter().filter(|&&k| k < 0.0).count();
        if neg > 0 {
            out.push(format!(
                "{neg} of {} springs of the van-gelder model have a negative stiffness (eq 1's nu term (a^2 + b^2 - c^2) / (8 |T|) is negative opposite an obtuse angle): the lattice may have no stable equilibrium; re-mesh with acute triangles or use {} tp",
                k.len(),
                crate::setting::Setting::Model
            ));
        }
    }
    out
}

/// Springs shorter than at rest: `(count, smallest strain)`.
pub fn compressed_springs(mesh: &Mesh, x: &[Point3<f64>]) -> (usize, f64) {
    let mut count = 0;
    let mut min = 0.0_f64;
    for e in &mesh.edges {
        let (i, j) = (e[0] as usize, e[1] as usize);
        let l0 = (mesh.nodes[j] - mesh.nodes[i]).norm();
        let s = (x[j] - x[i]).norm() / l0 - 1.0;
        if s < -1e-9 {
            count += 1;
            min = min.min(s);
        }
    }
    (count, min)
}

/// Bytes held by a mesh, its membrane and an explicit dynamic run (positions,
/// velocities, forces, per-edge damping and stiffness, inverse masses), from
/// the sizes of the data structures (heap only, vectors at their length).
pub fn memory_bytes(mesh: &Mesh, membrane: &Membrane) -> usize {
    use std::mem::size_of;
    let n = mesh.nodes.len();
    let t = mesh.triangles.len();
    let e = mesh.edges.len();
    let p3 = size_of::<Point3<f64>>();
    let c = size_of::<super::mesh::Constraint>();
    let mesh_b = n * (p3 + c) + t * (2 * size_of::<[u32; 3]>()) + e * size_of::<[u32; 2]>();
    // membrane: per triangle v, l0, l0sq, area0, c (f64 x 10 + u32 x 3);
    // per edge the edge list, l0 and (linear springs) k; per node
    // constraints and masses
    let tri_b = 3 * 4 + 10 * 8 + 4; // padded to 8
    let mem_b = t * tri_b
        + e * (size_of::<[u32; 2]>() + 2 * 8)
        + n * (c + 8)
        + membrane.node_loads.len() * 32
        // the membrane model's rest data per triangle
        + if membrane.model == SpringModel::Membrane {
            t * size_of::<super::cst::CstRest>()
        } else {
            0
        };
    // dynamics: x, v, f, scratch (Vector3 each), inverse mass; damping and k per edge
    let dyn_b = n * (4 * p3 + 8) + e * 16;
    mesh_b + mem_b + dyn_b
}
