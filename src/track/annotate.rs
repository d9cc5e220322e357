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
    super::image::opencv_serial().map_err(cv)?;
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

/// The image scaled down (area interpolation) to at most `max_width_px`
/// wide (0: no limit), and the scale applied.
fn scaled(img: Mat, max_width_px: usize) -> Result<(Mat, f64), TrackError> {
    let (w, h) = (img.cols() as f64, img.rows() as f64);
    if max_width_px == 0 || w <= max_width_px as f64 {
        return Ok((img, 1.0));
    }
    let scale = max_width_px as f64 / w;
    let mut out = Mat::default();
    let size = Size::new((w * scale).round() as i32, (h * scale).round() as i32);
    imgproc::resize(&img, &mut out, size, 0.0, 0.0, imgproc::INTER_AREA).map_err(cv)?;
    Ok((out, scale))
}

/// The image as PNG bytes.
fn png(img: &Mat) -> Result<Vec<u8>, TrackError> {
    let mut buf = Vector::<u8>::new();
    let ok = imgcodecs::imencode(".png", img, &mut buf, &Vector::new()).map_err(cv)?;
    if !ok {
        return Err(TrackError::OpenCv("OpenCV could not encode a PNG".into()));
    }
    Ok(buf.as_slice().to_vec())
}

/// Draws `marks` on a colour image and encodes it as PNG, at most
/// `max_width_px` wide.
fn draw_png(img: Mat, marks: &Marks, max_width_px: usize) -> Result<Vec<u8>, TrackError> {
    let (mut out, scale) = scaled(img, max_width_px)?;
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
    png(&out)
}

/// `init.png`: frame `i` of `frames` (the last of the sequence) with what
/// `bulge init` found drawn on it: the clamp's top edge as located (green
/// dots) and the clamp plane (green line over the clamp's width), the
/// opening `2a` at the clamp plane (magenta), the silhouette's sides as
/// located (cyan), the first and last silhouettes' outlines (yellow), the
/// axis (blue), every photo's apex (red crosses), the region `roi_px`
/// (blue) and the template (green), with the values written at the top.
pub fn init_png(
    frames: &super::init::Frames,
    i: usize,
    found: &super::init::Found,
    max_width_px: usize,
) -> Result<Vec<u8>, TrackError> {
    super::image::opencv_serial().map_err(cv)?;
    let img = match frames {
        super::init::Frames::Photos(p) => {
            let path = &p[i];
            let bytes = std::fs::read(path).map_err(|e| TrackError::Unreadable {
                path: path.to_path_buf(),
                reason: e.to_string(),
            })?;
            imgcodecs::imdecode(&Vector::<u8>::from_slice(&bytes), imgcodecs::IMREAD_COLOR)
                .map_err(cv)?
        }
        super::init::Frames::Video { path, indices } => {
            super::video::read_frame_bgr(path, indices[i])?
        }
    };
    let (w, h) = (img.cols() as f64, img.rows() as f64);
    let (mut out, scale) = scaled(img, max_width_px)?;
    let thick = ((out.cols() as f64 / 500.0).round() as i32).max(1);
    let pt = |x: f64, y: f64| {
        Point::new(
            ((x + 0.5) * scale).round() as i32,
            ((y + 0.5) * scale).round() as i32,
        )
    };
    let colour = |b: f64, g: f64, r: f64| Scalar::new(b, g, r, 0.0);
    let (blue, green, red) = (
        colour(220.0, 120.0, 0.0),
        colour(0.0, 200.0, 0.0),
        colour(0.0, 0.0, 255.0),
    );
    let (yellow, cyan, magenta) = (
        colour(0.0, 220.0, 255.0),
        colour(230.0, 220.0, 0.0),
        colour(230.0, 0.0, 230.0),
    );
    let dot = |m: &mut Mat, p: Point, c: Scalar| {
        imgproc::circle(m, p, thick, c, -1, imgproc::LINE_AA, 0).map_err(cv)
    };
    let line = |m: &mut Mat, a: Point, b: Point, c: Scalar| {
        imgproc::line(m, a, b, c, thick, imgproc::LINE_AA, 0).map_err(cv)
    };
    let every = |n: usize| (n / 150).max(1);
    for o in &found.outlines_px {
        for p in o.iter().step_by(every(o.len())) {
            dot(&mut out, pt(p[0], p[1]), yellow)?;
        }
    }
    for p in found
        .clamp_points_px
        .iter()
        .step_by(every(found.clamp_points_px.len()))
    {
        dot(&mut out, pt(p[0], p[1]), green)?;
    }
    for p in &found.side_points_px {
        dot(&mut out, pt(p[0], p[1]), cyan)?;
    }
    let (x0, c) = (found.axis_x_px.value, found.clamp_row_px.value);
    let half = found
        .clamp_half_width_px
        .or(found.radius_px.map(|a| 1.2 * a.value))
        .unwrap_or(0.25 * w);
    line(&mut out, pt(x0 - half, c), pt(x0 + half, c), green)?;
    let top = found.apexes_px.iter().map(|a| a[1]).fold(c, f64::min);
    line(&mut out, pt(x0, top - 0.05 * h), pt(x0, c), blue)?;
    if let Some(a) = found.radius_px {
        let a = a.value;
        line(&mut out, pt(x0 - a, c), pt(x0 + a, c), magenta)?;
        let tick = 0.02 * h;
        line(
            &mut out,
            pt(x0 - a, c - tick),
            pt(x0 - a, c + tick),
            magenta,
        )?;
        line(
            &mut out,
            pt(x0 + a, c - tick),
            pt(x0 + a, c + tick),
            magenta,
        )?;
    }
    let arm = 3 * thick + 2;
    for a in &found.apexes_px {
        let p = pt(a[0], a[1]);
        line(
            &mut out,
            Point::new(p.x - arm, p.y),
            Point::new(p.x + arm, p.y),
            red,
        )?;
        line(
            &mut out,
            Point::new(p.x, p.y - arm),
            Point::new(p.x, p.y + arm),
            red,
        )?;
    }
    let rect = |r: [i64; 4]| {
        let a = pt(r[0] as f64 - 0.5, r[1] as f64 - 0.5);
        let b = pt((r[0] + r[2]) as f64 - 0.5, (r[1] + r[3]) as f64 - 0.5);
        Rect::new(a.x, a.y, (b.x - a.x).max(1), (b.y - a.y).max(1))
    };
    imgproc::rectangle(
        &mut out,
        rect(found.layout.roi_px),
        blue,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    imgproc::rectangle(
        &mut out,
        rect(found.layout.template_rect_px),
        green,
        thick,
        imgproc::LINE_AA,
        0,
    )
    .map_err(cv)?;
    let mut lines = vec![format!(
        "clamp row {:.2} +- {:.2} px   axis {:.2} px",
        c, found.clamp_row_px.std, x0
    )];
    if let Some(a) = found.radius_px {
        lines.push(format!(
            "2a = {:.2} +- {:.2} px: {:.4e} m/px",
            2.0 * a.value,
            2.0 * a.std,
            found.metres_per_pixel.value
        ));
    }
    if let Some(e) = found.elevation_deg {
        lines.push(format!("elevation {:.2} +- {:.2} deg", e.value, e.std));
    }
    let font = (out.cols() as f64 / 1100.0).max(0.4);
    for (k, text) in lines.iter().enumerate() {
        let at = Point::new(8, ((k + 1) as f64 * 26.0 * font / 0.7) as i32);
        for (c, t) in [
            (colour(255.0, 255.0, 255.0), thick + 2),
            (colour(0.0, 0.0, 0.0), thick),
        ] {
            imgproc::put_text(
                &mut out,
                text,
                at,
                imgproc::FONT_HERSHEY_SIMPLEX,
                font,
                c,
                t,
                imgproc::LINE_AA,
                false,
            )
            .map_err(cv)?;
        }
    }
    png(&out)
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
            tone: crate::track::image::Tone::LINEAR,
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
