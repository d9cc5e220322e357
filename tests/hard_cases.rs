//! The hard cases of the membrane solvers (the stiff sheet and the sliver
//! triangles are tested with the sheet of the integrator benchmarks): a zero-strain modulus jump, an apex past the hemisphere, a nearly
//! incompressible material, obtuse and sliver triangles, pressures above the
//! limit point, springs in compression, and the memory bound of a large mesh.

mod tests {
    use nalgebra::{Point3, Vector3};

    use bulge::experiment::Specimen;
    use bulge::material::Material;
    use bulge::material::Model;
    use bulge::sim::dynamics::{
        DampingLaw, DynError, DynOptions, Dynamics, Integrator, StepPolicy,
    };
    use bulge::sim::hard::*;
    use bulge::sim::mesh::Mesh;
    use bulge::sim::mesh::{self, Constraint, DiscOptions};
    use bulge::sim::scene::DiscPredictor;
    use bulge::sim::solve::{self, Options, Solver};
    use bulge::sim::springs::SpringModel;
    use bulge::sim::{SimError, springs::Membrane};

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
        let h = bulge::axisym::solve_pressure(mat, &spec, p, &bulge::axisym::Options::default())
            .expect("axisym reference")
            .height_m;
        Ok((x[0].z, h))
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

    /// Hard case: a pressure above the limit point of a neo-Hookean bubble.
    /// The static solve stops with the last equilibrium, the note gives the
    /// axisymmetric limit pressure (Adkins & Rivlin 1952: P = p a / (C1 t) = 3.7583).
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
        // below it the law has an equilibrium, a softer spring model may not
        let below = limit_note(&mat, a, t, 0.9 * pl).unwrap();
        assert!(
            below.contains("below it") && below.contains("its own limit point"),
            "{below}"
        );
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
