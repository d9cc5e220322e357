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
    let spec = Specimen {
        radius_m,
        thickness_m,
        poisson: material.poisson,
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
            "this disc's limit pressure is {pl:.6e} Pa (exact axisymmetric solution); {pressure_pa} Pa is below it, so an equilibrium exists: refine the pressure steps or raise --max-iterations"
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
                "{neg} of {} springs of the van-gelder model have a negative stiffness (eq 1's nu term (a^2 + b^2 - c^2) / (8 |T|) is negative opposite an obtuse angle): the lattice may have no stable equilibrium; re-mesh with acute triangles or use --model tp",
                k.len()
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
        + membrane.node_loads.len() * 32;
    // dynamics: x, v, f, scratch (Vector3 each), inverse mass; damping and k per edge
    let dyn_b = n * (4 * p3 + 8) + e * 16;
    mesh_b + mem_b + dyn_b
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3};

    use super::*;
    use crate::material::Model;
    use crate::sim::dynamics::{
        DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy,
    };
    use crate::sim::mesh::{self, Constraint, DiscOptions};
    use crate::sim::paper003::{SheetSetup, in_plane, static_solution};
    use crate::sim::scene::DiscPredictor;
    use crate::sim::solve::{self, Options, Solver};
    use crate::sim::{SimError, springs::Membrane};

    fn linear(e: f64, nu: f64) -> Material {
        Material {
            model: Model::Linear { young_pa: e },
            poisson: nu,
            fit: None,
        }
    }

    /// Static apex height of a disc (sector) and the axisymmetric one.
    fn disc_heights(
        mat: &Material,
        rings: usize,
        p: f64,
        steps: usize,
    ) -> Result<(f64, f64), SimError> {
        let (a, t) = (0.0375, 0.35e-3);
        let m = mesh::disc(DiscOptions {
            radius_m: a,
            rings,
            sector: true,
        })?;
        let mut mem = Membrane::new(&m, SpringModel::Tp, mat, t, 1100.0)?;
        let pred = DiscPredictor {
            radius_m: a,
            young_pa: mem.law.young(1.0).1,
            thickness_m: t,
            poisson: mat.poisson,
        };
        let mut x = m.nodes.clone();
        let mut ws = None;
        let opts = Options::default();
        let mut p0 = 0.0;
        for k in 1..=steps {
            let p1 = p * k as f64 / steps as f64;
            solve::continuation(
                &mut mem,
                &m.nodes,
                &mut x,
                p0,
                p1,
                Solver::Newton,
                &opts,
                &pred,
                &mut ws,
            )?;
            p0 = p1;
        }
        let spec = Specimen {
            radius_m: a,
            thickness_m: t,
            poisson: mat.poisson,
            prebulge_height_m: 0.0,
        };
        let h = crate::axisym::solve_pressure(mat, &spec, p, &crate::axisym::Options::default())
            .expect("axisym reference")
            .height_m;
        Ok((x[0].z, h))
    }

    /// Hard case: a stiff material with a large step. E = 1 GPa on the 003
    /// sheet: Verlet at 20 times its limit sub-steps and lands on the same
    /// answer as at its limit; with the refuse policy the message gives the
    /// limit; unchecked, the watch stops it before any NaN.
    #[test]
    fn stiff_material_large_step() {
        let setup = SheetSetup {
            young_pa: 1.0e9,
            ..SheetSetup::default()
        };
        let mesh = setup.mesh(60);
        let node = mesh.probe("middle").unwrap();
        let mut mem = setup.membrane(&mesh, "middle", 1.0e5);
        let limit = {
            let d = Dynamics::new(&mut mem, &mesh, setup.damping).unwrap();
            d.estimate_step(&mesh.nodes)
                .unwrap()
                .limit(Integrator::Verlet)
        };
        let run = |mem: &mut Membrane, dt: f64, policy: StepPolicy| {
            let mut d = Dynamics::new(mem, &mesh, setup.damping).unwrap();
            let mut x = mesh.nodes.clone();
            let mut v = vec![Vector3::zeros(); x.len()];
            let opts = DynOptions {
                integrator: Integrator::Verlet,
                dt_s: dt,
                t_end_s: 200.0 * limit,
                policy,
                ..DynOptions::default()
            };
            d.run(&mut x, &mut v, &opts, &|x| {
                (x[node] - mesh.nodes[node]).norm()
            })
        };
        let big = run(&mut mem, 20.0 * limit, StepPolicy::Substep).unwrap();
        assert!(big.substeps >= 22, "{}", big.substeps);
        let small = run(&mut mem, 0.5 * limit, StepPolicy::Substep).unwrap();
        assert_eq!(small.substeps, 1);
        // same time grid at the outputs: the sub-stepped run is the same run at h = dt/substeps
        assert!(big.samples.iter().all(|s| s.value_m.is_finite()));
        let e = run(&mut mem, 20.0 * limit, StepPolicy::Refuse).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, DynError::StepTooLarge { .. }), "{msg}");
        assert!(msg.contains(&format!("{limit:.4e}")), "{msg}");
        let e = run(&mut mem, 3.0 * limit, StepPolicy::Unchecked).unwrap_err();
        assert!(matches!(e, DynError::Diverged { .. }), "{e}");
    }

    /// Hard case: zero strain. At a state where one side keeps its rest
    /// length while the triangle's height changes, tp-paper switches to eq 16
    /// and that side's tension drops to zero; 1e-9 of strain later it is back
    /// to eq 11's value. The division-free tp has no jump. At rest both give
    /// exactly zero force.
    #[test]
    fn zero_strain_tp_paper_jumps_tp_does_not() {
        let s3 = 3f64.sqrt();
        let p0 = vec![
            Point3::new(0.5, s3 / 2.0, 0.0),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
        ];
        let m = Mesh::new(p0.clone(), vec![[1, 2, 0]], vec![Constraint::Free; 3]).unwrap();
        let mat = linear(1.0e6, 0.45);
        // vertex 0 moved up: side 1-2 (rest length 1) keeps its length exactly
        let at = |eps: f64| {
            vec![
                Point3::new(0.5, s3 / 2.0 * 1.1, 0.0),
                Point3::new(-eps / 2.0, 0.0, 0.0),
                Point3::new(1.0 + eps / 2.0, 0.0, 0.0),
            ]
        };
        let force = |model: SpringModel, x: &[Point3<f64>]| {
            let mem = Membrane::new(&m, model, &mat, 1e-3, 1000.0).unwrap();
            let mut f = vec![Vector3::zeros(); 3];
            mem.forces(x, &mut f).unwrap();
            f[1].x // vertex 1 pulled along the unchanged side
        };
        for model in [SpringModel::Tp, SpringModel::TpPaper] {
            let mem = Membrane::new(&m, model, &mat, 1e-3, 1000.0).unwrap();
            let mut f = vec![Vector3::zeros(); 3];
            mem.forces(&p0, &mut f).unwrap();
            assert!(
                f.iter().all(|v| v.norm() == 0.0),
                "{model:?} at rest: {f:?}"
            );
        }
        let (tp0, tp1) = (
            force(SpringModel::Tp, &at(0.0)),
            force(SpringModel::Tp, &at(1e-9)),
        );
        let (pp0, pp1) = (
            force(SpringModel::TpPaper, &at(0.0)),
            force(SpringModel::TpPaper, &at(1e-9)),
        );
        assert!(
            (tp0 - tp1).abs() < 1e-6 * tp0.abs(),
            "tp continuous: {tp0} vs {tp1}"
        );
        assert!(
            (pp1 - tp1).abs() < 1e-6 * tp1.abs(),
            "tp-paper = tp off zero strain: {pp1} vs {tp1}"
        );
        assert!(
            (pp0 - pp1).abs() > 0.1 * tp1.abs(),
            "tp-paper jumps at zero strain: {pp0} vs {pp1}"
        );
    }

    /// Hard case: apex past the hemisphere (h > a). The linear material at
    /// 15 kPa (h/a = 1.27 exactly; its limit point is at 17.16 kPa): the tp
    /// disc of 8 rings is within 3 % of the exact axisymmetric height.
    #[test]
    fn apex_past_the_hemisphere() {
        let (h, href) = disc_heights(&linear(1.0e6, 0.45), 8, 15_000.0, 3).unwrap();
        assert!(href > 0.0375, "reference {href}");
        assert!(h > 0.0375, "{h}");
        // measured: 2.2 % low at 8 rings (pole stretch 2.1)
        assert!((h - href).abs() < 0.03 * href, "{h} vs {href}");
    }

    /// Hard case: nu = 0.49 (nearly incompressible): tp stays within 1 % of
    /// the axisymmetric height; nu = 0.5 is refused.
    #[test]
    fn nearly_incompressible() {
        let (h, href) = disc_heights(&linear(1.0e6, 0.49), 8, 5000.0, 1).unwrap();
        assert!((h - href).abs() < 0.01 * href, "{h} vs {href}");
        let m = mesh::disc(DiscOptions {
            radius_m: 1.0,
            rings: 2,
            sector: true,
        })
        .unwrap();
        assert!(Membrane::new(&m, SpringModel::Tp, &linear(1.0e6, 0.5), 1e-3, 1000.0).is_err());
    }

    /// Hard case: obtuse and sliver triangles. The 003 sheet (at 3.5 kPa) with every
    /// other column of nodes pulled to 0.1 of the spacing from its left
    /// neighbour (angles down to about 6 deg and up to about 160 deg). tp
    /// stays within 15 % of the regular mesh (13 % stiffer) and a Verlet run at its estimated step is
    /// stable (the estimate falls with the small masses); Van Gelder's eq 1
    /// gives the sides opposite the obtuse angles a negative stiffness, the
    /// lattice has no stable equilibrium, Newton stops with NoEquilibrium and
    /// [`mesh_warnings`] names the cause.
    #[test]
    fn obtuse_and_sliver_triangles() {
        let setup = SheetSetup {
            young_pa: 3500.0,
            ..SheetSetup::default()
        };
        let regular = setup.mesh(200);
        let mut nodes = regular.nodes.clone();
        let xs: Vec<f64> = {
            let mut v: Vec<f64> = nodes.iter().map(|p| p.x).collect();
            v.sort_by(f64::total_cmp);
            v.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
            v
        };
        let hx = xs[1] - xs[0];
        for p in nodes.iter_mut() {
            let c = (p.x / hx).round() as usize;
            if c % 2 == 1 {
                p.x -= 0.9 * hx;
            }
        }
        let mut bad = Mesh::new(
            nodes,
            regular.triangles.clone(),
            regular.constraints.clone(),
        )
        .unwrap();
        bad.probes = regular.probes.clone();
        in_plane(&mut bad);
        let q = bad.quality();
        assert!(
            q.non_acute_share > 0.3 && q.min_angle_deg < 15.0 && q.max_angle_deg > 140.0,
            "{q:?}"
        );
        let node = regular.probe("middle").unwrap();
        // tp: a correct result
        let s = SheetSetup {
            model: SpringModel::Tp,
            ..setup
        };
        let mut good = s.membrane(&regular, "middle", 10.0);
        let xg = static_solution(&mut good, &regular, 2).unwrap();
        let mut m = s.membrane(&bad, "middle", 10.0);
        let xb = static_solution(&mut m, &bad, 2).unwrap();
        let (ug, ub) = (
            (xg[node] - regular.nodes[node]).norm(),
            (xb[node] - bad.nodes[node]).norm(),
        );
        // measured: 13 % stiffer than the regular mesh
        assert!((ub - ug).abs() < 0.15 * ug, "tp: {ub} vs regular {ug}");
        let lim_g = Dynamics::new(&mut good, &regular, s.damping)
            .unwrap()
            .estimate_step(&regular.nodes)
            .unwrap()
            .limit(Integrator::Verlet);
        let mut d = Dynamics::new(&mut m, &bad, s.damping).unwrap();
        let lim_b = d
            .estimate_step(&bad.nodes)
            .unwrap()
            .limit(Integrator::Verlet);
        assert!(lim_b < lim_g, "{lim_b} vs {lim_g}");
        let mut x = bad.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let opts = DynOptions {
            integrator: Integrator::Verlet,
            dt_s: 0.9 * lim_b,
            t_end_s: 300.0 * lim_b,
            ..DynOptions::default()
        };
        let r = d.run(&mut x, &mut v, &opts, &|x| x[node].y).unwrap();
        assert!(r.samples.iter().all(|s| s.value_m.is_finite()));
        let w = mesh_warnings(&bad, SpringModel::Tp, &s.material(), s.thickness_m);
        assert!(w.iter().any(|w| w.contains("acute")), "{w:?}");
        // Van Gelder: a clear message
        let s = SheetSetup {
            model: SpringModel::VanGelder,
            ..setup
        };
        let mut m = s.membrane(&bad, "middle", 10.0);
        let e = static_solution(&mut m, &bad, 2).unwrap_err();
        assert!(e.to_string().contains("no equilibrium"), "{e}");
        let w = mesh_warnings(&bad, SpringModel::VanGelder, &s.material(), s.thickness_m);
        assert!(w.iter().any(|w| w.contains("negative stiffness")), "{w:?}");
        assert!(
            mesh_warnings(
                &regular,
                SpringModel::VanGelder,
                &s.material(),
                s.thickness_m
            )
            .iter()
            .all(|w| !w.contains("negative"))
        );
    }

    /// Hard case: a pressure above the limit point of a neo-Hookean bubble.
    /// The static solve stops with the last equilibrium, the note gives the
    /// axisymmetric limit pressure (NOTES: P = p a / (C1 t) = 3.7583).
    #[test]
    fn above_the_limit_point() {
        let (a, t, c1) = (0.0375, 0.35e-3, 1.0e5);
        let mat = Material {
            model: Model::NeoHookean { c1_pa: c1 },
            poisson: 0.49,
            fit: None,
        };
        let pl = 3.7583 * c1 * t / a;
        let (p_lim, _) = disc_limit_point(&mat, a, t).unwrap();
        assert!((p_lim - pl).abs() < 2e-3 * pl, "{p_lim} vs {pl}");
        let err = disc_heights(&mat, 4, 1.3 * pl, 4).unwrap_err();
        assert!(matches!(err, SimError::NoEquilibrium { .. }), "{err}");
        let note = limit_note(&mat, a, t, 1.3 * pl).unwrap();
        assert!(note.contains(&format!("{p_lim:.6e}")), "{note}");
        // the dynamic run at that pressure grows until the watch stops it
        let m = mesh::disc(DiscOptions {
            radius_m: a,
            rings: 4,
            sector: true,
        })
        .unwrap();
        let mut mem = Membrane::new(&m, SpringModel::Tp, &mat, t, 1100.0).unwrap();
        mem.pressure_pa = 1.3 * pl;
        let mut d = Dynamics::new(&mut mem, &m, DampingLaw::Critical(1.0)).unwrap();
        let mut x = m.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let opts = DynOptions {
            integrator: Integrator::SymplecticEuler,
            dt_s: 2e-5,
            t_end_s: 2.0,
            ..DynOptions::default()
        };
        let e = d.run(&mut x, &mut v, &opts, &|x| x[0].z).unwrap_err();
        assert!(
            matches!(e, DynError::Diverged { .. } | DynError::Sim(_)),
            "{e}"
        );
    }

    /// Hard case: compression. In the plane, the springs carry compression
    /// like a 2D plate (a real membrane would wrinkle): pushing the free edge
    /// gives the tension's displacement mirrored at small load, and the
    /// compressed springs are counted. Free out of its plane, a flat sheet
    /// has no stiffness there: Newton stops with a clear error, no NaN.
    #[test]
    fn compression() {
        let setup = SheetSetup::default();
        let mesh = setup.mesh(120);
        let node = mesh.probe("middle").unwrap();
        let load = |fx: f64| {
            let mut m = setup.membrane(&mesh, "middle", 0.0);
            m.node_loads = vec![(node, Vector3::new(fx, 0.0, 0.0))];
            m
        };
        let f = 0.01 * setup.thickness_m;
        let mut mt = load(f);
        let xt = static_solution(&mut mt, &mesh, 1).unwrap();
        let mut mc = load(-f);
        let xc = static_solution(&mut mc, &mesh, 1).unwrap();
        let (ut, uc) = (
            xt[node].x - mesh.nodes[node].x,
            xc[node].x - mesh.nodes[node].x,
        );
        assert!(
            ut > 0.0 && uc < 0.0 && (ut + uc).abs() < 0.02 * ut,
            "{ut} {uc}"
        );
        let (count, min) = compressed_springs(&mesh, &xc);
        assert!(count > 0 && min < 0.0);
        // free out of plane
        let mut free = mesh.clone();
        for c in free.constraints.iter_mut() {
            if *c != Constraint::Fixed {
                *c = Constraint::Free;
            }
        }
        let mut m = setup.membrane(&free, "middle", 0.0);
        m.node_loads = vec![(node, Vector3::new(-f, 0.0, 0.0))];
        let mut x = free.nodes.clone();
        match solve::newton(&mut m, &mut x, 0.0, &Options::default()) {
            Err(e) => assert!(e.to_string().contains("equilibrium"), "{e}"),
            Ok(_) => {
                // if it converges, it converged to the in-plane answer
                assert!(x.iter().all(|p| p.z.abs() < 1e-9 && p.x.is_finite()));
            }
        }
    }

    /// Hard case: a 1e5-node mesh. The memory of mesh, membrane and an
    /// explicit run is below 1.2 kB per node (from the data structures), and
    /// a few Verlet steps run.
    #[test]
    fn hundred_thousand_nodes_memory_bound() {
        let rings = mesh::disc_rings_for_nodes(100_000, false) + 1;
        let m = mesh::disc(DiscOptions {
            radius_m: 0.0375,
            rings,
            sector: false,
        })
        .unwrap();
        assert!(m.nodes.len() >= 100_000, "{}", m.nodes.len());
        let mut mem =
            Membrane::new(&m, SpringModel::Tp, &linear(1.0e6, 0.45), 0.35e-3, 1100.0).unwrap();
        let bytes = memory_bytes(&m, &mem);
        let per_node = bytes as f64 / m.nodes.len() as f64;
        assert!(per_node < 1200.0, "{per_node} B/node");
        mem.pressure_pa = 5000.0;
        let mut d = Dynamics::new(&mut mem, &m, DampingLaw::Critical(0.1)).unwrap();
        let mut x = m.nodes.clone();
        let mut v = vec![Vector3::zeros(); x.len()];
        let opts = DynOptions {
            integrator: Integrator::Verlet,
            dt_s: 1e-8,
            t_end_s: 3e-8,
            policy: StepPolicy::Unchecked,
            ..DynOptions::default()
        };
        let r = d.run(&mut x, &mut v, &opts, &|x| x[0].z).unwrap();
        assert!(r.last() > 0.0 && r.last().is_finite());
    }
}
