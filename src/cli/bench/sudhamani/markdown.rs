//! `sudhamani-merriliance.md`: Sudhamani & Merriliance's (2019) three experiments on the
//! sheet beside their published figures, and the disc's pressure step.

use std::fmt::Write as _;

use bulge::sim::dynamics::Integrator;

use super::SheetSetup;
use super::disc::pressure_step_table;
use super::tables::{load_table, step_table, time_table};

/// Sudhamani & Merriliance's (2019) three experiments and the disc pressure step, as Markdown.
pub fn markdown(quick: bool) -> anyhow::Result<String> {
    let setup = SheetSetup::default();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Sheet: {} m square, t = {} m, E = {} Pa, nu = {}, rho = {} kg/m^3, {} springs, damping {:?} of each spring's critical value; in-plane load along -y, force per unit thickness.\n",
        setup.side_m,
        setup.thickness_m,
        setup.young_pa,
        setup.poisson,
        setup.density_kg_m3,
        setup.model.name(),
        setup.damping
    );
    time_against_points(&setup, quick, &mut s)?;
    largest_stable_step(&setup, quick, &mut s)?;
    deformation_against_load(&setup, quick, &mut s)?;
    s.push_str(&pressure_step_table(quick)?);
    Ok(s)
}

/// Table 2.2.1: computation time against the number of points.
fn time_against_points(setup: &SheetSetup, quick: bool, s: &mut String) -> anyhow::Result<()> {
    let points: &[usize] = if quick {
        &[60, 120]
    } else {
        &[200, 500, 1000, 2000, 4000]
    };
    // Sudhamani & Merriliance (2019) Table 2.2.1 as published (3.14 s is a time, not pi).
    #[allow(clippy::approx_constant)]
    let paper_time = [
        (200, 0.5, 0.3),
        (500, 1.7, 1.2),
        (1000, 2.78, 2.0),
        (2000, 3.14, 2.67),
        (4000, 3.96, 3.12),
    ];
    let t_end = 1.0;
    let rows = time_table(
        setup,
        points,
        &[
            Integrator::ExplicitEuler,
            Integrator::Verlet,
            Integrator::ImplicitEuler,
        ],
        10.0,
        t_end,
    )?;
    let _ = writeln!(
        s,
        "#### Computation time against points (Sudhamani & Merriliance 2019, Table 2.2.1)\n\n{t_end} s simulated, 10 N/m at the middle, from rest; step 0.9 of Verlet's estimated limit for every integrator (explicit Euler sub-steps to 0.9 of its own). One core.\n\n| points (published) | published Euler s | published Verlet s | points | dt_s | explicit Euler s (sub-steps) | Verlet s | implicit Euler s | u(t_end) / u_static, Verlet |\n|---|---|---|---|---|---|---|---|---|"
    );
    let mut pts: Vec<usize> = rows.iter().map(|r| r.points).collect();
    pts.dedup();
    for (k, &np) in pts.iter().enumerate() {
        // Sudhamani & Merriliance's sizes only beside the full set (the quick one is smaller).
        let paper = if quick {
            None
        } else {
            paper_time.get(k).copied()
        };
        let get = |i: Integrator| rows.iter().find(|r| r.points == np && r.integrator == i);
        let (ee, vv) = (
            get(Integrator::ExplicitEuler).expect("explicit Euler row"),
            get(Integrator::Verlet).expect("Verlet row"),
        );
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.3e} | {:.3} ({}) | {:.3} | {} | {:.3} |",
            paper.map(|p| p.0.to_string()).unwrap_or_default(),
            paper.map(|p| p.1.to_string()).unwrap_or_default(),
            paper.map(|p| p.2.to_string()).unwrap_or_default(),
            np,
            vv.dt_s,
            ee.wall_s,
            ee.substeps,
            vv.wall_s,
            get(Integrator::ImplicitEuler)
                .map(|r| format!("{:.3}", r.wall_s))
                .unwrap_or_else(|| "-".into()),
            vv.displacement_m / vv.static_m
        );
    }
    Ok(())
}

/// Table 2.2.2: the largest stable step per integrator.
fn largest_stable_step(setup: &SheetSetup, quick: bool, s: &mut String) -> anyhow::Result<()> {
    let np = if quick { 120 } else { 1000 };
    let rows = step_table(
        setup,
        np,
        10.0,
        if quick { 600 } else { 1500 },
        &Integrator::ALL,
    )?;
    let paper_step = |i: Integrator| match i {
        Integrator::ExplicitEuler => "0.5",
        Integrator::ImplicitEuler => "49.0",
        Integrator::Verlet => "11.5",
        _ => "-",
    };
    let _ = writeln!(
        s,
        "\n#### Largest stable step (Sudhamani & Merriliance 2019, Table 2.2.2)\n\n{} points, at the static equilibrium under 10 N/m; stiffest mode {:.1} rad/s (power iteration; Gershgorin bound {:.1}), its damping ratio {:.3}. Measured: bisection to 1 %, a velocity along the stiffest mode integrated for the stated steps, stable when the kinetic energy has not grown.\n\n| integrator | published step ms | estimate ms | measured ms | measured / estimate |\n|---|---|---|---|---|",
        np, rows[0].omega[0], rows[0].omega[2], rows[0].omega[1]
    );
    for r in &rows {
        let est = if r.estimate_s.is_finite() {
            format!("{:.4}", r.estimate_s * 1e3)
        } else {
            "none (unconditionally stable)".into()
        };
        let meas = match r.measured_s {
            Some(m) => format!("{:.4}", m * 1e3),
            None => format!("stable up to {:.1}", r.tried_s * 1e3),
        };
        let ratio = match r.measured_s {
            Some(m) if r.estimate_s.is_finite() => format!("{:.3}", m / r.estimate_s),
            _ => "-".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            r.integrator.name(),
            paper_step(r.integrator),
            est,
            meas,
            ratio
        );
    }
    Ok(())
}

/// Table 2.2.3: deformation against load, at the middle and at the corner.
fn deformation_against_load(setup: &SheetSetup, quick: bool, s: &mut String) -> anyhow::Result<()> {
    let loads = [0.0, 2.0, 4.0, 6.0, 8.0, 10.0];
    let paper_def = [
        (0.0, 0.0),
        (1.583356, 1.298453),
        (3.248017, 1.972952),
        (4.183456, 2.7839),
        (9.492629, 6.93582),
        (12.423452, 8.1674),
    ];
    let np = if quick { 120 } else { 1000 };
    let t3 = 2.0;
    let _ = writeln!(
        s,
        "\n#### Deformation against load (Sudhamani & Merriliance 2019, Table 2.2.3)\n\n{np} points; displacement of the loaded node; \"error\" = |u(t = {t3} s) - u_static| after {t3} s from rest at 0.9 of Verlet's step limit.\n"
    );
    for at in ["middle", "corner"] {
        let rows = load_table(
            setup,
            np,
            at,
            &loads,
            &[
                Integrator::ExplicitEuler,
                Integrator::Verlet,
                Integrator::ImplicitEuler,
            ],
            t3,
        )?;
        let _ = writeln!(
            s,
            "Load at the {at}:\n\n| N/m | published Euler mm | published Verlet mm | static u mm | explicit Euler error mm | Verlet error mm | implicit Euler error mm |\n|---|---|---|---|---|---|---|"
        );
        for (r, p) in rows.iter().zip(paper_def) {
            let err = |k: usize| (r.dynamic_m[k].1 - r.static_m).abs() * 1e3;
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
                r.q_n_m,
                p.0,
                p.1,
                r.static_m * 1e3,
                err(0),
                err(1),
                err(2)
            );
        }
        let _ = writeln!(s);
    }
    Ok(())
}
