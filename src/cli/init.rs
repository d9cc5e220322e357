//! `bulge init`: the experiment file from the photos alone.

use std::path::{Path, PathBuf};

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::experiment::Specimen;
use bulge::io::OutputPlan;
use bulge::track::init::{self, Frames, Given, Sources};
use bulge::track::{self, TrackError};

mod paths;
use paths::{default_glob, relative};

mod args;
pub use args::*;

/// Runs `bulge init`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    let bad = |m: String| Failure::BadInput(anyhow!(m));
    let specimen = Specimen {
        radius_m: args.radius_m,
        thickness_m: args.thickness_m,
        poisson: args.poisson,
        prebulge_height_m: 0.0,
    };
    specimen.validate().map_err(|m| {
        bad(format!(
            "the specimen (--radius-m, --thickness-m, --poisson): {m}"
        ))
    })?;
    if let Some(m) = args.metres_per_pixel
        && !(m.is_finite() && m > 0.0)
    {
        return Err(bad(format!(
            "--metres-per-pixel {m}: give a positive scale, m per px"
        )));
    }
    if let Some(e) = args.elevation_deg
        && !(0.0..=30.0).contains(&e)
    {
        return Err(bad(format!("--elevation-deg {e}: give 0 to 30 degrees")));
    }
    if !args.source.exists() {
        return Err(bad(format!(
            "{}: no such folder or video; give the folder the camera wrote the test's photos to, or the video",
            args.source.display()
        )));
    }
    if args.every.is_some() && args.source.is_dir() {
        return Err(bad(format!(
            "--every applies to a video, and {} is a photo folder: drop --every, or use --glob to choose photos",
            args.source.display()
        )));
    }
    let points = match (&args.points_px, args.distance_m) {
        (Some(p), Some(d)) => {
            let pts = [[p[0], p[1]], [p[2], p[3]]];
            let len = ((p[2] - p[0]).powi(2) + (p[3] - p[1]).powi(2)).sqrt();
            if !(d.is_finite() && d > 0.0) || len == 0.0 {
                return Err(bad(format!(
                    "--points-px {p:?} with --distance-m {d}: give two different points and a positive distance"
                )));
            }
            Some((pts, d))
        }
        _ => None,
    };
    let (frames, glob) = if args.source.is_dir() {
        let glob = match &args.glob {
            Some(g) => g.clone(),
            None => default_glob(&args.source)?,
        };
        let photos = track::list_photos(&args.source, &glob).bad_input()?;
        (Frames::Photos(photos), glob)
    } else {
        let info = track::video::probe(&args.source).bad_input()?;
        let indices = info
            .select(args.every, None)
            .map_err(|m| bad(format!("{}: {m} (--every)", args.source.display())))?;
        (
            Frames::Video {
                path: args.source.clone(),
                indices,
            },
            String::new(),
        )
    };
    let inputs: Vec<PathBuf> = match &frames {
        Frames::Photos(p) => p.clone(),
        Frames::Video { path, .. } => vec![path.clone()],
    };
    if let Some(p) = &args.pressure
        && !p.is_file()
    {
        return Err(bad(format!("--pressure {}: no such file", p.display())));
    }
    let png = args.png.clone().unwrap_or_else(|| {
        args.output
            .parent()
            .unwrap_or(Path::new("."))
            .join("init.png")
    });
    let mut plan = OutputPlan::new().inputs(&inputs).output(&png);
    if let Some(p) = &args.pressure {
        plan = plan.input(p);
    }
    plan = plan.output(&args.output);
    super::guard(plan)?;
    if args.output.exists() && !args.force {
        return Err(bad(format!(
            "{} exists: bulge init does not replace an experiment file; pass --force to replace it, or -o another name",
            args.output.display()
        )));
    }
    let lens = match &args.camera {
        Some(p) => Some(read_lens(p)?),
        None => None,
    };
    if let Some(d) = args.camera_distance_m
        && !(d.is_finite() && d > 2.0 * args.radius_m)
    {
        return Err(bad(format!(
            "--camera-distance-m {d}: give the horizontal distance from the bubble's axis to the camera's lens, m, more than the opening's diameter {}",
            2.0 * args.radius_m
        )));
    }
    let given = Given {
        metres_per_pixel: args.metres_per_pixel.or(points
            .map(|(p, d)| d / ((p[1][0] - p[0][0]).powi(2) + (p[1][1] - p[0][1]).powi(2)).sqrt())),
        elevation_deg: args.elevation_deg,
        response: args.response,
        lens,
        camera_distance_m: args.camera_distance_m,
        distance_from_focal: !args.orthographic,
    };
    let found = init::find_in(&frames, args.radius_m, given).map_err(Failure::of::<TrackError>)?;
    if let Some(why) = found
        .raised_without_distance()
        .filter(|_| !args.orthographic)
    {
        return Err(bad(format!(
            "{why}; give --camera-distance-m D (from the bubble's axis to the lens, m), or --camera camera.toml (bulge calibrate: the distance from its focal length), or --orthographic if the lens is telecentric"
        )));
    }
    let base = args
        .output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(base).map_err(|e| {
        Failure::Failed(anyhow!("{}: cannot create the folder: {e}", base.display()))
    })?;
    let sources = Sources {
        dir: relative(&args.source, base),
        video_every: match frames {
            Frames::Photos(_) => None,
            Frames::Video { .. } => Some(args.every.unwrap_or(1)),
        },
        glob,
        count: frames.len(),
        pressure_csv: args.pressure.as_ref().map(|p| relative(p, base)),
        points,
    };
    let toml = found.experiment_toml(&specimen, &sources);
    let picture = track::annotate::init_png(&frames, frames.len() - 1, &found, 1600).failed()?;
    bulge::io::write_atomic(&png, &picture)
        .map_err(|e| Failure::Failed(anyhow!("{}: cannot write: {e}", png.display())))?;
    bulge::io::write_atomic(&args.output, toml.as_bytes())
        .map_err(|e| Failure::Failed(anyhow!("{}: cannot write: {e}", args.output.display())))?;
    let a = found.radius_px.map_or(String::new(), |a| {
        format!(", 2a = {:.2} +- {:.2} px", 2.0 * a.value, 2.0 * a.std)
    });
    let e = found.elevation_deg.map_or(String::new(), |e| {
        format!(", elevation {:.2} +- {:.2} deg", e.value, e.std)
    });
    let e = match (found.camera_distance_m, found.camera_distance_from_focal) {
        (Some(d), true) => {
            format!("{e}, camera {d:.4} m from the axis (the lens's focal length times the scale)")
        }
        _ => e,
    };
    println!(
        "{} {} {}x{} px: clamp row {:.3} +- {:.3} px, axis {:.2} px{a}, {:.5e} m/px{e}; apex rows {:.0} to {:.0} -> {}, {}",
        frames.len(),
        match frames {
            Frames::Photos(_) => "photos",
            Frames::Video { .. } => "video frames",
        },
        found.width,
        found.height,
        found.clamp_row_px.value,
        found.clamp_row_px.std,
        found.axis_x_px.value,
        found.metres_per_pixel.value,
        found
            .apexes_px
            .iter()
            .map(|p| p[1])
            .fold(f64::INFINITY, f64::min),
        found
            .apexes_px
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max),
        args.output.display(),
        png.display()
    );
    if found.camera_distance_m.is_none()
        && !args.orthographic
        && found.scale_from == init::ScaleSource::ClampOpening
    {
        eprintln!(
            "note: the camera is read as orthographic (no --camera-distance-m, no lens with a focal length): a camera D from the bubble's axis sees the opening through its tangent points, so the scale comes out about a^2 / (2 D^2) small (0.35 % at 0.45 m); give --camera-distance-m D or --camera camera.toml (bulge calibrate)"
        );
    }
    if args.pressure.is_none() {
        eprintln!(
            "note: no --pressure given: fill in [pressure] csv in {} before `bulge track`",
            args.output.display()
        );
    }
    Ok(())
}

/// The lens of a `[camera]` table written by `bulge calibrate`.
fn read_lens(p: &Path) -> Result<bulge::track::lens::Lens, Failure> {
    #[derive(serde::Deserialize)]
    struct File {
        camera: Option<bulge::experiment::CameraConfig>,
    }
    let bad = |m: String| Failure::BadInput(anyhow!("{}: {m}", p.display()));
    let text = std::fs::read_to_string(p).map_err(|e| {
        bad(format!(
            "cannot read it ({e}); give the file `bulge calibrate` wrote"
        ))
    })?;
    let f: File = toml::from_str(&text).map_err(|e| bad(format!("not a [camera] table: {e}")))?;
    let c = f
        .camera
        .ok_or_else(|| bad("no [camera] table: give the file `bulge calibrate` wrote".into()))?;
    bulge::track::lens::Lens::from_config(&c)
        .map_err(bad)?
        .ok_or_else(|| bad("the [camera] table has no lens (focal_px, principal_point_px, distortion): give the file `bulge calibrate` wrote".into()))
}
