//! The closed-loop study of `bulge run` (docs/run.md): synthetic experiments
//! with known truth, drawn by the photo synthesiser from the exact
//! axisymmetric inflation of four materials that the demo does not use, with
//! sensor noise and blur, are run through track -> stress -> fit -> simulate
//! under every combination of the stress stage's conventions; the simulated
//! heights are compared with the true heights at every pressure below the
//! limit point.
//!
//! Each setting is run with and without the correction of the fitted law to
//! the measured heights (`Settings::refine`, the default).
//!
//! Run: `cargo run --release --example closed_loop` (a few minutes).
//! Prints Markdown tables.

use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::mechanics::{Modulus, ModulusStress, Options, StrainMeasure, TrueStress};
#[path = "../tests/support/closed_loop.rs"]
mod closed_loop;

use bulge::fit::FitModel;
use bulge::pipeline::{Settings, describe_stress};
use bulge::sim::springs::SpringModel;
use closed_loop::{Case, Drawn, HeightModel, TP, VAN_GELDER};

fn cases() -> Vec<Case> {
    let specimen = Specimen {
        radius_m: 0.0375,
        thickness_m: 0.00035,
        poisson: 0.45,
        prebulge_height_m: 0.0,
    };
    let m = |model: Model| Material {
        model,
        poisson: 0.45,
        fit: None,
    };
    let case = |name: &str, model: Model, seed: u64| Case {
        name: name.into(),
        material: m(model),
        specimen,
        frames: 12,
        top_fraction: 0.9,
        p_max_pa: 6000.0,
        size: [640, 480],
        noise: (2.0, 1.0, None),
        seed,
    };
    vec![
        case(
            "mooney-rivlin C1 0.12 MPa, C2 0.03 MPa",
            Model::MooneyRivlin {
                c1_pa: 0.12e6,
                c2_pa: 0.03e6,
            },
            11,
        ),
        case(
            "yeoh C1 0.25, C2 -0.02, C3 0.004 MPa",
            Model::Yeoh {
                c1_pa: 0.25e6,
                c2_pa: -0.02e6,
                c3_pa: 0.004e6,
            },
            12,
        ),
        case(
            "gent mu 0.35 MPa, Jm 20",
            Model::Gent {
                mu_pa: 0.35e6,
                jm: 20.0,
            },
            13,
        ),
        case(
            "ogden-3 (Treloar 1972)",
            Model::Ogden {
                mu_pa: vec![0.63e6, 0.0012e6, -0.01e6],
                alpha: vec![1.3, 5.0, -2.0],
            },
            14,
        ),
    ]
}

fn conventions() -> Vec<Options> {
    let mut v = Vec::new();
    for strain in [StrainMeasure::Engineering, StrainMeasure::Log] {
        for modulus in [Modulus::Biaxial, Modulus::Uniaxial] {
            for (modulus_stress, true_stress) in [
                (ModulusStress::Nominal, TrueStress::Paper),
                (ModulusStress::Stress, TrueStress::Paper),
                (ModulusStress::True, TrueStress::Incompressible),
            ] {
                v.push(Options {
                    strain,
                    true_stress,
                    modulus,
                    modulus_stress,
                });
            }
        }
    }
    v
}

fn main() {
    let base = Settings {
        models: vec![SpringModel::Tp, SpringModel::VanGelder],
        axisym: true,
        ..Settings::default()
    };
    let tmp = tempfile::tempdir().expect("temporary folder");
    let mut drawn: Vec<Drawn> = Vec::new();
    println!("## Cases\n");
    println!("| material | limit point (Pa) | pressures (Pa) | tracking error rms (%) | max (%) |");
    println!("|---|---:|---|---:|---:|");
    for (i, c) in cases().iter().enumerate() {
        let dir = tmp.path().join(format!("case{i}"));
        let d = closed_loop::draw(c, &dir, &base).expect("draw and track");
        drawn.push(d);
    }
    for d in &drawn {
        let o = closed_loop::evaluate(d, &base).expect("evaluate");
        let te = &o.tracking_errors;
        let rms = (te.iter().map(|x| x * x).sum::<f64>() / te.len() as f64).sqrt();
        let max = te.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let p: Vec<f64> = d.tracking.points().iter().map(|p| p.pressure_pa).collect();
        println!(
            "| {} | {} | {:.0} .. {:.0} ({} frames) | {:.3} | {:.3} |",
            d.case.name,
            d.limit_pa
                .map_or("none up to pole stretch 4".into(), |l| format!("{l:.1}")),
            p[0],
            p[p.len() - 1],
            p.len(),
            rms * 100.0,
            max * 100.0
        );
    }

    println!("\n## Conventions (fit: quartic E(eps), mesh: 16 rings of the sector)\n");
    println!(
        "Largest |simulated / true - 1| over all pressures below the limit point, per material, in %.\n"
    );
    print!("| law corrected to the heights | stress stage conventions |");
    for d in &drawn {
        print!(" TP: {} |", d.case.name.split(' ').next().unwrap_or(""));
    }
    println!(" TP worst | TP rms | Van Gelder worst | axisym worst |");
    print!("|---|---|");
    for _ in &drawn {
        print!("---:|");
    }
    println!("---:|---:|---:|---:|");
    let mut best: Option<(f64, Options)> = None;
    for (refine, o) in [false, true]
        .into_iter()
        .flat_map(|r| conventions().into_iter().map(move |o| (r, o)))
    {
        let s = Settings {
            stress: o,
            refine,
            ..base.clone()
        };
        let mut worst = [0.0f64; 3];
        let mut sq = (0.0, 0usize);
        let mut cells = Vec::new();
        for d in &drawn {
            match closed_loop::evaluate(d, &s) {
                Ok(out) => {
                    let tp = out.max_abs(TP);
                    cells.push(format!("{:.2}", tp * 100.0));
                    worst[0] = worst[0].max(tp);
                    worst[1] = worst[1].max(out.max_abs(VAN_GELDER));
                    worst[2] = worst[2].max(out.max_abs(HeightModel::Axisym));
                    let r = out.rms(TP);
                    let n = out.errors[0].1.len();
                    sq = (sq.0 + r * r * n as f64, sq.1 + n);
                }
                Err(e) => {
                    cells.push(format!("failed: {e}"));
                    worst = [f64::INFINITY; 3];
                }
            }
        }
        let rms = (sq.0 / sq.1.max(1) as f64).sqrt();
        println!(
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
            if refine { "yes" } else { "no" },
            describe_stress(&o),
            cells.join(" | "),
            worst[0] * 100.0,
            rms * 100.0,
            worst[1] * 100.0,
            worst[2] * 100.0
        );
        if refine && best.is_none_or(|(b, _)| worst[0] < b) {
            best = Some((worst[0], o));
        }
    }
    if let Some((w, o)) = best {
        println!(
            "\nSmallest worst TP error with the correction (the default): {:.2} % with {}.",
            w * 100.0,
            describe_stress(&o)
        );
    }

    println!("\n## Fit model (default conventions)\n");
    println!(
        "| fit | law corrected to the heights | TP worst (%) | TP rms (%) | Van Gelder worst (%) | axisym worst (%) |"
    );
    println!("|---|---|---:|---:|---:|---:|");
    for (fit, refine) in ["quartic", "mooney-rivlin", "ogden-3", "neo-hookean"]
        .into_iter()
        .flat_map(|f| [(f, false), (f, true)])
    {
        let s = Settings {
            fit: fit.parse::<FitModel>().expect("fit name"),
            refine,
            ..base.clone()
        };
        let mut w = [0.0f64; 3];
        let mut sq = (0.0, 0usize);
        for d in &drawn {
            match closed_loop::evaluate(d, &s) {
                Ok(out) => {
                    w[0] = w[0].max(out.max_abs(TP));
                    w[1] = w[1].max(out.max_abs(VAN_GELDER));
                    w[2] = w[2].max(out.max_abs(HeightModel::Axisym));
                    let r = out.rms(TP);
                    let n = out.errors[0].1.len();
                    sq = (sq.0 + r * r * n as f64, sq.1 + n);
                }
                Err(_) => w = [f64::INFINITY; 3],
            }
        }
        println!(
            "| {fit} | {} | {:.2} | {:.2} | {:.2} | {:.2} |",
            if refine { "yes" } else { "no" },
            w[0] * 100.0,
            (sq.0 / sq.1.max(1) as f64).sqrt() * 100.0,
            w[1] * 100.0,
            w[2] * 100.0
        );
    }
}
