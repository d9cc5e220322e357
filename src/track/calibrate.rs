//! The lens from photos of a chessboard (`bulge calibrate`): OpenCV's
//! `findChessboardCorners` and `cornerSubPix` in every photo, then
//! `calibrateCameraExtended` (Zhang, "A flexible new technique for camera
//! calibration", IEEE Trans. PAMI 22(11), 1330-1334, 2000,
//! doi:10.1109/34.888718) for the focal lengths, the principal point and the
//! distortion coefficients `k1 k2 p1 p2` (`k3` is held at 0: a lens of
//! ordinary field of view does not determine it apart from `k2`).

use std::path::{Path, PathBuf};

use opencv::core::{Mat, Point2f, Point3f, Size, TermCriteria, Vector};
use opencv::prelude::*;

use super::TrackError;
use super::lens::Lens;
pub use super::synth::lens::Board;

/// The fewest photos with the board found: Zhang's method needs three views
/// of the plane at different tilts to determine the intrinsics.
pub const MIN_PHOTOS: usize = 3;

/// One photo's part in the calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct PhotoFit {
    /// The photo's file name.
    pub file: String,
    /// RMS reprojection error of its corners, px.
    pub rms_px: f64,
}

/// A calibrated lens and how well it fits.
#[derive(Debug, Clone, PartialEq)]
pub struct LensCalibration {
    /// The lens (with the photos' size).
    pub lens: Lens,
    /// Standard deviations of `fx fy cx cy k1 k2 p1 p2 k3` (OpenCV's, from
    /// the residuals and the Jacobian; 0 for `k3`, held at 0).
    pub std: [f64; 9],
    /// RMS reprojection error over every corner, px.
    pub rms_px: f64,
    /// The photos used, in order.
    pub photos: Vec<PhotoFit>,
    /// The photos where the board was not found.
    pub skipped: Vec<String>,
}

/// The photos of a folder (PNG, JPEG, TIFF, BMP), in natural order.
fn list_photos(dir: &Path) -> Result<Vec<PathBuf>, TrackError> {
    let cfg = |message: String| TrackError::Config {
        path: dir.to_path_buf(),
        message,
    };
    let rd = std::fs::read_dir(dir).map_err(|e| {
        cfg(format!(
            "cannot read the folder ({e}): give the folder of the chessboard's photos"
        ))
    })?;
    let mut names: Vec<String> = rd
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_file())
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| {
            let l = n.to_ascii_lowercase();
            [".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp"]
                .iter()
                .any(|x| l.ends_with(x))
        })
        .collect();
    names.sort_by(|a, b| super::natural_cmp(a, b));
    if names.is_empty() {
        return Err(cfg("no photos (PNG, JPEG, TIFF or BMP) in the folder: give the folder of the chessboard's photos".into()));
    }
    Ok(names.into_iter().map(|n| dir.join(n)).collect())
}

fn cv(e: opencv::Error) -> TrackError {
    TrackError::OpenCv(e.to_string())
}

/// The board's inner corners in one photo, refined to sub-pixel precision
/// (`None`: the board is not found).
fn corners(img: &super::image::Gray, board: &Board) -> Result<Option<Vector<Point2f>>, TrackError> {
    let mat = img.as_mat().map_err(cv)?;
    let pattern = Size::new(board.inner[0] as i32, board.inner[1] as i32);
    let mut found = Vector::<Point2f>::new();
    let flags =
        opencv::calib3d::CALIB_CB_ADAPTIVE_THRESH | opencv::calib3d::CALIB_CB_NORMALIZE_IMAGE;
    if !opencv::calib3d::find_chessboard_corners(&mat, pattern, &mut found, flags).map_err(cv)? {
        return Ok(None);
    }
    // The refinement's window stays inside the squares around each corner:
    // its side at most 0.8 of the smallest spacing between neighbours.
    let nx = board.inner[0];
    let mut spacing = f32::INFINITY;
    for (k, p) in found.iter().enumerate() {
        if k % nx + 1 < nx {
            let q = found.get(k + 1).map_err(cv)?;
            spacing = spacing.min((p.x - q.x).hypot(p.y - q.y));
        }
        if k + nx < found.len() {
            let q = found.get(k + nx).map_err(cv)?;
            spacing = spacing.min((p.x - q.x).hypot(p.y - q.y));
        }
    }
    let half = ((0.4 * spacing).floor() as i32).clamp(2, 11);
    let crit = TermCriteria::new(
        opencv::core::TermCriteria_Type::COUNT as i32 | opencv::core::TermCriteria_Type::EPS as i32,
        100,
        1e-4,
    )
    .map_err(cv)?;
    opencv::imgproc::corner_sub_pix(
        &mat,
        &mut found,
        Size::new(half, half),
        Size::new(-1, -1),
        crit,
    )
    .map_err(cv)?;
    Ok(Some(found))
}

/// Calibrates the lens from the photos of `board` in the folder `dir`.
/// Photos where the board is not found are skipped (and named in the
/// result); fewer than [`MIN_PHOTOS`] with the board found, or photos of
/// different sizes, are refused.
pub fn calibrate_folder(dir: &Path, board: &Board) -> Result<LensCalibration, TrackError> {
    let photos = list_photos(dir)?;
    let object: Vector<Point3f> = board
        .corners_m()
        .iter()
        .map(|c| Point3f::new(c[0] as f32, c[1] as f32, 0.0))
        .collect();
    let mut object_points = Vector::<Vector<Point3f>>::new();
    let mut image_points = Vector::<Vector<Point2f>>::new();
    let mut used = Vec::new();
    let mut skipped = Vec::new();
    let mut size: Option<([usize; 2], String)> = None;
    for p in &photos {
        let name = p
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let d = super::image::read_gray(p, None)?;
        match &size {
            None => size = Some(([d.width, d.height], name.clone())),
            Some((s, first)) if *s != [d.width, d.height] => {
                return Err(TrackError::Config {
                    path: p.clone(),
                    message: format!(
                        "the photo is {}x{} px but {first} is {}x{} px: a calibration is for one photo size; photograph the board at the size of the experiment's photos",
                        d.width, d.height, s[0], s[1]
                    ),
                });
            }
            _ => {}
        }
        match corners(&d.crop, board)? {
            Some(c) => {
                object_points.push(object.clone());
                image_points.push(c);
                used.push(name);
            }
            None => skipped.push(name),
        }
    }
    let ([w, h], _) = size.expect("at least one photo");
    if used.len() < MIN_PHOTOS {
        return Err(TrackError::Config {
            path: dir.to_path_buf(),
            message: format!(
                "the board ({}x{} inner corners) was found in {} of {} photos{}, and the calibration needs at least {MIN_PHOTOS}: photograph the whole board (every square in the picture, sharp and evenly lit) at 10-20 poses, tilted by 10-40 degrees, reaching the corners of the picture; check {} (columns x rows of corners where four squares meet, not of squares)",
                board.inner[0],
                board.inner[1],
                used.len(),
                photos.len(),
                if skipped.is_empty() {
                    String::new()
                } else {
                    format!(" (not found in {})", skipped.join(", "))
                },
                crate::setting::Setting::InnerCorners
            ),
        });
    }
    let mut k = Mat::default();
    let mut dist = Mat::default();
    let (mut rvecs, mut tvecs) = (Vector::<Mat>::new(), Vector::<Mat>::new());
    let (mut std_i, mut std_e, mut per_view) = (Mat::default(), Mat::default(), Mat::default());
    let crit = TermCriteria::new(
        opencv::core::TermCriteria_Type::COUNT as i32 | opencv::core::TermCriteria_Type::EPS as i32,
        200,
        1e-12,
    )
    .map_err(cv)?;
    let rms = opencv::calib3d::calibrate_camera_extended(
        &object_points,
        &image_points,
        Size::new(w as i32, h as i32),
        &mut k,
        &mut dist,
        &mut rvecs,
        &mut tvecs,
        &mut std_i,
        &mut std_e,
        &mut per_view,
        opencv::calib3d::CALIB_FIX_K3,
        crit,
    )
    .map_err(cv)?;
    let at = |m: &Mat, r: i32, c: i32| -> Result<f64, TrackError> {
        m.at_2d::<f64>(r, c).copied().map_err(cv)
    };
    let d: Vec<f64> = (0..5)
        .map(|i| dist.at::<f64>(i).copied().map_err(cv))
        .collect::<Result<_, _>>()?;
    let s: Vec<f64> = (0..9)
        .map(|i| std_i.at::<f64>(i).copied().map_err(cv))
        .collect::<Result<_, _>>()?;
    let lens = Lens {
        fx: at(&k, 0, 0)?,
        fy: at(&k, 1, 1)?,
        cx: at(&k, 0, 2)?,
        cy: at(&k, 1, 2)?,
        k1: d[0],
        k2: d[1],
        p1: d[2],
        p2: d[3],
        k3: d[4],
        image_size_px: Some([w, h]),
    };
    let photos = used
        .into_iter()
        .enumerate()
        .map(|(i, file)| {
            Ok(PhotoFit {
                file,
                rms_px: per_view.at::<f64>(i as i32).copied().map_err(cv)?,
            })
        })
        .collect::<Result<_, TrackError>>()?;
    Ok(LensCalibration {
        lens,
        std: [s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], s[8]],
        rms_px: rms,
        photos,
        skipped,
    })
}

/// Writes synthetic photos of `board` through `lens` into `dir`
/// (`board_NN.png`, `n` poses from [`super::synth::lens::board_poses`]):
/// the test set of [`calibrate_folder`].
#[allow(clippy::too_many_arguments)]
pub fn write_board_photos(
    dir: &Path,
    board: &Board,
    lens: &Lens,
    size: [usize; 2],
    n: usize,
    blur_px: f64,
    noise_grey: f64,
    seed: u64,
) -> Result<(), TrackError> {
    use super::synth::lens::{board_poses, render_board};
    std::fs::create_dir_all(dir).map_err(|e| TrackError::Write {
        path: dir.to_path_buf(),
        reason: e.to_string(),
    })?;
    let poses = board_poses(board, lens, size[0], size[1], n, seed);
    for (i, p) in poses.iter().enumerate() {
        let img = render_board(
            board,
            p,
            lens,
            size[0],
            size[1],
            blur_px,
            noise_grey,
            seed.wrapping_add(i as u64 + 1),
        );
        let bytes = super::image::encode(&img, super::image::Encoding::Png)?;
        let path = dir.join(format!("board_{:02}.png", i + 1));
        crate::io::write_atomic(&path, &bytes).map_err(|e| TrackError::Write {
            path: path.clone(),
            reason: e.to_string(),
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic photos of a 9x6 board through a lens of known k1, k2:
    /// the calibration recovers them within its own stated uncertainty.
    #[test]
    fn recovers_a_known_lens_from_synthetic_boards() {
        let dir = tempfile::tempdir().unwrap();
        let truth = Lens {
            k1: -0.12,
            k2: 0.08,
            image_size_px: Some([640, 480]),
            ..Lens::pinhole(760.0, 760.0, 321.3, 238.6)
        };
        let board = Board {
            inner: [9, 6],
            square_m: 0.02,
        };
        write_board_photos(dir.path(), &board, &truth, [640, 480], 12, 0.8, 2.0, 7).unwrap();
        let c = calibrate_folder(dir.path(), &board).unwrap();
        assert!(c.skipped.is_empty(), "{:?}", c.skipped);
        assert!(c.rms_px < 0.1, "{}", c.rms_px);
        let l = c.lens;
        for (got, want, s, what) in [
            (l.fx, truth.fx, c.std[0], "fx"),
            (l.fy, truth.fy, c.std[1], "fy"),
            (l.k1, truth.k1, c.std[4], "k1"),
        ] {
            assert!(
                (got - want).abs() < 4.0 * s,
                "{what}: {got} vs {want} +- {s}"
            );
        }
    }
}
