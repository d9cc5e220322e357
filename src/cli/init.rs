//! `bulge init`: the experiment file from the photos alone.

use std::path::{Component, Path, PathBuf};

use anyhow::anyhow;

use super::{Classify, Failure};
use bulge::experiment::Specimen;
use bulge::io::OutputPlan;
use bulge::track::init::{self, Frames, Given, Sources};
use bulge::track::{self, TrackError};

/// Flags of `bulge init`.
///
/// Finds, in a folder of photos of a bubble test taken from the side while
/// the bubble grows, everything `bulge track` needs: the clamp plane (its
/// row, to a fraction of a pixel), the bubble's axis, the apex in every
/// photo, the region where it moves, a template around it, the scale from
/// the clamp opening (the silhouette is 2a wide at the clamp plane) and the
/// camera's elevation above the clamp plane (from the clamp's ellipse). It
/// writes a commented experiment file, each value found with its standard
/// deviation, and init.png: the last photo with everything found drawn on
/// it. What it cannot find (no bubble, a bubble cut by the border, the
/// clamp out of the picture, two candidate edges) is refused with exit
/// status 2, naming the key to set by hand.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder of photos, in the order taken (natural order of the names:
    /// img2 before img10), or a video; the bubble must grow from the first
    /// frame to the last.
    pub source: PathBuf,

    /// A video only: use every N-th frame (frames 0, N, 2N, ...; default 1),
    /// written into [photos] `every`.
    #[arg(long, value_name = "N")]
    pub every: Option<usize>,

    /// The experiment file to write (refused if it exists, unless --force).
    #[arg(short, long, default_value = "experiment.toml")]
    pub output: PathBuf,

    /// The specimen's free radius a (the clamp opening's radius), m.
    #[arg(long)]
    pub radius_m: f64,

    /// The specimen's initial thickness t, m.
    #[arg(long)]
    pub thickness_m: f64,

    /// Poisson ratio (default 0.45).
    #[arg(long, default_value_t = 0.45)]
    pub poisson: f64,

    /// The pressure log: columns file,pressure_pa (by photo), or a log by
    /// time (see docs/track.md). Written into [pressure] relative to the
    /// experiment file; without it, [pressure] is left for you to fill in.
    #[arg(long)]
    pub pressure: Option<PathBuf>,

    /// The photos to use in the folder (default: every file with the
    /// folder's most common image extension, e.g. "*.jpg").
    #[arg(long)]
    pub glob: Option<String>,

    /// The scale, m per px, when known (instead of the clamp opening).
    #[arg(long, conflicts_with = "points_px")]
    pub metres_per_pixel: Option<f64>,

    /// Two points in the photos (x1,y1,x2,y2 px) a known distance apart
    /// (--distance-m), for the scale instead of the clamp opening.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 4,
        requires = "distance_m",
        value_name = "X1,Y1,X2,Y2"
    )]
    pub points_px: Option<Vec<f64>>,

    /// The distance between --points-px, m.
    #[arg(long, requires = "points_px")]
    pub distance_m: Option<f64>,

    /// The camera's elevation above the clamp plane, degrees, when known
    /// (default: found from the clamp's ellipse when its ends are in the
    /// picture, else level).
    #[arg(long)]
    pub elevation_deg: Option<f64>,

    /// The camera's tone curve from light to grey levels: `srgb` (ordinary
    /// 8-bit JPEG or PNG photos), `linear` (raw or linearised photos), or a
    /// gamma such as 2.2. Edges are located in light; the experiment file
    /// keeps it as `[camera] response`.
    #[arg(long, default_value = "srgb", value_parser = parse_response)]
    pub response: bulge::camera::Response,

    /// The lens, a `[camera]` table written by `bulge calibrate`: the
    /// clamp row, the axis and the scale are measured in the undistorted
    /// image, and the table is copied into the experiment file.
    #[arg(long)]
    pub camera: Option<PathBuf>,

    /// Where to draw what was found (default: init.png beside the
    /// experiment file).
    #[arg(long)]
    pub png: Option<PathBuf>,

    /// Replace an existing experiment file (never one of the inputs).
    #[arg(long)]
    pub force: bool,
}

fn parse_response(s: &str) -> Result<bulge::camera::Response, String> {
    s.parse()
}

/// `path` relative to the folder `base` (both made absolute), with `/`.
fn relative(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| {
        let p = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        p.components().fold(PathBuf::new(), |mut acc, c| {
            match c {
                Component::ParentDir => {
                    acc.pop();
                }
                Component::CurDir => {}
                c => acc.push(c),
            }
            acc
        })
    };
    let (p, b) = (abs(path), abs(base));
    let pc: Vec<Component> = p.components().collect();
    let bc: Vec<Component> = b.components().collect();
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); bc.len() - common];
    parts.extend(
        pc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    if parts.is_empty() {
        ".".into()
    } else {
        parts.join("/")
    }
}

/// The folder's most common image extension as a glob.
fn default_glob(dir: &Path) -> Result<String, Failure> {
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    let rd = std::fs::read_dir(dir).map_err(|e| {
        Failure::BadInput(anyhow!(
            "{}: cannot read the photo folder: {e}",
            dir.display()
        ))
    })?;
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if let Some((_, ext)) = name.rsplit_once('.') {
            let ext = ext.to_string();
            if ["jpg", "jpeg", "png", "tif", "tiff", "bmp"]
                .contains(&ext.to_ascii_lowercase().as_str())
            {
                *counts.entry(ext).or_default() += 1;
            }
        }
    }
    counts
        .into_iter()
        .max_by_key(|(_, n)| *n)
        .map(|(ext, _)| format!("*.{ext}"))
        .ok_or_else(|| {
            Failure::BadInput(anyhow!(
                "{}: no photos (.jpg, .jpeg, .png, .tif, .tiff, .bmp) in the folder; give the folder of the test's photos, or --glob",
                dir.display()
            ))
        })
}

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
    let given = Given {
        metres_per_pixel: args.metres_per_pixel.or(points
            .map(|(p, d)| d / ((p[1][0] - p[0][0]).powi(2) + (p[1][1] - p[0][1]).powi(2)).sqrt())),
        elevation_deg: args.elevation_deg,
        response: args.response,
        lens,
    };
    let found = init::find_in(&frames, args.radius_m, given).map_err(|e: TrackError| {
        if e.is_bad_input() {
            Failure::BadInput(e.into())
        } else {
            Failure::Failed(e.into())
        }
    })?;
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
