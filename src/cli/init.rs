//! `bulge init`: the experiment file from the photos alone
//! ([`bulge::track::init::command`], shared with the Python package): the
//! settings checked, the frames guarded against the outputs, the set-up
//! found, then the experiment file and `init.png` written.

use std::path::Path;

use anyhow::anyhow;

use super::Failure;
use bulge::experiment::Specimen;
use bulge::io::OutputPlan;
use bulge::track::init::command::{InitRequest, init_files, init_inputs};

mod args;
pub use args::*;

/// Runs `bulge init`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let bad = |m: String| Failure::BadInput(anyhow!(m));
    let base = args
        .output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let req = InitRequest {
        source: args.source.clone(),
        every: args.every,
        specimen: Specimen {
            radius_m: args.radius_m,
            thickness_m: args.thickness_m,
            poisson: args.poisson,
            prebulge_height_m: 0.0,
        },
        pressure: args.pressure.clone(),
        glob: args.glob.clone(),
        metres_per_pixel: args.metres_per_pixel,
        points_px: match (&args.points_px, args.distance_m) {
            (Some(p), Some(d)) => Some(([p[0], p[1], p[2], p[3]], d)),
            _ => None,
        },
        elevation_deg: args.elevation_deg,
        clamp_row_px: args.clamp_row_px.map(|r| (r, args.clamp_row_std_px)),
        camera_distance_m: args.camera_distance_m,
        orthographic: args.orthographic,
        response: args.response,
        camera: args.camera.clone(),
        base: base.to_path_buf(),
    };
    let inputs = init_inputs(&req).map_err(Failure::of)?;
    let png = args.png.clone().unwrap_or_else(|| {
        args.output
            .parent()
            .unwrap_or(Path::new("."))
            .join("init.png")
    });
    super::guard(
        OutputPlan::new()
            .inputs(&inputs)
            .output(&png)
            .output(&args.output),
    )?;
    if args.output.exists() && !args.force {
        return Err(bad(format!(
            "{} exists: bulge init does not replace an experiment file; pass --force to replace it, or -o another name",
            args.output.display()
        )));
    }
    let files = init_files(&req).map_err(Failure::of)?;
    std::fs::create_dir_all(base).map_err(|e| {
        Failure::Failed(anyhow!("{}: cannot create the folder: {e}", base.display()))
    })?;
    bulge::io::write_atomic(&png, &files.png)
        .map_err(|e| Failure::Failed(anyhow!("{}: cannot write: {e}", png.display())))?;
    bulge::io::write_atomic(&args.output, files.toml.as_bytes())
        .map_err(|e| Failure::Failed(anyhow!("{}: cannot write: {e}", args.output.display())))?;
    println!(
        "{} -> {}, {}",
        files.summary,
        args.output.display(),
        png.display()
    );
    for n in &files.notes {
        eprintln!("{n}");
    }
    if args.pressure.is_none() {
        eprintln!(
            "note: no --pressure given: fill in [pressure] csv in {} before `bulge track`",
            args.output.display()
        );
    }
    Ok(())
}
