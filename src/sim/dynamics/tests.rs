//! Unit tests of the integrators, the damping and the step limit against
//! closed forms.
//!
//! The test system is one linear spring-mass oscillator: an equilateral
//! triangle of side `L` with Lloyd springs (`k = E t |T0| / l0^2 =
//! E t sqrt(3)/4` on every side), nodes 0 and 1 clamped and node 2 sliding
//! on the line of the edge 0-2. Along that line the spring 0-2 acts fully
//! and the spring 1-2 (at 60 degrees) with `cos^2 60 = 1/4`, so the one
//! degree of freedom has the stiffness `k_eff = 5 k / 4`, the lumped mass
//! `m = rho t |T0| / 3` and `w^2 = k_eff / m = 15 E / (4 rho L^2)`. The
//! amplitudes are 1e-5 of `L`: the geometric nonlinearity of the slanted
//! spring changes the results by about that share, below every tolerance.
//!
//! For `e'' = -w^2 e` and a step `h` the integrators are linear maps whose
//! properties are known exactly: explicit Euler multiplies
//! `v^2 + w^2 e^2` by `1 + (w h)^2` per step, implicit Euler divides it by
//! the same factor; position Verlet (Verlet 1967; drift-kick-drift) and
//! symplectic Euler turn by `2 asin(w h / 2)` per step (the period short by
//! about `(w h)^2 / 24`), Verlet keeping `v^2 (1 - (w h)^2 / 4) + w^2 e^2`.

use nalgebra::{Point3, Vector3};

use super::*;
use crate::material::{Material, Model};
use crate::sim::mesh::Constraint;
use crate::sim::solve;
use crate::sim::springs::SpringModel;

mod disc;

const L: f64 = 0.01;
const E: f64 = 1.0e6;
const T: f64 = 1.0e-3;
const RHO: f64 = 1000.0;
/// Static displacement of the loaded oscillator, m.
const S_STAR: f64 = 1e-5 * L;

fn sqrt3() -> f64 {
    3f64.sqrt()
}

/// Unit direction of the sliding node's line (along the edge 0-2).
fn dir() -> Vector3<f64> {
    Vector3::new(0.5, 0.5 * sqrt3(), 0.0)
}

fn triangle() -> Mesh {
    let nodes = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(L, 0.0, 0.0),
        Point3::new(0.5 * L, 0.5 * sqrt3() * L, 0.0),
    ];
    Mesh::new(
        nodes,
        vec![[0, 1, 2]],
        vec![
            Constraint::Fixed,
            Constraint::Fixed,
            Constraint::Line(dir()),
        ],
    )
    .unwrap()
}

fn material() -> Material {
    Material {
        model: Model::Linear { young_pa: E },
        poisson: 0.3,
        fit: None,
    }
}

/// A spring's stiffness, N/m (Lloyd on the equilateral triangle).
fn k_spring() -> f64 {
    E * T * sqrt3() / 4.0
}

/// The stiffness of the sliding degree of freedom, N/m.
fn k_eff() -> f64 {
    1.25 * k_spring()
}

/// Lumped mass of a node, kg.
fn mass() -> f64 {
    RHO * T * (sqrt3() / 4.0 * L * L) / 3.0
}

/// Angular frequency of the oscillator, rad/s.
fn omega() -> f64 {
    (15.0 * E / (4.0 * RHO * L * L)).sqrt()
}

/// The damping ratio of the oscillator for a spring damping fraction `z`:
/// every dashpot is `z 2 sqrt(k m / 2)` (equal masses), acting with
/// `1 + 1/4` along the line, so `zeta = z sqrt(5/8)`.
fn zeta_of(z: f64) -> f64 {
    z * (5.0f64 / 8.0).sqrt()
}

/// The oscillator's membrane, loaded along its line with `k_eff S_STAR`
/// when `loaded`.
fn membrane(mesh: &Mesh, loaded: bool) -> Membrane {
    let mut m = Membrane::new(mesh, SpringModel::Lloyd, &material(), T, RHO).unwrap();
    if loaded {
        m.node_loads = vec![(2, dir() * (k_eff() * S_STAR))];
    }
    m
}

/// Displacement of the sliding node along its line.
fn slide(x: &[Point3<f64>]) -> f64 {
    (x[2] - triangle().nodes[2]).dot(&dir())
}

/// Runs the loaded oscillator from rest at its unloaded position for
/// `steps` steps of `h`, every step sampled.
fn run_oscillator(integrator: Integrator, z: f64, h: f64, steps: usize) -> DynRun {
    run_with(integrator, z, h, steps, |o| o)
}

fn run_with(
    integrator: Integrator,
    z: f64,
    h: f64,
    steps: usize,
    tweak: impl Fn(DynOptions) -> DynOptions,
) -> DynRun {
    let mesh = triangle();
    let mut m = membrane(&mesh, true);
    let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(z)).unwrap();
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); 3];
    let opts = tweak(DynOptions {
        integrator,
        dt_s: h,
        t_end_s: h * steps as f64,
        damping: DampingLaw::Critical(z),
        policy: StepPolicy::Unchecked,
        max_samples: steps + 1,
        ..DynOptions::default()
    });
    let x_of = |x: &[Point3<f64>]| (x[2] - mesh.nodes[2]).dot(&dir());
    d.run(&mut x, &mut v, &opts, &x_of).unwrap()
}

/// `v^2 + w^2 e^2` (twice the energy per unit mass about the static
/// solution `S_STAR`) of every sample.
fn energies(run: &DynRun) -> Vec<f64> {
    let w2 = omega() * omega();
    run.samples
        .iter()
        .map(|s| 2.0 * s.kinetic_j / mass() + w2 * (s.value_m - S_STAR).powi(2))
        .collect()
}

/// Times at which `value - S_STAR` crosses zero upwards, linearly
/// interpolated between samples.
fn upward_crossings(run: &DynRun) -> Vec<f64> {
    run.samples
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (w[0].value_m - S_STAR, w[1].value_m - S_STAR);
            (a < 0.0 && b >= 0.0).then(|| w[0].t_s + (w[1].t_s - w[0].t_s) * (-a) / (b - a))
        })
        .collect()
}

fn mean_period(run: &DynRun) -> f64 {
    let c = upward_crossings(run);
    assert!(c.len() >= 5, "{} crossings", c.len());
    (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// The fixture itself: its stiffness (from the forces, by a central
/// difference) is `k_eff`, so the closed forms below describe it.
#[test]
fn oscillator_stiffness_is_five_quarters_of_a_spring() {
    let mesh = triangle();
    let m = membrane(&mesh, false);
    let ds = 1e-9;
    let mut f = vec![Vector3::zeros(); 3];
    let mut x = mesh.nodes.clone();
    x[2] += dir() * ds;
    m.forces(&x, &mut f).unwrap();
    let fp = f[2].dot(&dir());
    x[2] -= dir() * (2.0 * ds);
    m.forces(&x, &mut f).unwrap();
    let fm = f[2].dot(&dir());
    let k = -(fp - fm) / (2.0 * ds);
    assert!(rel(k, k_eff()) < 1e-6, "{k} vs {}", k_eff());
    assert!(rel(m.masses[2], mass()) < 1e-12);
}

/// Explicit Euler multiplies `v^2 + w^2 e^2` by exactly `1 + (w h)^2` per
/// step.
#[test]
fn explicit_euler_energy_grows_by_one_plus_wh_squared() {
    let wh = 0.05;
    let run = run_oscillator(Integrator::ExplicitEuler, 0.0, wh / omega(), 40);
    let e = energies(&run);
    let g = 1.0 + wh * wh;
    for (n, w) in e.windows(2).enumerate() {
        assert!(
            rel(w[1] / w[0], g) < 1e-4,
            "step {n}: {} vs {g}",
            w[1] / w[0]
        );
    }
    assert!(rel(e[40] / e[0], g.powi(40)) < 1e-3);
    assert_eq!(run.force_evaluations, 40);
}

/// Implicit Euler divides `v^2 + w^2 e^2` by exactly `1 + (w h)^2` per step.
#[test]
fn implicit_euler_energy_decays_by_one_plus_wh_squared() {
    let wh = 0.3;
    let run = run_oscillator(Integrator::ImplicitEuler, 0.0, wh / omega(), 20);
    let e = energies(&run);
    let g = 1.0 / (1.0 + wh * wh);
    for (n, w) in e.windows(2).enumerate() {
        assert!(
            rel(w[1] / w[0], g) < 1e-4,
            "step {n}: {} vs {g}",
            w[1] / w[0]
        );
    }
    assert!(run.newton_iterations >= 20);
}

/// XPBD with converged constraint iterations is implicit Euler for springs
/// (Macklin, Mueller & Chentanez 2016): the same decay per step.
#[test]
fn xpbd_converged_decays_like_implicit_euler() {
    let wh = 0.3;
    let run = run_with(Integrator::Xpbd, 0.0, wh / omega(), 20, |o| DynOptions {
        xpbd_iterations: 200,
        ..o
    });
    let e = energies(&run);
    let g = 1.0 / (1.0 + wh * wh);
    for (n, w) in e.windows(2).enumerate() {
        assert!(
            rel(w[1] / w[0], g) < 1e-3,
            "step {n}: {} vs {g}",
            w[1] / w[0]
        );
    }
}

/// Verlet: the period is `2 pi h / (2 asin(w h / 2))`, short of `2 pi / w`
/// by about `(w h)^2 / 24`; the amplitude about the static solution stays
/// `S_STAR` (its invariant `v^2 (1 - (w h)^2/4) + w^2 e^2`).
#[test]
fn verlet_period_and_amplitude_match_the_harmonic_oscillator() {
    let w = omega();
    let wh = 0.2;
    let h = wh / w;
    let run = run_oscillator(Integrator::Verlet, 0.0, h, 400);
    let period = mean_period(&run);
    let exact = 2.0 * std::f64::consts::PI / w;
    let discrete = 2.0 * std::f64::consts::PI * h / (2.0 * (wh / 2.0).asin());
    assert!(rel(period, discrete) < 2e-5, "{period} vs {discrete}");
    // the period error is (w h)^2 / 24 of the period, to 10 %
    let err = 1.0 - period / exact;
    assert!(
        (err / (wh * wh / 24.0) - 1.0).abs() < 0.1,
        "period error {err} vs {}",
        wh * wh / 24.0
    );
    let amp = run
        .samples
        .iter()
        .map(|s| (s.value_m - S_STAR).abs())
        .fold(0.0, f64::max);
    assert!(
        amp <= S_STAR * (1.0 + 1e-4) && amp >= S_STAR * (1.0 - wh * wh / 8.0),
        "amplitude {amp} vs {S_STAR}"
    );
    // the invariant
    let e = run.samples.iter().map(|s| {
        2.0 * s.kinetic_j / mass() * (1.0 - wh * wh / 4.0) + w * w * (s.value_m - S_STAR).powi(2)
    });
    let e0 = (w * S_STAR).powi(2);
    for (n, q) in e.enumerate() {
        assert!(rel(q, e0) < 1e-4, "sample {n}: {q} vs {e0}");
    }
}

/// Symplectic Euler shares Verlet's characteristic polynomial: the same
/// discrete period; its amplitude stays within `1 / sqrt(1 - (w h)^2 / 4)`.
#[test]
fn symplectic_euler_period_matches_the_discrete_frequency() {
    let w = omega();
    let wh = 0.2;
    let h = wh / w;
    let run = run_oscillator(Integrator::SymplecticEuler, 0.0, h, 400);
    let period = mean_period(&run);
    let discrete = 2.0 * std::f64::consts::PI * h / (2.0 * (wh / 2.0).asin());
    assert!(rel(period, discrete) < 2e-5, "{period} vs {discrete}");
    let amp = run
        .samples
        .iter()
        .map(|s| (s.value_m - S_STAR).abs())
        .fold(0.0, f64::max);
    let bound = S_STAR / (1.0 - wh * wh / 4.0).sqrt();
    assert!(
        amp <= bound * (1.0 + 1e-4) && amp >= S_STAR * (1.0 - 1e-4),
        "amplitude {amp}"
    );
}

/// Damped Verlet settles onto the static solution: `k_eff s = F` (to the
/// nonlinearity, 1e-4) and the Newton solution of the same membrane (to the
/// settle tolerance); successive maxima shrink by the logarithmic decrement
/// `exp(-2 pi zeta / sqrt(1 - zeta^2))` (to the first-order damping error
/// of the scheme, `zeta w h`).
#[test]
fn damped_verlet_settles_on_the_static_solution() {
    let zeta = 0.2;
    let z = zeta / (5.0f64 / 8.0).sqrt();
    let h = 0.02 / omega();
    let run = run_with(Integrator::Verlet, z, h, 20_000, |o| DynOptions {
        settle_tolerance: Some(1e-6),
        ..o
    });
    assert!(run.steps < 20_000, "did not settle");
    let mesh = triangle();
    let mut m = membrane(&mesh, true);
    let mut xs = mesh.nodes.clone();
    solve::newton(&mut m, &mut xs, 0.0, &solve::Options::default()).unwrap();
    let s_newton = slide(&xs);
    assert!(rel(s_newton, S_STAR) < 1e-4, "{s_newton} vs {S_STAR}");
    assert!(
        rel(run.last(), s_newton) < 1e-5,
        "{} vs {s_newton}",
        run.last()
    );
    assert!(run.residual < 1e-6);
    // logarithmic decrement from the first two maxima
    let v: Vec<f64> = run.samples.iter().map(|s| s.value_m - S_STAR).collect();
    let peaks: Vec<f64> = (1..v.len() - 1)
        .filter(|&i| v[i] > v[i - 1] && v[i] >= v[i + 1] && v[i] > 0.0)
        .map(|i| v[i])
        .take(2)
        .collect();
    let want = (-2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    assert!(rel(peaks[1] / peaks[0], want) < 0.03, "{peaks:?} vs {want}");
}

/// The power iteration finds the oscillator's frequency and damping ratio,
/// and the limits follow the closed forms of the module docs.
#[test]
fn step_estimate_matches_the_closed_form_frequency() {
    let mesh = triangle();
    let w = omega();
    for z in [0.0, 0.1, 0.5] {
        let mut m = membrane(&mesh, false);
        let d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(z)).unwrap();
        let est = d.estimate_step(&mesh.nodes).unwrap();
        let zeta = zeta_of(z);
        assert!(rel(est.omega_max, w) < 1e-6, "{} vs {w}", est.omega_max);
        assert!((est.zeta - zeta).abs() < 1e-6, "{} vs {zeta}", est.zeta);
        assert!((est.damping_rate - 2.0 * zeta * w).abs() < 1e-6 * w);
        assert!(est.omega_gershgorin >= est.omega_max * (1.0 - 1e-9));
        let symplectic = 2.0 / w * ((1.0 + zeta * zeta).sqrt() - zeta);
        // the split Verlet: min(2 / w, 4 / c), c = 2 zeta w
        let verlet = if zeta > 0.0 {
            (2.0 / w).min(4.0 / (2.0 * zeta * w))
        } else {
            2.0 / w
        };
        assert!(rel(est.limit(Integrator::Verlet), verlet) < 1e-6);
        assert!(rel(est.limit(Integrator::SymplecticEuler), symplectic) < 1e-6);
        assert!((est.limit(Integrator::ExplicitEuler) - 2.0 * zeta / w).abs() < 1e-6 / w);
        assert_eq!(est.limit(Integrator::ImplicitEuler), f64::INFINITY);
        assert_eq!(est.limit(Integrator::Xpbd), f64::INFINITY);
    }
}

/// The measured limit (bisection on integrated runs) agrees with the
/// closed forms: `2 / w` for undamped Verlet, `2 zeta / w` for damped
/// explicit Euler.
#[test]
fn measured_step_limit_matches_the_closed_form() {
    let mesh = triangle();
    let w = omega();
    let mut m = membrane(&mesh, false);
    let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(0.0)).unwrap();
    let lim = 2.0 / w;
    let got = measure_step_limit(
        &mut d,
        &mesh.nodes,
        Integrator::Verlet,
        0.5 * lim,
        2.0 * lim,
        200,
        1e-4,
    )
    .unwrap()
    .unwrap();
    assert!(rel(got, lim) < 1e-3, "{got} vs {lim}");
    let zeta = 0.2;
    let mut m = membrane(&mesh, false);
    let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(zeta / zeta_of(1.0))).unwrap();
    let lim = 2.0 * zeta / w;
    let got = measure_step_limit(
        &mut d,
        &mesh.nodes,
        Integrator::ExplicitEuler,
        0.5 * lim,
        2.0 * lim,
        200,
        1e-4,
    )
    .unwrap()
    .unwrap();
    assert!(rel(got, lim) < 0.02, "{got} vs {lim}");
}

/// Above the limit: refuse with the limit, or sub-step below
/// `STEP_SAFETY` of it; explicit Euler without damping has no stable step.
#[test]
fn step_policy_refuses_or_substeps_at_the_closed_form_limit() {
    let lim = 2.0 / omega();
    let dt = 2.9 * lim;
    let mesh = triangle();
    let run = |policy: StepPolicy, integrator: Integrator| {
        let mut m = membrane(&mesh, true);
        let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(0.0)).unwrap();
        let mut x = mesh.nodes.clone();
        let mut v = vec![Vector3::zeros(); 3];
        let opts = DynOptions {
            integrator,
            dt_s: dt,
            t_end_s: 4.0 * dt,
            policy,
            ..DynOptions::default()
        };
        d.run(&mut x, &mut v, &opts, &slide)
    };
    match run(StepPolicy::Refuse, Integrator::Verlet) {
        Err(DynError::StepTooLarge {
            dt_crit_s,
            suggest_s,
            ..
        }) => {
            assert!(rel(dt_crit_s, lim) < 1e-6);
            // undamped: the undamped share of the limit
            assert!(rel(suggest_s, STEP_SAFETY_UNDAMPED * lim) < 1e-6);
        }
        other => panic!("{other:?}"),
    }
    let r = run(StepPolicy::Substep, Integrator::Verlet).unwrap();
    assert_eq!(r.substeps, (2.9 / STEP_SAFETY_UNDAMPED).ceil() as usize);
    assert!(r.h_s <= STEP_SAFETY_UNDAMPED * lim && rel(r.h_s * r.substeps as f64, dt) < 1e-12);
    assert!(matches!(
        run(StepPolicy::Substep, Integrator::ExplicitEuler),
        Err(DynError::NoStableStep)
    ));
}

/// The watch stops an explicit run that blows up, before any NaN.
#[test]
fn watch_stops_a_diverging_run() {
    let mesh = triangle();
    let mut m = membrane(&mesh, true);
    let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(0.0)).unwrap();
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); 3];
    let h = 1.0 / omega();
    let opts = DynOptions {
        integrator: Integrator::ExplicitEuler,
        dt_s: h,
        t_end_s: 200.0 * h,
        policy: StepPolicy::Unchecked,
        ..DynOptions::default()
    };
    match d.run(&mut x, &mut v, &opts, &slide) {
        Err(DynError::Diverged { step, .. }) => assert!(step < 200),
        other => panic!("{other:?}"),
    }
    assert!(x.iter().all(|p| p.iter().all(|c| c.is_finite())));
}

/// XPBD refuses a spring model without a fixed stiffness per spring.
#[test]
fn xpbd_refuses_tp_springs() {
    let mesh = triangle();
    let mut m = Membrane::new(&mesh, SpringModel::Tp, &material(), T, RHO).unwrap();
    let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::default()).unwrap();
    let mut x = mesh.nodes.clone();
    let mut v = vec![Vector3::zeros(); 3];
    let opts = DynOptions {
        integrator: Integrator::Xpbd,
        ..DynOptions::default()
    };
    assert!(matches!(
        d.run(&mut x, &mut v, &opts, &slide),
        Err(DynError::BadParameter(_))
    ));
}

/// The small-strain spring stiffness on an equilateral triangle of side
/// `L` (area `sqrt(3)/4 L^2`), from the papers' formulas: Lloyd
/// `E t sqrt(3)/4`; Van Gelder `E t (sqrt(3) / (4 (1 + nu)) + nu / (2
/// sqrt(3) (1 - nu^2)))`; TP eq 16 `E t / (2 sqrt(3) (1 - nu))`.
#[test]
fn reference_edge_stiffness_on_an_equilateral_triangle() {
    let mesh = triangle();
    let nu: f64 = 0.3;
    let s3 = sqrt3();
    let cases = [
        (SpringModel::Lloyd, E * T * s3 / 4.0),
        (
            SpringModel::VanGelder,
            E * T * (s3 / (4.0 * (1.0 + nu)) + nu / (2.0 * s3 * (1.0 - nu * nu))),
        ),
        (SpringModel::Tp, E * T / (2.0 * s3 * (1.0 - nu))),
        (SpringModel::TpPaper, E * T / (2.0 * s3 * (1.0 - nu))),
    ];
    for (model, want) in cases {
        let k = reference_edge_stiffness(&mesh, model, E, nu, T);
        assert_eq!(k.len(), 3);
        for ki in k {
            assert!(rel(ki, want) < 1e-12, "{model:?}: {ki} vs {want}");
        }
    }
}

/// Dashpots: a fraction of `2 sqrt(k m_red)`, or `sqrt(k (m_i + m_j)) / l0`
/// for the law of Sudhamani & Merriliance (2019); negative stiffness clamped.
#[test]
fn edge_damping_follows_its_laws() {
    let mesh = triangle();
    let (m1, m2) = (2.0, 3.0);
    let masses = [m1, m1, m2];
    let k = [4.0, 5.0, -1.0];
    // edges sorted: (0,1), (0,2), (1,2)
    assert_eq!(mesh.edges, vec![[0, 1], [0, 2], [1, 2]]);
    let c = edge_damping(&mesh, &k, &masses, DampingLaw::Critical(0.5));
    assert!(rel(c[0], 0.5 * 2.0 * (4.0 * m1 / 2.0).sqrt()) < 1e-14);
    assert!(rel(c[1], 0.5 * 2.0 * (5.0 * m1 * m2 / (m1 + m2)).sqrt()) < 1e-14);
    assert_eq!(c[2], 0.0);
    let c = edge_damping(&mesh, &k, &masses, DampingLaw::SudhamaniMerriliance);
    assert!(rel(c[1], (5.0 * (m1 + m2)).sqrt() / L) < 1e-12);
    assert_eq!(DampingLaw::default(), DampingLaw::Critical(DEFAULT_DAMPING));
}

/// A dashpot force is `c ((v_j - v_i) . u) u` on `i` and its opposite on `j`.
#[test]
fn dashpot_force_is_along_the_edge() {
    let mesh = triangle();
    let mut m = membrane(&mesh, false);
    let d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(1.0)).unwrap();
    let c = d.damping[1]; // edge 0-2
    let v = [
        Vector3::zeros(),
        Vector3::zeros(),
        Vector3::new(0.0, 0.0, 1.0) + dir(),
    ];
    let mut f = vec![Vector3::zeros(); 3];
    d.add_damping(&mesh.nodes, &v, &mut f);
    // edge 0-2: relative speed along it 1; edge 1-2: (dir + z) . u12 = 1/2
    let u12 = Vector3::new(-0.5, 0.5 * sqrt3(), 0.0);
    let want2 = -dir() * c - u12 * (0.5 * c);
    assert!((f[2] - want2).norm() < 1e-12 * c);
    assert!((f[0] + f[1] + f[2]).norm() < 1e-12 * c);
}

/// Names round-trip; only the three explicit integrators have a limit.
#[test]
fn integrator_names_round_trip() {
    for i in Integrator::ALL {
        assert_eq!(Integrator::parse(i.name()), Some(i));
    }
    assert_eq!(Integrator::parse(" verlet "), Some(Integrator::Verlet));
    assert_eq!(Integrator::parse("rk4"), None);
    let explicit: Vec<_> = Integrator::ALL
        .into_iter()
        .filter(|i| i.is_explicit())
        .collect();
    assert_eq!(
        explicit,
        [
            Integrator::ExplicitEuler,
            Integrator::SymplecticEuler,
            Integrator::Verlet
        ]
    );
}

/// Peak, last value and settling time of a history.
#[test]
fn run_summaries() {
    let samples = [0.0, 2.0, 0.5, 1.05, 0.98, 1.0]
        .iter()
        .enumerate()
        .map(|(i, &v)| Sample {
            t_s: i as f64,
            value_m: v,
            kinetic_j: 0.0,
        })
        .collect();
    let run = DynRun {
        samples,
        steps: 5,
        substeps: 1,
        h_s: 1.0,
        estimate: None,
        rechecks: 0,
        force_evaluations: 5,
        newton_iterations: 0,
        residual: 0.0,
    };
    assert_eq!(run.peak(), 2.0);
    assert_eq!(run.last(), 1.0);
    assert_eq!(run.settling_time(1.0, 0.1), 2.0);
    assert_eq!(run.settling_time(1.0, 0.03), 3.0);
    assert_eq!(run.settling_time(1.0, 5.0), 0.0);
}

/// `--step-policy refuse` refuses exactly the steps above the limit it
/// prints: 0.95 of it runs (in one step per step), 1.05 is refused with that
/// limit and a smaller suggestion.
#[test]
fn refuse_policy_agrees_with_the_limit_it_prints() {
    let lim = 2.0 / omega();
    let mesh = triangle();
    let run = |dt: f64| {
        let mut m = membrane(&mesh, true);
        let mut d = Dynamics::new(&mut m, &mesh, DampingLaw::Critical(0.0)).unwrap();
        let mut x = mesh.nodes.clone();
        let mut v = vec![Vector3::zeros(); 3];
        let opts = DynOptions {
            integrator: Integrator::Verlet,
            dt_s: dt,
            t_end_s: 40.0 * dt,
            policy: StepPolicy::Refuse,
            ..DynOptions::default()
        };
        d.run(&mut x, &mut v, &opts, &slide)
    };
    let r = run(0.95 * lim).unwrap();
    assert_eq!(r.substeps, 1);
    match run(1.05 * lim) {
        Err(e @ DynError::StepTooLarge { .. }) => {
            let DynError::StepTooLarge {
                dt_s,
                dt_crit_s,
                suggest_s,
                ..
            } = e
            else {
                unreachable!()
            };
            assert!(dt_s > dt_crit_s && suggest_s < dt_crit_s, "{e}");
            assert!(rel(dt_crit_s, lim) < 1e-6);
        }
        other => panic!("{other:?}"),
    }
}

/// Verlet with its dashpots split off symmetrically is second order with
/// damping: a step load from rest on the one-degree-of-freedom oscillator
/// against its closed form `x = S (1 - e^(-zeta w t) (cos w_d t + zeta /
/// sqrt(1 - zeta^2) sin w_d t))`, `w_d = w sqrt(1 - zeta^2)`, the largest
/// error over two periods, at damping 0.1 (the default) and 1 (a damping
/// ratio of 0.79).
#[test]
fn damped_verlet_is_second_order() {
    let w = omega();
    for z in [0.1, 1.0] {
        let zeta = zeta_of(z);
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let exact = |t: f64| {
            S_STAR
                * (1.0
                    - (-zeta * w * t).exp()
                        * ((wd * t).cos() + zeta / (1.0 - zeta * zeta).sqrt() * (wd * t).sin()))
        };
        let period = 2.0 * std::f64::consts::PI / w;
        let err = |k: usize| {
            let steps = 20 * k * 2;
            let h = period / (20 * k) as f64;
            let run = run_oscillator(Integrator::Verlet, z, h, steps);
            run.samples
                .iter()
                .map(|s| (s.value_m - exact(s.t_s)).abs())
                .fold(0.0, f64::max)
        };
        let (e1, e2, e4) = (err(1), err(2), err(4));
        let order = [(e1 / e2).log2(), (e2 / e4).log2()];
        assert!(
            order.iter().all(|&p| p >= 1.9),
            "damping {z}: errors {e1:.3e} {e2:.3e} {e4:.3e}, orders {order:?}"
        );
    }
}
