//! A tracked photo with what was found drawn on it, as PNG bytes, for the
//! report of `bulge run` (here because only `src/track/` uses OpenCV).
//!
//! Drawn in colour over the photo: the search region `roi_px` (blue), the
//! matched template rectangle (green) and the apex (red cross). Photos wider
//! than `max_width_px` are scaled down (area interpolation) so that a report
//! with several frames stays small.

use std::path::Path;

use opencv::core::{Mat, MatTraitConst, Point, Rect, Scalar, Size, Vector};
use opencv::{imgcodecs, imgproc};

use super::TrackError;

/// What to draw on one photo, in image pixels (centre of the top-left pixel
/// at (0, 0), as everywhere in [`crate::track`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Marks {
    /// The search region `[x, y, width, height]`.
    pub roi_px: [f64; 4],
    /// The matched template `[x, y, width, height]`.
    pub template_px: [f64; 4],
    /// The apex `[x, y]`.
    pub apex_px: [f64; 2],
}

fn cv(e: opencv::Error) -> TrackError {
    TrackError::OpenCv(e.to_string())
}

/// Reads the photo at `path`, draws `marks` and returns a PNG, at most
/// `max_width_px` wide.
pub fn annotated_png(
    path: &Path,
    marks: &Marks,
    max_width_px: usize,
) -> Result<Vec<u8>, TrackError> {
    let bytes = std::fs::read(path).map_err(|e| TrackError::Unreadable {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let img = imgcodecs::imdecode(&Vector::<u8>::from_slice(&bytes), imgcodecs::IMREAD_COLOR)
        .map_err(cv)?;
    if img.empty() {
        return Err(TrackError::Unreadable {
            path: path.to_path_buf(),
            reason: "OpenCV cannot decode it".into(),
        });
    }
    draw_png(img, marks, max_width_px)
}

/// [`annotated_png`] for a tracked frame: a photo, or a frame of a video.
pub fn annotated_frame_png(
    frame: &super::Frame,
    marks: &Marks,
    max_width_px: usize,
) -> Result<Vec<u8>, TrackError> {
    match frame.video_frame {
        Some(i) => draw_png(
            super::video::read_frame_bgr(&frame.path, i)?,
            marks,
            max_width_px,
        ),
        None => annotated_png(&frame.path, marks, max_width_px),
    }
}

/// Draws `marks` on a colour image and encodes it as PNG, at most
/// `max_width_px` wide.
fn draw_png(img: Mat, marks: &Marks, max_width_px: usize) -> Result<Vec<u8>, TrackError> {
    let (w, h) = (img.cols() as f64, img.rows() as f64);
    let scale = if max_width_px > 0 && w > max_width_px as f64 {
        max_width_px as f64 / w
    } else {
        1.0
    };
    let mut out = Mat::default();
    if scale < 1.0 {
        let size = Size::new((w * scale).round() as i32, (h * scale).round() as i32);
        imgproc::resize(&img, &mut out, size, 0.0, 0.0, imgproc::INTER_AREA).map_err(cv)?;
    } else {
        out = img;
    }
    let thick = ((out.cols() as f64 / 400.0).round() as i32).max(1);
    // Pixel-centre coordinates to the scaled image's pixel edges.
    let px = |v: f64| ((v + 0.5) * scale).round() as i32;
    let rect = |r: [f64; 4]| {
        let (x0, y0) = (px(r[0] - 0.5), px(r[1] - 0.5));
        let (x1, y1) = (px(r[0] + r[2] - 0.5), px(r[1] + r[3] - 0.5));
        Rect::new(x0, y0, (x1 - x0).max(1), (y1 - y0).max(1))
    };
    let blue = Scalar::new(220.0, 120.0, 0.0, 0.0);
    let green = Scalar::new(0.0, 200.0, 0.0, 0.0);
    let red = Scalar::new(0.0, 0.0, 255.0, 0.0);
    imgproc::rectangle(
        &mut out,
        rect(marks.roi_px),
        blue,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    imgproc::rectangle(
        &mut out,
        rect(marks.template_px),
        green,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    let (ax, ay) = (px(marks.apex_px[0]), px(marks.apex_px[1]));
    let arm = 4 * thick + 3;
    imgproc::line(
        &mut out,
        Point::new(ax - arm, ay),
        Point::new(ax + arm, ay),
        red,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    imgproc::line(
        &mut out,
        Point::new(ax, ay - arm),
        Point::new(ax, ay + arm),
        red,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    let mut buf = Vector::<u8>::new();
    let ok = imgcodecs::imencode(".png", &out, &mut buf, &Vector::new()).map_err(cv)?;
    if !ok {
        return Err(TrackError::OpenCv("OpenCV could not encode a PNG".into()));
    }
    Ok(buf.as_slice().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::image::{Encoding, Gray, encode};

    #[test]
    fn draws_marks_in_colour_and_scales_down() {
        let img = Gray {
            width: 200,
            height: 100,
            data: vec![128; 200 * 100],
        };
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.png");
        std::fs::write(&p, encode(&img, Encoding::Png).unwrap()).unwrap();
        let marks = Marks {
            roi_px: [50.0, 20.0, 100.0, 60.0],
            template_px: [80.0, 40.0, 30.0, 10.0],
            apex_px: [95.0, 45.0],
        };
        let png = annotated_png(&p, &marks, 100).unwrap();
        let m =
            imgcodecs::imdecode(&Vector::<u8>::from_slice(&png), imgcodecs::IMREAD_COLOR).unwrap();
        assert_eq!((m.cols(), m.rows()), (100, 50));
        // The apex cross is red (BGR) at the scaled apex.
        let v = *m.at_2d::<opencv::core::Vec3b>(23, 48).unwrap();
        assert!(v[2] > 200 && v[0] < 100, "{v:?}");
        // A grey pixel far from every mark stays grey.
        let g = *m.at_2d::<opencv::core::Vec3b>(2, 2).unwrap();
        assert_eq!((g[0], g[1], g[2]), (128, 128, 128));
        assert!(annotated_png(&dir.path().join("missing.png"), &marks, 100).is_err());
    }
}
