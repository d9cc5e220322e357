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
//!
//! This file holds the scene (the bubble's [`Silhouette`], the camera's
//! [`Scene`] and [`Degradation`]), the truth's error summary and the seeded
//! generator; drawing a frame is in `draw`, a sequence's description in
//! `sequence`, writing it to disk in `write`.

use std::path::Path;

use super::TrackError;
use super::image::{Encoding, Gray};
use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num};

mod draw;
mod frames;
pub mod lens;
mod look;
pub mod pinhole;
mod sequence;
pub mod sweep;
#[cfg(any(test, feature = "harness"))]
pub mod trial;
mod write;
use draw::densify;
pub use draw::{coverage, gaussian_blur, render};
pub use frames::{FramesError, bubble_frames, pressure_steps};
pub use look::{Framing, FramingError, HighlightShape, Look, Psf, vignette};
pub use sequence::{
    Layout, SequenceSpec, SynthFrame, Truth, Written, axisym_frame, experiment_file,
    neo_hookean_bubble, random_camera, render_frame, template_size,
};
pub use write::{pressure_log_csv, pressure_ramp, write_sequence, write_video};

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

/// The generator of the photos: the crate's one seeded SplitMix64, so that
/// a seed gives the same photos on every platform and version of the
/// dependencies.
pub use crate::numerics::Rng;

#[cfg(test)]
mod tests;
