//! Synthetic side-view photos of an inflated membrane with known truth.
//!
//! The bubble's silhouette seen from the side (orthographic camera looking
//! along the clamp plane) is exactly its meridian profile `(rho(s), z(s))`
//! mirrored about the axis. It is drawn as a closed polygon (the profile
//! densified by Catmull-Rom interpolation to segments of at most 0.25 px) with
//! the exact area coverage of every pixel (signed-area accumulation, as in
//! font rasterisers), over a textured background and a dark clamp fixture,
//! then blurred (Gaussian), given an exposure gain, sensor noise and 8-bit
//! quantisation.
//!
//! Image coordinates: the centre of the top-left pixel is (0, 0), x to the
//! right, y down (OpenCV's convention); pixel (i, j) covers
//! `[i - 0.5, i + 0.5) x [j - 0.5, j + 0.5)`.

use std::path::Path;

use super::TrackError;
use super::image::{Encoding, Gray};
use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num};

pub mod lens;
mod look;
pub mod pinhole;
pub mod sweep;
pub mod trial;
pub use look::{Framing, Look, Psf, vignette};

/// A meridian profile, pole first: `rho_m` is the current radial position and
/// `z_m` the height above the clamp plane; the last point is on the rim
/// (`z = 0`, `rho = a`).
#[derive(Debug, Clone, PartialEq)]
pub struct Silhouette {
    /// Radial positions, m (0 at the pole).
    pub rho_m: Vec<f64>,
    /// Heights above the clamp plane, m.
    pub z_m: Vec<f64>,
}

impl Silhouette {
    /// A spherical cap of base radius `a` and apex height `h` (`h = 0`: flat),
    /// `n` points from pole to rim.
    pub fn spherical_cap(a: f64, h: f64, n: usize) -> Self {
        let n = n.max(3);
        if h <= 0.0 {
            let rho = (0..n).map(|i| a * i as f64 / (n - 1) as f64).collect();
            return Silhouette {
                rho_m: rho,
                z_m: vec![0.0; n],
            };
        }
        let r = (a * a + h * h) / (2.0 * h);
        let theta = 2.0 * (h / a).atan();
        let mut rho = Vec::with_capacity(n);
        let mut z = Vec::with_capacity(n);
        for i in 0..n {
            let phi = theta * i as f64 / (n - 1) as f64;
            rho.push(r * phi.sin());
            z.push(h - r * (1.0 - phi.cos()));
        }
        *z.last_mut().expect("n >= 3") = 0.0;
        *rho.last_mut().expect("n >= 3") = a;
        Silhouette { rho_m: rho, z_m: z }
    }

    /// Apex height, m.
    pub fn height_m(&self) -> f64 {
        self.z_m[0]
    }
}

/// Where the specimen is in the picture and what the picture looks like
/// apart from the bubble (fixed for a whole sequence).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Image width, px.
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// Scale, m per px.
    pub metres_per_pixel: f64,
    /// Column of the bubble's axis, px (image coordinates).
    pub axis_x_px: f64,
    /// Row of the clamp plane, px (image coordinates).
    pub clamp_row_px: f64,
    /// Free radius of the specimen, m.
    pub radius_m: f64,
    /// Background texture: (amplitude, kx, ky, phase) of a few plane waves.
    waves: Vec<(f64, f64, f64, f64)>,
    /// Seed of the fixed fine grain of the background.
    grain_seed: u64,
    /// What the photos show besides the plain side view.
    pub look: Look,
    /// Where the clutter and the light are (drawn once per scene).
    extras: look::Extras,
}

impl Scene {
    /// The default framing: the clamped disc spans 70 % of the width, the
    /// clamp plane sits at 80 % of the height; the axis and the clamp plane
    /// are placed at seeded sub-pixel offsets so that the apex is never on a
    /// pixel centre by construction.
    pub fn new(width: usize, height: usize, radius_m: f64, seed: u64) -> Self {
        let mut rng = Rng::new(seed ^ 0x5CE9E);
        let mpp = 2.0 * radius_m / (0.7 * width as f64);
        let axis_x_px = (width as f64 / 2.0).floor() + rng.uniform() - 0.5;
        let clamp_row_px = (0.8 * height as f64).floor() + rng.uniform() - 0.5;
        let scale = width as f64;
        let waves = (0..6)
            .map(|_| {
                let lambda = scale / (8.0 + 16.0 * rng.uniform());
                let dir = std::f64::consts::TAU * rng.uniform();
                let k = std::f64::consts::TAU / lambda;
                (
                    1.5 + 1.0 * rng.uniform(),
                    k * dir.cos(),
                    k * dir.sin(),
                    std::f64::consts::TAU * rng.uniform(),
                )
            })
            .collect();
        Scene {
            width,
            height,
            metres_per_pixel: mpp,
            axis_x_px,
            clamp_row_px,
            radius_m,
            waves,
            grain_seed: rng.next_u64(),
            look: Look::default(),
            extras: look::Extras::default(),
        }
    }

    /// Apex position of a silhouette in image coordinates, px.
    /// With the camera raised by an elevation angle `e`, the pole's
    /// projection: `h cos e` above the clamp ring's centre.
    /// With a pinhole camera, the silhouette's top (the grazing ray).
    pub fn apex_px(&self, s: &Silhouette) -> [f64; 2] {
        if let Some(p) = self.pinhole() {
            return [
                self.axis_x_px,
                pinhole::top_row(&p, s, self.metres_per_pixel),
            ];
        }
        let up = if self.look.elevation_deg == 0.0 {
            s.height_m()
        } else {
            s.height_m() * self.look.elevation_deg.to_radians().cos()
        };
        [
            self.axis_x_px,
            self.clamp_row_px - up / self.metres_per_pixel,
        ]
    }

    /// The tallest bubble (m) that leaves a margin of 10 % of the image
    /// height above the apex.
    pub fn max_height_m(&self) -> f64 {
        (self.clamp_row_px - 0.1 * self.height as f64) * self.metres_per_pixel
    }
}

/// What the camera adds to the ideal picture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Degradation {
    /// Gaussian blur standard deviation, px (0: none).
    pub blur_px: f64,
    /// Sensor noise standard deviation, grey levels (0: none).
    pub noise_grey: f64,
    /// Exposure gain applied to the whole frame (1: none).
    pub gain: f64,
}

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
            let fix_level = if yf - fix_front[x] < flange_rows {
                face
            } else {
                FIXTURE
            };
            let fixture_cov = below * in_fixture;
            // Levels are the encoded values of the scene's light; a pixel
            // partly covered sums the light of its parts.
            let base = light(bg) * (1.0 - fixture_cov) + light(fix_level) * fixture_cov;
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
        tone: super::image::Tone::of(tone),
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
fn densify(s: &Silhouette, max_seg_m: f64) -> Vec<(f64, f64)> {
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
    let r = (4.0 * sigma).ceil() as isize;
    let k: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = k.iter().sum();
    let k: Vec<f64> = k.iter().map(|v| v / sum).collect();
    let mut tmp = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for (j, kv) in k.iter().enumerate() {
                let xi = (x as isize + j as isize - r).clamp(0, w as isize - 1) as usize;
                acc += kv * img[y * w + xi];
            }
            tmp[y * w + x] = acc;
        }
    }
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for (j, kv) in k.iter().enumerate() {
                let yi = (y as isize + j as isize - r).clamp(0, h as isize - 1) as usize;
                acc += kv * tmp[yi * w + x];
            }
            img[y * w + x] = acc;
        }
    }
}

/// A synthetic sequence: the camera, the specimen and the degradations.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceSpec {
    /// Image width, px.
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// Seed of the scene placement, texture and noise.
    pub seed: u64,
    /// Gaussian blur, px.
    pub blur_px: f64,
    /// Sensor noise, grey levels.
    pub noise_grey: f64,
    /// Exposure drift: the gain goes linearly from `1 - drift` to `1 + drift`.
    pub drift: f64,
    /// File format.
    pub encoding: Encoding,
    /// The specimen written into `experiment.toml`.
    pub specimen: Specimen,
    /// The window written into `experiment.toml` (a `[window]` table when
    /// it is not the circle).
    pub window: crate::experiment::Window,
    /// Where the specimen is in the picture.
    pub framing: Framing,
    /// What the photos show besides the plain side view.
    pub look: Look,
}

impl SequenceSpec {
    /// A `width` x `height` sequence of the latex disc of the paper
    /// (a = 37.5 mm, t = 0.35 mm, nu = 0.45, flat) with the default
    /// framing, the plain look, the circular window and an exposure drift
    /// of 3 %: the camera of the tests and benchmarks.
    pub fn plain(
        width: usize,
        height: usize,
        seed: u64,
        blur_px: f64,
        noise_grey: f64,
        encoding: Encoding,
    ) -> SequenceSpec {
        SequenceSpec {
            width,
            height,
            seed,
            blur_px,
            noise_grey,
            drift: 0.03,
            encoding,
            specimen: Specimen {
                radius_m: 0.0375,
                thickness_m: 0.00035,
                poisson: 0.45,
                prebulge_height_m: 0.0,
            },
            window: Default::default(),
            framing: Default::default(),
            look: Default::default(),
        }
    }

    /// The scene of this sequence drawing `frames` (see [`Scene::framed`]).
    pub fn scene(&self, frames: &[SynthFrame]) -> Result<Scene, String> {
        let s: Vec<&Silhouette> = frames.iter().map(|f| &f.silhouette).collect();
        Scene::for_frames(
            self.width,
            self.height,
            self.specimen.radius_m,
            self.seed,
            &self.framing,
            self.look,
            &s,
        )
    }
}

/// A random camera for `seed`: a size of `sizes`, scale 0.05-0.12 mm/px,
/// the disc 35-65 % of the width (its radius follows, the thickness in
/// proportion), blur 0.8-2 px, noise 1-4 grey levels, JPEG quality 80-95,
/// the framing random ([`Framing::random`]) and the look given.
pub fn random_camera(seed: u64, sizes: &[(usize, usize)], look: Look) -> SequenceSpec {
    let mut rng = Rng::new(seed ^ 0x1A17);
    let (w, h) = sizes[(rng.next_u64() % sizes.len() as u64) as usize];
    let mpp = 5e-5 + 7e-5 * rng.uniform();
    let f = 0.35 + 0.3 * rng.uniform();
    let a = f * w as f64 * mpp / 2.0;
    let q = 80 + (rng.next_u64() % 16) as u8;
    SequenceSpec {
        width: w,
        height: h,
        seed,
        blur_px: 0.8 + 1.2 * rng.uniform(),
        noise_grey: 1.0 + 3.0 * rng.uniform(),
        drift: 0.03,
        encoding: Encoding::Jpeg(q),
        specimen: Specimen {
            radius_m: a,
            thickness_m: 0.00035 * a / 0.0375,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        },
        window: Default::default(),
        framing: Framing {
            metres_per_pixel: Some(mpp),
            random: true,
            ..Framing::default()
        },
        look,
    }
}

/// One frame to draw: the pressure and the bubble's profile at it.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthFrame {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Meridian profile (pole first).
    pub silhouette: Silhouette,
}

/// The frame of the exact axisymmetric bubble of `material` on `specimen` at
/// `pressure_pa` (default [`crate::axisym::Options`]), labelled `label_pa`
/// in `pressure.csv` (the pressure itself, or a gauge's reading of it).
pub fn axisym_frame(
    material: &crate::material::Material,
    specimen: &Specimen,
    pressure_pa: f64,
    label_pa: f64,
) -> Result<SynthFrame, crate::axisym::AxisymError> {
    let sol = crate::axisym::solve_pressure(
        material,
        specimen,
        pressure_pa,
        &crate::axisym::Options::default(),
    )?;
    Ok(SynthFrame {
        pressure_pa: label_pa,
        silhouette: Silhouette {
            rho_m: sol.profile.rho_m,
            z_m: sol.profile.z_m,
        },
    })
}

/// The truth of one written frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// File name inside `photos/`.
    pub file: String,
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height above the clamp plane, m.
    pub height_m: f64,
    /// Apex column, px.
    pub apex_x_px: f64,
    /// Apex row, px.
    pub apex_y_px: f64,
}

/// What [`write_sequence`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// The truth per frame.
    pub truth: Vec<Truth>,
    /// Total bytes of the photos.
    pub photo_bytes: usize,
    /// The scene.
    pub scene: Scene,
    /// The region and template written into `experiment.toml`.
    pub layout: Layout,
}

/// Template size for an image width: 10 % by 5 % of the width (even).
pub fn template_size(width: usize) -> (usize, usize) {
    let tw = ((0.1 * width as f64 / 2.0).round() as usize * 2).max(16);
    (tw, (tw / 2).max(8))
}

/// Photo `i` of a sequence of `n` (the same pixels as the file
/// [`write_sequence`] writes, before encoding).
pub fn render_frame(
    scene: &Scene,
    spec: &SequenceSpec,
    n: usize,
    i: usize,
    f: &SynthFrame,
) -> Gray {
    let t = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        0.5
    };
    let d = Degradation {
        blur_px: spec.blur_px,
        noise_grey: spec.noise_grey,
        gain: 1.0 + spec.drift * (2.0 * t - 1.0),
    };
    render(
        scene,
        &f.silhouette,
        &d,
        spec.seed.wrapping_mul(1_000_003).wrapping_add(i as u64 + 1),
    )
}

/// Where tracking looks, as `experiment.toml` says: the region, the template
/// rectangle (around the first frame's apex) and the apex inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// `roi_px`: `[x, y, w, h]`.
    pub roi_px: [i64; 4],
    /// `template_rect_px`: `[x, y, w, h]`.
    pub template_rect_px: [i64; 4],
    /// `apex_in_template_px`.
    pub apex_in_template_px: [f64; 2],
}

impl Layout {
    /// The template (`size` = width, height px) centred on the apex of
    /// photo `reference` and a region three template widths wide covering
    /// every apex with a template's height above and below, inside a photo
    /// of `frame` = (width, height) px.
    pub fn around(
        apexes: &[[f64; 2]],
        reference: usize,
        size: (usize, usize),
        frame: (usize, usize),
    ) -> Layout {
        let (tw, th) = size;
        let [ax0, ay0] = apexes[reference];
        let tx = (ax0 - tw as f64 / 2.0).round() as i64;
        let ty = (ay0 - th as f64 / 2.0).round() as i64;
        let ymin = apexes.iter().map(|a| a[1]).fold(f64::INFINITY, f64::min);
        let ymax = apexes
            .iter()
            .map(|a| a[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let rx = (ax0 - 1.5 * tw as f64).round().max(0.0) as i64;
        let ry = (ymin - th as f64).floor().max(0.0) as i64;
        let rw = ((3 * tw) as i64).min(frame.0 as i64 - rx);
        let rh = ((ymax + th as f64).ceil() as i64 - ry).min(frame.1 as i64 - ry);
        Layout {
            roi_px: [rx, ry, rw, rh],
            template_rect_px: [tx, ty, tw as i64, th as i64],
            apex_in_template_px: [ax0 - tx as f64, ay0 - ty as f64],
        }
    }
}

/// The text of an experiment file for a synthetic sequence; `photos` and
/// `pressure` are the lines saying where the frames and the pressures are
/// (e.g. `dir = "photos"\nglob = "*.png"\n` and `csv = "pressure.csv"\n`).
pub fn experiment_toml(
    spec: &SequenceSpec,
    scene: &Scene,
    layout: &Layout,
    photos: &str,
    pressure: &str,
) -> String {
    let s = spec.specimen;
    let (elevation, elevation_key) = if spec.look.elevation_deg != 0.0 {
        (
            format!(
                "# The camera is {:?} degrees above the clamp plane: clamp_row_px is the row of the\n\
                 # clamp ring's centre, and elevation_deg corrects the heights for it.\n",
                spec.look.elevation_deg
            ),
            format!("elevation_deg = {:?}\n", spec.look.elevation_deg),
        )
    } else {
        (String::new(), String::new())
    };
    let [rx, ry, rw, rh] = layout.roi_px;
    let [tx, ty, tw, th] = layout.template_rect_px;
    format!(
        "# A synthetic experiment written by `bulge synth` (truth in truth.csv).\n\
         # Image coordinates: the centre of the top-left pixel is (0, 0), y down.\n\
         {elevation}[specimen]\nradius_m = {:?}\nthickness_m = {:?}\npoisson = {:?}\nprebulge_height_m = {:?}\n\n\
         [photos]\n{photos}roi_px = [{rx}, {ry}, {rw}, {rh}]\n\
         template_rect_px = [{tx}, {ty}, {tw}, {th}]\nreference_frame = 0\n\
         apex_in_template_px = [{:?}, {:?}]\n\n\
         [camera]\nresponse = {}\n{}{}\n\
         [calibration]\nmetres_per_pixel = {:?}\nclamp_row_px = {:?}\n{elevation_key}\n\
         [pressure]\n{pressure}{}",
        s.radius_m,
        s.thickness_m,
        s.poisson,
        s.prebulge_height_m,
        layout.apex_in_template_px[0],
        layout.apex_in_template_px[1],
        toml::Value::try_from(spec.look.response)
            .map_or_else(|_| "\"srgb\"".into(), |v| v.to_string()),
        spec.look.lens.map_or_else(String::new, |l| lens_toml(&l)),
        if spec.look.camera_distance_m > 0.0 {
            format!(
                "# a pinhole camera this far from the axis, m (elevation_deg: the angle it looks down at the ring's centre)\ndistance_m = {:?}\n",
                spec.look.camera_distance_m
            )
        } else {
            String::new()
        },
        scene.metres_per_pixel,
        scene.clamp_row_px,
        window_toml(&spec.window),
    )
}

/// The lens keys of `[camera]` (the lens the photos were drawn through).
fn lens_toml(l: &super::lens::Lens) -> String {
    let c = l.to_config(None);
    let mut t = toml::to_string(&c).unwrap_or_default();
    if !t.is_empty() {
        t.insert_str(
            0,
            "# the lens the photos were drawn through (as `bulge calibrate` writes it)\n",
        );
    }
    t
}

/// The `[window]` table of a non-circular window (empty for the circle).
fn window_toml(w: &crate::experiment::Window) -> String {
    use crate::experiment::Window;
    match w {
        Window::Circle => String::new(),
        Window::Ellipse { semi_axes_m } => format!(
            "\n[window]\nshape = \"ellipse\"\nsemi_axes_m = [{:?}, {:?}]\n",
            semi_axes_m[0], semi_axes_m[1]
        ),
        Window::Rectangle { length_m, width_m } => format!(
            "\n[window]\nshape = \"rectangle\"\nlength_m = {length_m:?}\nwidth_m = {width_m:?}\n"
        ),
    }
}

/// Renders and writes a whole synthetic experiment into `out`:
/// `photos/frame_NNN.{png,jpg}`, `pressure.csv`, `truth.csv`,
/// `experiment.toml`. Frames are rendered in parallel; every file is written
/// atomically. Fails when the tallest bubble does not fit in the picture.
pub fn write_sequence(
    out: &Path,
    spec: &SequenceSpec,
    frames: &[SynthFrame],
) -> Result<Written, TrackError> {
    use rayon::prelude::*;
    if frames.is_empty() {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: "no frames to draw: give at least one pressure".into(),
        });
    }
    let scene = spec.scene(frames).map_err(|message| TrackError::Config {
        path: out.to_path_buf(),
        message,
    })?;
    let hmax = frames
        .iter()
        .map(|f| f.silhouette.height_m())
        .fold(0.0, f64::max);
    if spec.framing.is_default() && hmax > scene.max_height_m() {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: format!(
                "the tallest bubble ({:.4} m) does not fit in a {}x{} px picture framed for the {:.4} m disc (at most {:.4} m): lower the pressure or use a wider image height",
                hmax,
                spec.width,
                spec.height,
                2.0 * spec.specimen.radius_m,
                scene.max_height_m()
            ),
        });
    }
    // A bubble too small to measure is refused rather than drawn: the
    // tracker's template is at least 32 px wide (so the opening must be as
    // wide), and at its best the apex is found to about 0.03 px, so a
    // tallest bubble under 3 px could not give heights to 1 %.
    let (a_px, h_px) = (
        spec.specimen.radius_m / scene.metres_per_pixel,
        hmax / scene.metres_per_pixel,
    );
    if 2.0 * a_px < 32.0 || h_px < 3.0 {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: format!(
                "the opening is {:.1} px wide and the tallest bubble {h_px:.2} px tall at {:.3e} m per px: the tracker needs an opening of at least 32 px and a bubble of at least 3 px; give a finer --metres-per-pixel or a higher --pressure-max-pa",
                2.0 * a_px,
                scene.metres_per_pixel
            ),
        });
    }
    let n = frames.len();
    let digits = n.to_string().len().max(3);
    let ext = spec.encoding.extension();
    let photos = out.join("photos");
    let write_err = |p: &Path, e: std::io::Error| TrackError::Write {
        path: p.to_path_buf(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(&photos).map_err(|e| write_err(&photos, e))?;
    let results: Vec<Result<(Truth, usize), TrackError>> = frames
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let img = render_frame(&scene, spec, n, i, f);
            let bytes = super::image::encode(&img, spec.encoding)?;
            let file = format!("frame_{:0digits$}.{ext}", i + 1);
            let path = photos.join(&file);
            crate::io::write_atomic(&path, &bytes).map_err(|e| write_err(&path, e))?;
            let [ax, ay] = scene.apex_px(&f.silhouette);
            Ok((
                Truth {
                    file,
                    pressure_pa: f.pressure_pa,
                    height_m: f.silhouette.height_m(),
                    apex_x_px: ax,
                    apex_y_px: ay,
                },
                bytes.len(),
            ))
        })
        .collect();
    let mut truth = Vec::with_capacity(n);
    let mut photo_bytes = 0;
    for r in results {
        let (t, b) = r?;
        truth.push(t);
        photo_bytes += b;
    }

    let mut pcsv = CsvOut::new(&["file", "pressure_pa"]);
    let mut tcsv = CsvOut::new(&["file", "pressure_pa", "height_m", "apex_x_px", "apex_y_px"]);
    for t in &truth {
        pcsv.row(&[t.file.clone(), fmt_num(Some(t.pressure_pa))]);
        tcsv.row(&[
            t.file.clone(),
            fmt_num(Some(t.pressure_pa)),
            fmt_num(Some(t.height_m)),
            fmt_num(Some(t.apex_x_px)),
            fmt_num(Some(t.apex_y_px)),
        ]);
    }
    let p = out.join("pressure.csv");
    pcsv.write(&p).map_err(|e| write_err(&p, e))?;
    let p = out.join("truth.csv");
    tcsv.write(&p).map_err(|e| write_err(&p, e))?;

    // The region and the template where the photos show the apex (through
    // the lens, when there is one).
    let apexes: Vec<[f64; 2]> = truth
        .iter()
        .map(|t| [t.apex_x_px, t.apex_y_px])
        .map(|p| spec.look.lens.map_or(p, |l| l.distort(p)))
        .collect();
    let layout = Layout::around(
        &apexes,
        0,
        template_size(spec.width),
        (spec.width, spec.height),
    );
    let toml = experiment_toml(
        spec,
        &scene,
        &layout,
        &format!("dir = \"photos\"\nglob = \"*.{ext}\"\n"),
        "csv = \"pressure.csv\"\n",
    );
    let p = out.join("experiment.toml");
    crate::io::write_atomic(&p, toml.as_bytes()).map_err(|e| write_err(&p, e))?;
    Ok(Written {
        truth,
        photo_bytes,
        scene,
        layout,
    })
}

/// Writes the photos of a sequence as a video at `fps` frames per second
/// (frame `i` at `i / fps` s), the same pixels as the photos before their
/// encoding: `.avi` as Motion JPEG (OpenCV's own writer, always available)
/// at JPEG quality `quality`, `.mp4` as MPEG-4 part 2 when OpenCV's FFmpeg
/// back-end can write it. Written whole or not at all. Returns its size, bytes.
pub fn write_video(
    path: &Path,
    spec: &SequenceSpec,
    frames: &[SynthFrame],
    fps: u32,
    quality: u8,
) -> Result<u64, TrackError> {
    use opencv::core::Size;
    use opencv::videoio::{self, VideoWriter, VideoWriterTrait, VideoWriterTraitConst};
    use rayon::prelude::*;
    let cv = |e: opencv::Error| TrackError::OpenCv(e.to_string());
    super::image::opencv_serial().map_err(cv)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let (api, fourcc) = match ext.as_str() {
        "avi" => (videoio::CAP_OPENCV_MJPEG, ['M', 'J', 'P', 'G']),
        "mp4" => (videoio::CAP_FFMPEG, ['m', 'p', '4', 'v']),
        _ => {
            return Err(TrackError::Config {
                path: path.to_path_buf(),
                message: "a video file name must end in .avi (Motion JPEG, always written) or .mp4 (MPEG-4, when OpenCV's FFmpeg back-end is present)".into(),
            });
        }
    };
    let scene = spec.scene(frames).map_err(|message| TrackError::Config {
        path: path.to_path_buf(),
        message,
    })?;
    let n = frames.len();
    let write = |tmp: &Path| -> Result<(), TrackError> {
        let name = tmp.to_str().ok_or_else(|| TrackError::Write {
            path: path.to_path_buf(),
            reason: "the path is not valid UTF-8, which OpenCV's video module needs".into(),
        })?;
        let code = VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]).map_err(cv)?;
        let size = Size::new(spec.width as i32, spec.height as i32);
        let mut w = VideoWriter::new_with_backend(name, api, code, f64::from(fps), size, true)
            .map_err(cv)?;
        if !w.is_opened().map_err(cv)? {
            return Err(TrackError::Write {
                path: path.to_path_buf(),
                reason: format!(
                    "OpenCV cannot write a .{ext} video here (no back-end for it); write .avi (Motion JPEG) instead"
                ),
            });
        }
        if api == videoio::CAP_OPENCV_MJPEG {
            w.set(videoio::VIDEOWRITER_PROP_QUALITY, f64::from(quality))
                .map_err(cv)?;
        }
        // Rendered a few at a time in parallel, written in order.
        let chunk = 2 * rayon::current_num_threads().max(1);
        for start in (0..n).step_by(chunk) {
            let imgs: Vec<Gray> = (start..(start + chunk).min(n))
                .into_par_iter()
                .map(|i| render_frame(&scene, spec, n, i, &frames[i]))
                .collect();
            for img in &imgs {
                // Written in colour (grey, R = G = B): the usual 3-channel
                // Motion JPEG that every reader decodes.
                let mut bgr = opencv::core::Mat::default();
                opencv::imgproc::cvt_color_def(
                    &img.as_mat().map_err(cv)?,
                    &mut bgr,
                    opencv::imgproc::COLOR_GRAY2BGR,
                )
                .map_err(cv)?;
                w.write(&bgr).map_err(cv)?;
            }
        }
        w.release().map_err(cv)?;
        Ok(())
    };
    crate::io::write_atomic_with(path, write).map_err(|e| match e {
        crate::io::AtomicWriteError::Write(e) => e,
        crate::io::AtomicWriteError::Io(e) => TrackError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        },
    })?;
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|e| TrackError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
}

/// The pressure of a synthetic test at camera time `t`, s, when photo `k`
/// (pressure `pressures[k]`) is taken at `k * interval_s`: linear between
/// photos plus a quarter of the step times `sin^2(pi t / interval_s)` (zero,
/// with zero slope, at every photo; the pressure still rises), so that the
/// linear interpolation of a log sampled between photos is not exact; its
/// error is at most `h^2 / 8 * max|p''|` for samples `h` apart, with
/// `max|p''| = (step / 4) * 2 pi^2 / interval_s^2`. Beyond the photos the
/// first and last steps continue; never below 0.
pub fn pressure_ramp(pressures: &[f64], interval_s: f64, t: f64) -> f64 {
    let n = pressures.len();
    if n == 1 {
        return pressures[0];
    }
    let u = t / interval_s;
    let k = (u.floor().max(0.0) as usize).min(n - 2);
    let step = pressures[k + 1] - pressures[k];
    let lin = pressures[k] + step * (u - k as f64);
    let wiggle = 0.25 * step * (std::f64::consts::PI * u).sin().powi(2);
    (lin + wiggle).max(0.0)
}

/// `time_s,pressure_pa`: the pressure of [`pressure_ramp`] sampled by a
/// logger at `rate_hz` on its own clock, which reads `offset_s` when the
/// camera's reads 0 (logger time = camera time + offset_s). The logger
/// starts at 0 (earlier when `offset_s` < 0, to cover the first photo) and
/// stops one sample after the last photo.
pub fn pressure_log_csv(pressures: &[f64], interval_s: f64, rate_hz: f64, offset_s: f64) -> CsvOut {
    let last = (pressures.len().max(1) - 1) as f64 * interval_s + offset_s;
    let j0 = ((offset_s * rate_hz).floor() as i64 - 1).min(0);
    let j1 = (last * rate_hz).ceil() as i64 + 1;
    let mut csv = CsvOut::new(&["time_s", "pressure_pa"]);
    for j in j0..=j1 {
        let tau = j as f64 / rate_hz;
        let p = pressure_ramp(pressures, interval_s, tau - offset_s);
        csv.row(&[fmt_num(Some(tau)), fmt_num(Some(p))]);
    }
    csv
}

/// Spherical caps of heights rising linearly from `h_max / n` to `h_max`
/// (for tests and benchmarks that must not depend on a material model; the
/// pressure column is then only a label: 100 Pa per frame).
pub fn cap_frames(radius_m: f64, h_max_m: f64, n: usize) -> Vec<SynthFrame> {
    (1..=n)
        .map(|k| SynthFrame {
            pressure_pa: 100.0 * k as f64,
            silhouette: Silhouette::spherical_cap(radius_m, h_max_m * k as f64 / n as f64, 400),
        })
        .collect()
}

/// RMS errors of the apex positions against the truth, px: `[x, y]` for the
/// integer match, the quadratic peak fit and the reported apex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApexErrors {
    /// Integer-pixel match (minMaxLoc alone).
    pub integer: [f64; 2],
    /// 2-D quadratic fit of the score peak.
    pub quadratic: [f64; 2],
    /// The reported apex (`apex_x_px`, `apex_y_px`).
    pub reported: [f64; 2],
    /// RMS of (error / apex_y_std_px) of the reported row: about 1 when the
    /// stated uncertainty is honest about the noise.
    pub y_z_rms: f64,
    /// Frames compared.
    pub frames: usize,
}

/// Compares tracked rows with the truth (matched by file name).
pub fn apex_errors(rows: &[super::FrameResult], truth: &[Truth]) -> ApexErrors {
    let mut sums = [[0.0f64; 2]; 3];
    let mut z2 = 0.0;
    let mut n = 0usize;
    for r in rows {
        let Some(t) = truth.iter().find(|t| t.file == r.file) else {
            continue;
        };
        let est = [
            r.apex_integer_px,
            r.apex_quadratic_px,
            [r.apex_x_px, r.apex_y_px],
        ];
        for (s, e) in sums.iter_mut().zip(est) {
            s[0] += (e[0] - t.apex_x_px).powi(2);
            s[1] += (e[1] - t.apex_y_px).powi(2);
        }
        z2 += ((r.apex_y_px - t.apex_y_px) / r.apex_y_std_px.max(1e-12)).powi(2);
        n += 1;
    }
    let rms = |s: [f64; 2]| [(s[0] / n as f64).sqrt(), (s[1] / n as f64).sqrt()];
    ApexErrors {
        integer: rms(sums[0]),
        quadratic: rms(sums[1]),
        reported: rms(sums[2]),
        y_z_rms: (z2 / n as f64).sqrt(),
        frames: n,
    }
}

/// A small deterministic generator (SplitMix64), so that a seed gives the
/// same photos on every platform and version of the dependencies.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        Scene::new(320, 240, 0.0375, 7)
    }

    #[test]
    fn the_pressure_ramp_meets_every_photo_and_rises() {
        let p = [400.0, 800.0, 1200.0, 1600.0];
        for (k, &pk) in p.iter().enumerate() {
            assert!((pressure_ramp(&p, 0.5, 0.5 * k as f64) - pk).abs() < 1e-9);
        }
        let mut last = f64::NEG_INFINITY;
        for j in -20..=200 {
            let v = pressure_ramp(&p, 0.5, j as f64 * 0.01);
            assert!(v >= last && v >= 0.0, "t = {}", j as f64 * 0.01);
            last = v;
        }
        // between photos it leaves the straight line (by up to a quarter step)
        assert!((pressure_ramp(&p, 0.5, 0.25) - 700.0).abs() < 1e-9);
        let log = String::from_utf8(pressure_log_csv(&p, 0.5, 7.0, 0.4).into_bytes()).unwrap();
        let rows: Vec<&str> = log.lines().collect();
        assert_eq!(rows[0], "time_s,pressure_pa");
        assert!(rows[1].starts_with("0,"), "{}", rows[1]);
        // one sample after the last photo, at 1.5 + 0.4 s on the logger's clock
        let last_t: f64 = rows[rows.len() - 1]
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(last_t > 1.9 && last_t <= 1.9 + 2.0 / 7.0, "{last_t}");
    }

    #[test]
    fn coverage_area_equals_the_cap_area() {
        let sc = scene();
        let h = 0.02;
        let s = Silhouette::spherical_cap(0.0375, h, 200);
        let cov = coverage(&sc, &s);
        let area_px: f64 = cov.iter().sum();
        // Circular segment of radius R, chord 2a, height h.
        let (a, r) = (0.0375f64, (0.0375f64.powi(2) + h * h) / (2.0 * h));
        let area = r * r * (2.0 * (a / r).asin()) / 2.0 - a * (r - h);
        let area_expected = area / sc.metres_per_pixel.powi(2);
        assert!(
            (area_px - area_expected).abs() / area_expected < 1e-4,
            "{area_px} vs {area_expected}"
        );
        assert!(cov.iter().all(|c| (0.0..=1.0).contains(c)));
    }

    #[test]
    fn apex_column_coverage_matches_the_apex_row() {
        // In the column through the apex, the coverage summed over rows is the
        // height of the silhouette from the apex to the clamp plane (up to the
        // curvature inside one pixel width, < 1e-3 px here).
        let sc = scene();
        let s = Silhouette::spherical_cap(0.0375, 0.015, 400);
        let cov = coverage(&sc, &s);
        let [ax, ay] = sc.apex_px(&s);
        let col = ax.round() as usize;
        let sum: f64 = (0..sc.height).map(|y| cov[y * sc.width + col]).sum();
        let expected = sc.clamp_row_px - ay;
        assert!((sum - expected).abs() < 2e-3, "{sum} vs {expected}");
    }

    #[test]
    fn rendering_is_deterministic_per_seed() {
        let sc = scene();
        let s = Silhouette::spherical_cap(0.0375, 0.01, 100);
        let d = Degradation {
            blur_px: 1.0,
            noise_grey: 3.0,
            gain: 1.0,
        };
        assert_eq!(render(&sc, &s, &d, 3), render(&sc, &s, &d, 3));
        assert_ne!(render(&sc, &s, &d, 3), render(&sc, &s, &d, 4));
    }

    /// The default framing and look through `Scene::framed` draw the same
    /// pixels as `Scene::new`.
    #[test]
    fn the_plain_look_is_unchanged() {
        let s = Silhouette::spherical_cap(0.0375, 0.01, 100);
        let framed = Scene::framed(
            320,
            240,
            0.0375,
            7,
            &Framing::default(),
            Look::default(),
            [0.01, 0.0375],
        )
        .unwrap();
        let d = Degradation {
            blur_px: 0.5,
            noise_grey: 1.0,
            gain: 1.0,
        };
        assert_eq!(render(&scene(), &s, &d, 3), render(&framed, &s, &d, 3));
    }

    /// Seen from an elevation `e`, the axis column of a spherical cap
    /// (sphere radius `R`, half-angle above `e`) is covered from the
    /// silhouette's top, `(h - R) cos e + R` above the clamp ring's centre
    /// (the latitude at polar angle `e` seen edge-on), down to the front of
    /// the base ring, `a sin e` below it: closed forms independent of the
    /// envelope of the latitude ellipses.
    #[test]
    fn an_elevated_cap_covers_its_axis_column_from_top_to_the_front_of_the_ring() {
        let (a, h) = (0.0375, 0.012);
        let s = Silhouette::spherical_cap(a, h, 400);
        for e_deg in [1.0f64, 3.0, 5.0] {
            let look = Look {
                elevation_deg: e_deg,
                ..Look::default()
            };
            let framing = Framing {
                axis_x_px: Some(160.0),
                ..Framing::default()
            };
            let sc = Scene::framed(320, 240, a, 7, &framing, look, [0.014, a]).unwrap();
            let cov = coverage(&sc, &s);
            let e = e_deg.to_radians();
            let r = (a * a + h * h) / (2.0 * h);
            let span_m = (h - r) * e.cos() + r + a * e.sin();
            let sum: f64 = (0..sc.height).map(|y| cov[y * sc.width + 160]).sum();
            let expected = span_m / sc.metres_per_pixel;
            assert!(
                (sum - expected).abs() < 0.01,
                "{e_deg} degrees: {sum} vs {expected} px"
            );
            // the pole's projection is lower than the top by R (1 - cos e)
            let top = look::silhouette_top_m(&s, e);
            assert!((top - ((h - r) * e.cos() + r)).abs() < 1e-7, "{top}");
            assert!(
                (sc.apex_px(&s)[1] - (sc.clamp_row_px - h * e.cos() / sc.metres_per_pixel)).abs()
                    < 1e-9
            );
        }
    }

    /// Random framing: the same seed gives the same scene; the bubble and
    /// the clamp ring stay in the picture; a framing by hand that leaves
    /// them out is refused naming the flags.
    #[test]
    fn random_framing_keeps_the_bubble_and_the_ring_in_the_picture() {
        let random = Framing {
            random: true,
            ..Framing::default()
        };
        let look = Look {
            elevation_deg: 4.0,
            ..Look::default()
        };
        let mut scales = Vec::new();
        for seed in 0..30 {
            let sc = Scene::framed(640, 480, 0.0375, seed, &random, look, [0.02, 0.0375]).unwrap();
            assert_eq!(
                sc,
                Scene::framed(640, 480, 0.0375, seed, &random, look, [0.02, 0.0375]).unwrap()
            );
            let (a, top) = (0.0375 / sc.metres_per_pixel, 0.02 / sc.metres_per_pixel);
            assert!(
                sc.axis_x_px - a > 0.0 && sc.axis_x_px + a < 639.0,
                "seed {seed}"
            );
            assert!(
                sc.clamp_row_px - top > 0.0 && sc.clamp_row_px < 470.0,
                "seed {seed}"
            );
            scales.push(sc.metres_per_pixel);
        }
        let (lo, hi) = scales
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(hi / lo > 1.5, "scales {lo}..{hi}");
        let by_hand = Framing {
            axis_x_px: Some(20.0),
            ..Framing::default()
        };
        let e = Scene::framed(640, 480, 0.0375, 1, &by_hand, look, [0.02, 0.0375]).unwrap_err();
        assert!(
            e.contains("side of the bubble") && e.contains("--axis-x-px"),
            "{e}"
        );
    }

    /// Clutter, light and the highlight change the picture only where they
    /// are drawn: the highlight only on the dome, near its top.
    #[test]
    fn the_highlight_lies_on_the_dome_below_the_apex() {
        let s = Silhouette::spherical_cap(0.0375, 0.015, 200);
        let plain = Scene::framed(
            320,
            240,
            0.0375,
            7,
            &Framing::default(),
            Look::default(),
            [0.015, 0.0375],
        )
        .unwrap();
        let glossy = Scene::framed(
            320,
            240,
            0.0375,
            7,
            &Framing::default(),
            Look {
                highlight_grey: 90.0,
                ..Look::default()
            },
            [0.015, 0.0375],
        )
        .unwrap();
        let d = Degradation {
            blur_px: 0.0,
            noise_grey: 0.0,
            gain: 1.0,
        };
        let (p, g) = (render(&plain, &s, &d, 1), render(&glossy, &s, &d, 1));
        let cov = coverage(&plain, &s);
        let apex = plain.apex_px(&s);
        let mut brightest = (0u8, 0usize, 0usize);
        for y in 0..240 {
            for x in 0..320 {
                let i = y * 320 + x;
                if cov[i] == 0.0 {
                    assert_eq!(p.data[i], g.data[i], "({x}, {y}) off the dome");
                }
                let gain = g.data[i].saturating_sub(p.data[i]);
                if gain > brightest.0 {
                    brightest = (gain, x, y);
                }
            }
        }
        assert!(brightest.0 > 60, "{brightest:?}");
        let below = brightest.2 as f64 - apex[1];
        assert!(
            below > 0.0 && below < 0.2 * 0.015 / plain.metres_per_pixel,
            "{brightest:?} {apex:?}"
        );
    }
}
