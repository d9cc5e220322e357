//! Locating the apex in one region: OpenCV's normalised cross-correlation
//! (TM_CCOEFF_NORMED), a 2-D quadratic fit of the score peak, and a local
//! edge fit at the apex.

use opencv::core::{Mat, MatTraitConst, MatTraitConstManual};
use opencv::imgproc;

use super::TrackError;
use super::image::Gray;

mod apex;
mod axis;
mod below;
mod columns;
mod edge;
#[cfg(test)]
pub(crate) mod tests;
mod uncertainty;

pub use apex::*;
pub use axis::*;
use below::*;
pub use columns::*;
pub use edge::*;
pub(crate) use uncertainty::*;

/// The best match of the template in a search window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Integer position of the template's top-left corner (what `minMaxLoc` gives), px.
    pub integer: [f64; 2],
    /// Sub-pixel position from a 2-D quadratic fit of the 3x3 scores around the peak, px.
    pub quadratic: [f64; 2],
    /// TM_CCOEFF_NORMED at the peak, in [-1, 1].
    pub score: f64,
}

/// Matches `templ` inside `img` restricted to the window `[x0, y0, w, h]`
/// (in `img` coordinates; the window is the set of pixels the template may
/// cover). Positions returned are of the template's top-left corner in `img`.
pub fn match_in_window(img: &Gray, templ: &Gray, win: [usize; 4]) -> Result<Match, TrackError> {
    let [x0, y0, w, h] = win;
    debug_assert!(w >= templ.width && h >= templ.height);
    let sub = img.crop(x0, y0, w, h);
    let a = sub.as_mat().map_err(cv)?;
    let t = templ.as_mat().map_err(cv)?;
    let mut res = Mat::default();
    imgproc::match_template_def(&a, &t, &mut res, imgproc::TM_CCOEFF_NORMED).map_err(cv)?;
    let (rw, rh) = (res.cols() as usize, res.rows() as usize);
    let s: &[f32] = res.data_typed::<f32>().map_err(cv)?;
    // A flat window gives NaN scores (zero variance): treat them as -1.
    let val = |x: usize, y: usize| {
        let v = s[y * rw + x];
        if v.is_finite() { f64::from(v) } else { -1.0 }
    };
    let (mut bx, mut by, mut best) = (0, 0, f64::NEG_INFINITY);
    for y in 0..rh {
        for x in 0..rw {
            let v = val(x, y);
            if v > best {
                best = v;
                bx = x;
                by = y;
            }
        }
    }
    let (dx, dy) = if bx > 0 && by > 0 && bx + 1 < rw && by + 1 < rh {
        let mut f = [[0.0; 3]; 3];
        for (j, row) in f.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = val(bx + i - 1, by + j - 1);
            }
        }
        quadratic_peak(&f)
    } else {
        (0.0, 0.0)
    };
    Ok(Match {
        integer: [(x0 + bx) as f64, (y0 + by) as f64],
        quadratic: [(x0 + bx) as f64 + dx, (y0 + by) as f64 + dy],
        score: best,
    })
}

/// Block average by an integer factor `f` (the image's last partial blocks
/// are dropped), rounded to the nearest grey level: OpenCV's area resize.
pub fn reduce(img: &Gray, f: usize) -> Result<Gray, TrackError> {
    let (w, h) = (img.width / f, img.height / f);
    let mut out = Gray {
        width: w,
        height: h,
        data: vec![0u8; w * h],
        tone: img.tone,
    };
    if w == 0 || h == 0 {
        return Ok(out);
    }
    let src = if img.width == w * f && img.height == h * f {
        std::borrow::Cow::Borrowed(img)
    } else {
        std::borrow::Cow::Owned(img.crop(0, 0, w * f, h * f))
    };
    let a = src.as_mat().map_err(cv)?;
    let mut dst = Mat::default();
    let size = opencv::core::Size::new(w as i32, h as i32);
    imgproc::resize(&a, &mut dst, size, 0.0, 0.0, imgproc::INTER_AREA).map_err(cv)?;
    out.data.copy_from_slice(dst.data_bytes().map_err(cv)?);
    Ok(out)
}

pub(super) fn cv(e: opencv::Error) -> TrackError {
    TrackError::OpenCv(e.to_string())
}

/// Offset of the maximum of the least-squares quadratic through a 3x3 patch
/// `f[row][col]` centred on the integer peak. Falls back to separate 1-D
/// parabolas when the 2-D fit is not a proper maximum; clamped to +-0.5 px
/// (beyond that the integer peak was not the nearest one).
pub fn quadratic_peak(f: &[[f64; 3]; 3]) -> (f64, f64) {
    let col = |i: usize| f[0][i] + f[1][i] + f[2][i];
    let row = |j: usize| f[j][0] + f[j][1] + f[j][2];
    let gx = (col(2) - col(0)) / 6.0;
    let gy = (row(2) - row(0)) / 6.0;
    let hxx = (col(2) + col(0) - 2.0 * col(1)) / 3.0;
    let hyy = (row(2) + row(0) - 2.0 * row(1)) / 3.0;
    let hxy = (f[2][2] - f[2][0] - f[0][2] + f[0][0]) / 4.0;
    let det = hxx * hyy - hxy * hxy;
    let (mut ox, mut oy) = if hxx < 0.0 && det > 0.0 {
        ((-gx * hyy + gy * hxy) / det, (-gy * hxx + gx * hxy) / det)
    } else {
        (f64::NAN, f64::NAN)
    };
    if !(ox.is_finite() && oy.is_finite() && ox.abs() <= 1.0 && oy.abs() <= 1.0) {
        let para = |m: f64, c: f64, p: f64| {
            let d = m + p - 2.0 * c;
            if d < 0.0 { 0.5 * (m - p) / d } else { 0.0 }
        };
        ox = para(f[1][0], f[1][1], f[1][2]);
        oy = para(f[0][1], f[1][1], f[2][1]);
    }
    (ox.clamp(-0.5, 0.5), oy.clamp(-0.5, 0.5))
}
