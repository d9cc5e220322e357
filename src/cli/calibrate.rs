//! `bulge calibrate`: photos of a chessboard -> the lens (`[camera]` table).

use std::path::PathBuf;

use anyhow::Context;

use super::{Classify, Failure};
use bulge::track::calibrate::{Board, calibrate_folder};

/// Flags of `bulge calibrate`.
///
/// Finds the chessboard's inner corners in every photo of the folder
/// (OpenCV's findChessboardCorners and cornerSubPix) and fits the camera
/// (calibrateCamera): focal lengths and principal point, px, distortion
/// k1 k2 p1 p2 (k3 held at 0), with the RMS reprojection error over every
/// corner and per photo. Photos where the board is not found are named and
/// skipped. Writes a `[camera]` table: paste it into the experiment file
/// (beside `response`), or give it to `bulge init --camera camera.toml`,
/// which copies it into the experiment file it writes. With it, `bulge
/// track` and `bulge init` undistort the points they measure, and heights
/// are in the undistorted pinhole image's pixels. Photograph the board at
/// the zoom and focus of the experiment, at 10-20 poses, tilted by 10-40
/// degrees, reaching the corners of the picture.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder of the chessboard's photos (PNG, JPEG, TIFF, BMP).
    pub photos: PathBuf,

    /// The side of one square, m (sets the board's poses' units only: the
    /// lens does not depend on it).
    #[arg(long)]
    pub square_m: f64,

    /// Inner corners of the board, COLUMNSxROWS (the corners where four
    /// squares meet: a board of 10x7 squares has 9x6).
    #[arg(long, default_value = "9x6", value_parser = parse_corners)]
    pub inner_corners: [usize; 2],

    /// The `[camera]` table written (whole or not at all).
    #[arg(short, long, default_value = "camera.toml")]
    pub output: PathBuf,
}

fn parse_corners(s: &str) -> anyhow::Result<[usize; 2]> {
    let bad = || {
        anyhow::anyhow!(
            "--inner-corners {s}: give COLUMNSxROWS of inner corners, each at least 2, such as 9x6"
        )
    };
    let (a, b) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (a, b): (usize, usize) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a < 2 || b < 2 {
        return Err(bad());
    }
    Ok([a, b])
}

/// Runs `bulge calibrate`.
pub fn run(args: Args) -> Result<(), Failure> {
    super::output_file(&args.output, "-o")?;
    if !(args.square_m.is_finite() && args.square_m > 0.0) {
        return Err(Failure::BadInput(anyhow::anyhow!(
            "--square-m {}: give the side of one square of the board, m (such as 0.005)",
            args.square_m
        )));
    }
    let board = Board {
        inner: args.inner_corners,
        square_m: args.square_m,
    };
    let c = calibrate_folder(&args.photos, &board).map_err(Failure::of)?;
    for s in &c.skipped {
        eprintln!(
            "skipped {s}: the board ({}x{} inner corners) was not found",
            board.inner[0], board.inner[1]
        );
    }
    let l = &c.lens;
    let [w, h] = l.image_size_px.unwrap_or([0, 0]);
    let s = &c.std;
    let mut text = format!(
        "# The lens, from {} photos of a {}x{} chessboard in {} by `bulge calibrate`\n\
         # (OpenCV calibrateCamera; k3 held at 0). Paste this table into the\n\
         # experiment file, or give it to `bulge init --camera`.\n\
         # RMS reprojection error {:.4} px; standard deviations: fx {:.3}, fy {:.3},\n\
         # cx {:.3}, cy {:.3} px, k1 {:.2e}, k2 {:.2e}, p1 {:.2e}, p2 {:.2e}.\n\
         # The largest displacement by the lens over the {w}x{h} photo: {:.2} px.\n\
         # RMS reprojection error per photo, px:\n",
        c.photos.len(),
        board.inner[0],
        board.inner[1],
        args.photos.display(),
        c.rms_px,
        s[0],
        s[1],
        s[2],
        s[3],
        s[4],
        s[5],
        s[6],
        s[7],
        l.max_displacement_px(w, h),
    );
    for p in &c.photos {
        text.push_str(&format!("#   {} {:.4}\n", p.file, p.rms_px));
    }
    #[derive(serde::Serialize)]
    struct File {
        camera: bulge::experiment::CameraConfig,
    }
    let table = toml::to_string(&File {
        camera: l.to_config(Some(c.rms_px)),
    })
    .context("cannot write the [camera] table")
    .failed()?;
    text.push_str(&table);
    bulge::io::write_atomic(&args.output, text.as_bytes())
        .with_context(|| format!("cannot write {}", args.output.display()))
        .failed()?;
    println!(
        "calibrated the lens from {} of {} photos ({} skipped) of {w}x{h} px: fx {:.2} fy {:.2} px, principal point ({:.2}, {:.2}) px, k1 {:.4} k2 {:.4} p1 {:.2e} p2 {:.2e}, RMS reprojection error {:.4} px (worst photo {:.4} px) -> {}",
        c.photos.len(),
        c.photos.len() + c.skipped.len(),
        c.skipped.len(),
        l.fx,
        l.fy,
        l.cx,
        l.cy,
        l.k1,
        l.k2,
        l.p1,
        l.p2,
        c.rms_px,
        c.photos.iter().map(|p| p.rms_px).fold(0.0, f64::max),
        args.output.display()
    );
    Ok(())
}
