//! `bulge simulate --model axisym`: rows of the exact axisymmetric solution
//! of the disc at the scene's pressures.

use std::path::Path;
use std::time::Instant;

use anyhow::anyhow;

use crate::cli::Failure;
use bulge::axisym::{self, AxisymError};
use bulge::io::{CsvOut, fmt_num};
use bulge::sim::scene::{Scene, SceneKind};

/// Rows of the exact axisymmetric solution at the scene's pressures.
pub(super) fn run_axisym(
    scene: &Scene,
    header_len: usize,
    csv: &mut CsvOut,
    table: &mut Vec<String>,
    failures: &mut Vec<String>,
    profile: Option<&Path>,
    pb: &indicatif::ProgressBar,
) -> Result<Option<CsvOut>, Failure> {
    let SceneKind::Disc {
        radius_m,
        dome_height_m,
    } = scene.kind
    else {
        return Err(Failure::BadInput(anyhow!(
            "--model axisym solves the clamped circular disc only; this scene is the {} ([window] or the scene's kind): simulate it with --model tp or membrane",
            scene.kind.name()
        )));
    };
    let specimen = bulge::experiment::Specimen {
        radius_m,
        thickness_m: scene.thickness_m,
        poisson: scene.material.poisson,
        prebulge_height_m: dome_height_m,
    };
    let opts = axisym::Options::default();
    let mut last = None;
    for &p in &scene.pressures_pa {
        let t0 = Instant::now();
        let out = axisym::solve_pressure(&scene.material, &specimen, p, &opts);
        let wall = t0.elapsed().as_secs_f64();
        pb.inc(1);
        match out {
            Ok(sol) => {
                let mut row = vec![
                    fmt_num(Some(p)),
                    fmt_num(Some(sol.height_m)),
                    "axisym".to_string(),
                    "shooting".to_string(),
                    opts.n_profile.to_string(),
                    sol.iterations.to_string(),
                    format!("{:.3e}", sol.residual),
                    format!("{wall:.4}"),
                ];
                row.resize(header_len, String::new());
                csv.row(&row);
                table.push(format!(
                    "{:>10} {:>12.6e} {:>10} {:>7} {:>6} {:>9.2e} {:>8.3}",
                    p, sol.height_m, "axisym", "shoot", sol.iterations, sol.residual, wall
                ));
                last = Some(sol);
            }
            Err(
                e @ (AxisymError::Specimen(_)
                | AxisymError::Material(_)
                | AxisymError::Options(_)
                | AxisymError::Pressure(_)),
            ) => return Err(Failure::BadInput(anyhow!("axisym at {p} Pa: {e}"))),
            Err(e) => {
                failures.push(format!("axisym: {e}"));
                break;
            }
        }
    }
    Ok(match (profile, last) {
        (Some(_), Some(sol)) => Some(axisym::profile_csv(&sol)),
        _ => None,
    })
}
