//! Drawing one frame: the scene's light (background texture, bubble, clamp
//! fixture and ring face, the look's extras), the bubble's exact pixel
//! coverage (its outline rasterised by signed-area accumulation), then the
//! lens's blur and distortion, the exposure, sensor noise and the tone curve.

use super::*;

/// Grey levels of the scene.
const BACKGROUND: f64 = 190.0;
const BUBBLE: f64 = 72.0;
const FIXTURE: f64 = 38.0;
const FLANGE: f64 = 58.0;

/// Renders one frame; `noise_seed` makes the sensor noise reproducible.
pub fn render(scene: &Scene, s: &Silhouette, d: &Degradation, noise_seed: u64) -> Gray {
    let (w, h) = (scene.width, scene.height);
    let cov = coverage(scene, s);
    let apex = scene.apex_px(s);
    let a_px = scene.radius_m / scene.metres_per_pixel;
    let h_px = s.height_m() / scene.metres_per_pixel;
    // Separable tables for the plane waves: sin(kx x + ky y + p).
    // (amp sin(kx x + p), amp cos(kx x + p), sin(ky y), cos(ky y)) per wave.
    type WaveTables = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);
    let tables: Vec<WaveTables> = scene
        .waves
        .iter()
        .map(|&(amp, kx, ky, p)| {
            let sx = (0..w).map(|x| amp * (kx * x as f64 + p).sin()).collect();
            let cx = (0..w).map(|x| amp * (kx * x as f64 + p).cos()).collect();
            let sy = (0..h).map(|y| (ky * y as f64).sin()).collect();
            let cy = (0..h).map(|y| (ky * y as f64).cos()).collect();
            (sx, cx, sy, cy)
        })
        .collect();
    let mut grain = Rng::new(scene.grain_seed);
    let mut fixture_half = 1.25 * a_px;
    let flange_rows = (0.025 * h as f64).max(2.0);
    // The fixture's top face, per column: its back and front edges (the
    // clamp row itself for a level camera).
    let (fix_back, fix_front) = match scene.pinhole() {
        Some(p) => {
            let (b, f, half) = pinhole::fixture_rows(scene, &p);
            fixture_half = half;
            (b, f)
        }
        None => look::fixture_rows(scene, fixture_half),
    };
    let highlight = look::Highlight::new(scene, s);
    let lk = scene.look;
    let tone = lk.response;
    let light = |v: f64| 255.0 * tone.to_linear(v.clamp(0.0, 255.0) / 255.0);
    let encode = |l: f64| 255.0 * tone.encode(l.max(0.0) / 255.0);
    let level = |v: f64, default: f64| if v > 0.0 { v } else { default };
    let background = level(lk.background_grey, BACKGROUND);
    let bubble = level(lk.bubble_grey, BUBBLE);
    let face = level(lk.ring_face_grey, FLANGE);
    let (face_light, fixture_light) = (light(face), light(FIXTURE));
    let mut img = vec![0.0f64; w * h];
    for y in 0..h {
        let yf = y as f64;
        for x in 0..w {
            let xf = x as f64;
            // Background: smooth gradient, plane waves, fixed grain.
            let mut bg = background + 12.0 * (xf / w as f64 - 0.5) - 8.0 * (yf / h as f64 - 0.5);
            for t in &tables {
                bg += t.0[x] * t.3[y] + t.1[x] * t.2[y];
            }
            bg += 1.5 * (grain.uniform() - 0.5) * 2.0;
            if lk.clutter {
                bg = scene.extras.clutter(bg, xf, yf);
            }
            // Fixture below the clamp plane (pixel-exact vertical coverage).
            let below = ((yf + 0.5) - fix_back[x]).clamp(0.0, 1.0);
            let in_fixture = ((fixture_half + 0.5) - (xf - scene.axis_x_px).abs()).clamp(0.0, 1.0);
            let fix_light = if yf - fix_front[x] < flange_rows {
                face_light
            } else {
                fixture_light
            };
            let fixture_cov = below * in_fixture;
            // Levels are the encoded values of the scene's light; a pixel
            // partly covered sums the light of its parts.
            let base = light(bg) * (1.0 - fixture_cov) + fix_light * fixture_cov;
            // Bubble: matte shading darker towards the rim, a soft highlight
            // below the apex.
            let c = cov[y * w + x];
            let mut v = if c > 0.0 {
                let u = (xf - apex[0]) / a_px;
                let hy = (yf - (apex[1] + 0.45 * h_px.max(0.1 * a_px))) / (0.35 * a_px);
                let mut shade =
                    bubble * (1.0 - 0.3 * u * u) + 14.0 * (-(u * u / 0.18 + hy * hy)).exp();
                if let Some(hl) = &highlight {
                    shade += hl.at(xf, yf);
                }
                base * (1.0 - c) + light(shade) * c
            } else {
                base
            };
            if lk.uneven_light != 0.0 {
                v *= scene.extras.light(xf, yf);
            }
            // Light from one side: brighter across the dome's columns on
            // one side of the axis, and behind it.
            if lk.side_light != 0.0 {
                v *= 1.0 + lk.side_light * ((xf - scene.axis_x_px) / a_px).clamp(-1.0, 1.0);
            }
            if lk.vignetting > 0.0 {
                v *= vignette(lk.vignetting, w, h, xf, yf);
            }
            img[y * w + x] = v;
        }
    }
    // The lens and the motion spread the light: the Gaussian of the lens's
    // aberrations, then a defocus disc, then a motion streak.
    if d.blur_px > 0.0 {
        gaussian_blur(&mut img, w, h, d.blur_px);
    }
    if lk.defocus_px > 0.0 {
        Psf::pillbox(lk.defocus_px).apply(&mut img, w, h);
    }
    if lk.motion_px > 0.0 {
        Psf::line(lk.motion_px, lk.motion_deg).apply(&mut img, w, h);
    }
    // The lens's distortion moves the light (a map of the image).
    if let Some(l) = &lk.lens {
        img = lens::distort_light(&img, w, h, l);
    }
    // The exposure scales the light; the tone curve encodes it. The sensor
    // noise is added to the encoded values: photon noise, whose deviation
    // grows as the square root of the light, comes out of the sRGB curve
    // (a 1/2.4 power) nearly even across grey levels.
    let mut rng = Rng::new(noise_seed);
    let data = img
        .iter()
        .map(|&l| {
            let n = if d.noise_grey > 0.0 {
                d.noise_grey * rng.normal()
            } else {
                0.0
            };
            (encode(l * d.gain) + n).round().clamp(0.0, 255.0) as u8
        })
        .collect();
    Gray {
        width: w,
        height: h,
        data,
        tone: super::super::image::Tone::of(tone),
    }
}

/// Exact area coverage of the bubble's side silhouette, per pixel, in [0, 1].
pub fn coverage(scene: &Scene, s: &Silhouette) -> Vec<f64> {
    if let Some(p) = scene.pinhole() {
        return rasterise(
            scene.width,
            scene.height,
            &pinhole::outline_px(scene, &p, s),
        );
    }
    if scene.look.elevation_deg != 0.0 {
        return rasterise(scene.width, scene.height, &look::outline_px(scene, s));
    }
    let dense = densify(s, 0.25 * scene.metres_per_pixel);
    // Raster coordinates: cell i covers [i, i + 1), so u = x + 0.5.
    let to_raster = |rho: f64, z: f64| {
        (
            scene.axis_x_px + rho / scene.metres_per_pixel + 0.5,
            scene.clamp_row_px - z / scene.metres_per_pixel + 0.5,
        )
    };
    let mut poly: Vec<(f64, f64)> = Vec::with_capacity(2 * dense.len());
    for &(r, z) in &dense {
        poly.push(to_raster(r, z));
    }
    for &(r, z) in dense.iter().rev() {
        poly.push(to_raster(-r, z));
    }
    rasterise(scene.width, scene.height, &poly)
}

/// Exact area coverage, per pixel in [0, 1], of a closed polygon in raster
/// coordinates (cell `i` covers `[i, i + 1)`: `u = x + 0.5`).
fn rasterise(w: usize, h: usize, poly: &[(f64, f64)]) -> Vec<f64> {
    let mut acc = vec![0.0f64; w * h + w + 4];
    for i in 0..poly.len() {
        let p0 = poly[i];
        let p1 = poly[(i + 1) % poly.len()];
        let clampx = |p: (f64, f64)| (p.0.clamp(0.0, w as f64 - 1.001), p.1);
        draw_line(&mut acc, w, h, clampx(p0), clampx(p1));
    }
    let mut out = vec![0.0; w * h];
    let mut run = 0.0;
    for (o, a) in out.iter_mut().zip(&acc) {
        run += a;
        *o = run.abs().min(1.0);
    }
    out
}

/// The profile as (rho, z) points, pole first, with segments no longer than
/// `max_seg_m`, by centripetal-free (uniform) Catmull-Rom interpolation; the
/// pole is made smooth by mirroring (the point before the pole is
/// `(-rho_1, z_1)`).
pub(super) fn densify(s: &Silhouette, max_seg_m: f64) -> Vec<(f64, f64)> {
    let n = s.rho_m.len();
    let p = |i: isize| -> (f64, f64) {
        if i < 0 {
            let j = (-i) as usize;
            (-s.rho_m[j.min(n - 1)], s.z_m[j.min(n - 1)])
        } else if (i as usize) >= n {
            let (a, b) = (
                (s.rho_m[n - 1], s.z_m[n - 1]),
                (s.rho_m[n - 2], s.z_m[n - 2]),
            );
            (2.0 * a.0 - b.0, 2.0 * a.1 - b.1)
        } else {
            (s.rho_m[i as usize], s.z_m[i as usize])
        }
    };
    let mut out = vec![p(0)];
    for i in 0..n as isize - 1 {
        let (p0, p1, p2, p3) = (p(i - 1), p(i), p(i + 1), p(i + 2));
        let len = ((p2.0 - p1.0).powi(2) + (p2.1 - p1.1).powi(2)).sqrt();
        let m = ((len / max_seg_m).ceil() as usize).max(1);
        for k in 1..=m {
            let t = k as f64 / m as f64;
            let cr = |a: f64, b: f64, c: f64, d: f64| {
                0.5 * (2.0 * b
                    + (-a + c) * t
                    + (2.0 * a - 5.0 * b + 4.0 * c - d) * t * t
                    + (-a + 3.0 * b - 3.0 * c + d) * t * t * t)
            };
            out.push((cr(p0.0, p1.0, p2.0, p3.0), cr(p0.1, p1.1, p2.1, p3.1)));
        }
    }
    out
}

/// The envelope of a family of latitudes in one image column: the least
/// first value and the greatest second value of `rows(rho, z)` (`None`
/// where a latitude misses the column) over the meridian `dense`
/// ([`densify`]), each refined between the neighbours of the best sample
/// on the meridian's polyline by golden-section search. The samples alone
/// fall short: from a camera near the clamp plane a latitude is a thin
/// ellipse, and near the sides the best one in a column is the highest
/// that still reaches it, so the samples' envelope is a staircase inside
/// the outline (level at 0.25 m, about 0.05 px inside on each side with
/// samples half a pixel apart: 0.02 % of the opening's width).
pub(super) fn envelope(
    dense: &[(f64, f64)],
    rows: impl Fn(f64, f64) -> Option<(f64, f64)>,
) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = ((f64::INFINITY, 0usize), (f64::NEG_INFINITY, 0usize));
    for (i, &(r, z)) in dense.iter().enumerate() {
        if let Some((a, b)) = rows(r, z) {
            if a < lo.0 {
                lo = (a, i);
            }
            if b > hi.0 {
                hi = (b, i);
            }
        }
    }
    if !lo.0.is_finite() || dense.len() < 2 {
        return lo.0.is_finite().then_some((lo.0, hi.0));
    }
    let last = (dense.len() - 1) as f64;
    let at = |t: f64| {
        let i = (t.floor().max(0.0) as usize).min(dense.len() - 2);
        let s = t - i as f64;
        let (p, q) = (dense[i], dense[i + 1]);
        rows(p.0 + s * (q.0 - p.0), p.1 + s * (q.1 - p.1))
    };
    // 60 sections shrink the bracket below 1e-12 of its width.
    let least = |i: usize, key: &dyn Fn(f64) -> f64| {
        let i = i as f64;
        let (lo, hi) = ((i - 1.0).max(0.0), (i + 1.0).min(last));
        crate::numerics::golden::golden_section(lo, hi, 60, |t| (key(t), ())).score
    };
    let top = least(lo.1, &|t| at(t).map_or(f64::INFINITY, |v| v.0));
    let bottom = -least(hi.1, &|t| at(t).map_or(f64::INFINITY, |v| -v.1));
    Some((top.min(lo.0), bottom.max(hi.0)))
}

/// Adds the signed area of segment p0-p1 (raster coordinates) to the
/// accumulation buffer (R. Levien's font-rs algorithm); a running sum of the
/// buffer gives each cell's coverage.
fn draw_line(acc: &mut [f64], w: usize, h: usize, p0: (f64, f64), p1: (f64, f64)) {
    if (p0.1 - p1.1).abs() <= 1e-12 {
        return;
    }
    let (dir, p0, p1) = if p0.1 < p1.1 {
        (1.0, p0, p1)
    } else {
        (-1.0, p1, p0)
    };
    let dxdy = (p1.0 - p0.0) / (p1.1 - p0.1);
    let mut x = p0.0;
    if p0.1 < 0.0 {
        x -= p0.1 * dxdy;
    }
    let y_start = p0.1.max(0.0) as usize;
    let y_end = (h as f64).min(p1.1.ceil()).max(0.0) as usize;
    for y in y_start..y_end {
        let ls = y * w;
        let dy = ((y + 1) as f64).min(p1.1) - (y as f64).max(p0.1);
        let xnext = x + dxdy * dy;
        let d = dy * dir;
        let (x0, x1) = if x < xnext { (x, xnext) } else { (xnext, x) };
        let x0f = x0.floor();
        let x0i = x0f as usize;
        let x1c = x1.ceil();
        let x1i = x1c as usize;
        if x1i <= x0i + 1 {
            let xmf = 0.5 * (x + xnext) - x0f;
            acc[ls + x0i] += d - d * xmf;
            acc[ls + x0i + 1] += d * xmf;
        } else {
            let s = 1.0 / (x1 - x0);
            let x0frac = x0 - x0f;
            let a0 = 0.5 * s * (1.0 - x0frac) * (1.0 - x0frac);
            let x1frac = x1 - x1c + 1.0;
            let am = 0.5 * s * x1frac * x1frac;
            acc[ls + x0i] += d * a0;
            if x1i == x0i + 2 {
                acc[ls + x0i + 1] += d * (1.0 - a0 - am);
            } else {
                let a1 = s * (1.5 - x0frac);
                acc[ls + x0i + 1] += d * (a1 - a0);
                for xi in x0i + 2..x1i - 1 {
                    acc[ls + xi] += d * s;
                }
                let a2 = a1 + (x1i - x0i - 3) as f64 * s;
                acc[ls + x1i - 1] += d * (1.0 - a2 - am);
            }
            acc[ls + x1i] += d * am;
        }
        x = xnext;
    }
}

/// Separable Gaussian blur with replicated borders, radius ceil(4 sigma).
pub fn gaussian_blur(img: &mut [f64], w: usize, h: usize, sigma: f64) {
    let (r, k) = gaussian_kernel(sigma);
    // Each pass adds the taps in order to every pixel of a row at once
    // (a pixel's sum is formed in the same order as tap by tap, so the
    // result does not depend on the loop order), reading rows whole.
    let mut tmp = vec![0.0; w * h];
    for (src, dst) in img.chunks_exact(w).zip(tmp.chunks_exact_mut(w)) {
        for (j, &kv) in k.iter().enumerate() {
            add_shifted(dst, src, j as isize - r, kv);
        }
    }
    img.fill(0.0);
    for (y, dst) in img.chunks_exact_mut(w).enumerate() {
        for (j, &kv) in k.iter().enumerate() {
            let yi = (y as isize + j as isize - r).clamp(0, h as isize - 1) as usize;
            for (d, s) in dst.iter_mut().zip(&tmp[yi * w..(yi + 1) * w]) {
                *d += kv * s;
            }
        }
    }
}

/// The normalised Gaussian of `sigma` px sampled at the integers within
/// `r = ceil(4 sigma)`: `(r, weights from -r to r)`.
fn gaussian_kernel(sigma: f64) -> (isize, Vec<f64>) {
    let r = (4.0 * sigma).ceil() as isize;
    let k: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = k.iter().sum();
    (r, k.iter().map(|v| v / sum).collect())
}

/// `dst[x] += kv * src[clamp(x + shift)]` over a row, the border value
/// replicated beyond the row's ends.
pub(super) fn add_shifted(dst: &mut [f64], src: &[f64], shift: isize, kv: f64) {
    let w = dst.len() as isize;
    // x + shift within 0..w for x in lo..hi
    let lo = (-shift).clamp(0, w) as usize;
    let hi = (w - shift).clamp(0, w) as usize;
    let (first, last) = (src[0], src[src.len() - 1]);
    for d in &mut dst[..lo] {
        *d += kv * first;
    }
    if lo < hi {
        let s0 = (lo as isize + shift) as usize;
        for (d, s) in dst[lo..hi].iter_mut().zip(&src[s0..s0 + (hi - lo)]) {
            *d += kv * s;
        }
    }
    for d in &mut dst[hi.max(lo)..] {
        *d += kv * last;
    }
}

#[cfg(test)]
mod tests {
    use super::look::Psf;
    use super::*;

    /// A test image with structure on every scale.
    fn image(w: usize, h: usize) -> Vec<f64> {
        let mut rng = Rng::new(7);
        (0..w * h)
            .map(|i| (i % w) as f64 * 0.7 + (i / w) as f64 * 1.3 + 40.0 * rng.uniform())
            .collect()
    }

    /// The direct sum at every pixel, border values replicated:
    /// `out(x, y) = sum over taps of kv * img(clamp(x + sx), clamp(y + sy))`,
    /// the taps in order.
    fn direct(img: &[f64], w: usize, h: usize, taps: &[(isize, isize, f64)]) -> Vec<f64> {
        let (wi, hi) = (w as isize, h as isize);
        let mut out = vec![0.0; w * h];
        for y in 0..hi {
            for x in 0..wi {
                let mut acc = 0.0;
                for &(sx, sy, kv) in taps {
                    let xs = (x + sx).clamp(0, wi - 1);
                    let ys = (y + sy).clamp(0, hi - 1);
                    acc += kv * img[(ys * wi + xs) as usize];
                }
                out[(y * wi + x) as usize] = acc;
            }
        }
        out
    }

    /// The row-wise blurs give the direct per-pixel sums bit for bit
    /// (each pixel's sum is formed in the same order), on images narrower
    /// and wider than the kernels.
    #[test]
    fn row_wise_blurs_equal_the_direct_sums() {
        for (w, h) in [(3, 2), (23, 17), (64, 9)] {
            let img = image(w, h);
            for sigma in [0.6f64, 1.5, 2.7] {
                let (r, k) = gaussian_kernel(sigma);
                let along = |vertical: bool| -> Vec<(isize, isize, f64)> {
                    k.iter()
                        .enumerate()
                        .map(|(j, &kv)| {
                            let s = j as isize - r;
                            if vertical { (0, s, kv) } else { (s, 0, kv) }
                        })
                        .collect()
                };
                let expected = direct(&direct(&img, w, h, &along(false)), w, h, &along(true));
                let mut got = img.clone();
                gaussian_blur(&mut got, w, h, sigma);
                assert_eq!(got, expected, "{w}x{h}, sigma {sigma}");
            }
            for psf in [Psf::pillbox(2.3), Psf::line(3.5, 30.0)] {
                let n = 2 * psf.r + 1;
                let r = psf.r as isize;
                let taps: Vec<(isize, isize, f64)> = (0..n * n)
                    .filter(|&i| psf.k[i] != 0.0)
                    .map(|i| (r - (i % n) as isize, r - (i / n) as isize, psf.k[i]))
                    .collect();
                let expected = direct(&img, w, h, &taps);
                let mut got = img.clone();
                psf.apply(&mut got, w, h);
                assert_eq!(got, expected, "{w}x{h}");
            }
        }
    }
}
