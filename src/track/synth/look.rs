//! What the photos of a lab add to the plain side view: the specimen framed
//! anywhere, a camera raised above the clamp plane, uneven light, a specular
//! highlight on the dome and clutter behind the bubble.
//!
//! A camera raised by an elevation angle `e` (orthographic, looking down
//! along `(0, cos e, -sin e)`, image up `(0, sin e, cos e)`) sees the point
//! `(x, y, z)` (z up the bubble's axis, y away from the camera) at image
//! `(x, y sin e + z cos e)`. A latitude circle of radius `rho` at height `z`
//! becomes an ellipse centred `z cos e` above the clamp ring's centre, of
//! semi-axes `rho` and `rho sin e`; the dome, a body of revolution closed by
//! its base disc, projects to the union of the ellipses of all its latitude
//! circles, whose outline per column `u` is the highest top
//! `max(z cos e + sqrt(rho^2 - u^2) sin e)` and the lowest bottom
//! `min(z cos e - sqrt(rho^2 - u^2) sin e)` over the latitudes with
//! `rho >= |u|`. The clamp fixture's top face, a ring of radius 1.25 a,
//! is an ellipse too.

use super::{Rng, Scene, Silhouette, densify};

/// What the photos show besides the plain side view (all off by default).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Look {
    /// Elevation of the camera above the clamp plane, degrees (0: level).
    pub elevation_deg: f64,
    /// Uneven light: the relative change of the illumination across the
    /// frame, a tilted plane plus a fall-off away from a seeded centre
    /// (0: even).
    pub uneven_light: f64,
    /// Peak of a specular highlight on the dome, grey levels (0: none).
    pub highlight_grey: f64,
    /// A dark shelf edge and a cable behind the bubble, across the apex's
    /// path.
    pub clutter: bool,
    /// The camera's tone curve: the scene's grey levels are the encoded
    /// values of its light; the lens blur, the exposure and the uneven light
    /// act on the light, which the curve then encodes (default sRGB;
    /// `Linear` draws in pixel values throughout).
    pub response: crate::camera::Response,
    /// A lens with distortion (`None`: a pinhole camera): the photo's pixels
    /// take the ideal image's light at their undistorted positions
    /// ([`super::lens::distort_light`]); positions in `truth.csv` stay the
    /// ideal image's.
    pub lens: Option<crate::track::lens::Lens>,
}

/// Where the specimen is in the picture. Unset values keep the default
/// framing (the disc spans 70 % of the width, the axis in the middle, the
/// clamp plane at 80 % of the height), or with `random` are drawn from the
/// seed so that the tallest bubble and the clamp ring are in the picture.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Framing {
    /// Scale, m per px.
    pub metres_per_pixel: Option<f64>,
    /// Column of the bubble's axis, px.
    pub axis_x_px: Option<f64>,
    /// Row of the clamp plane (the clamp ring's centre), px.
    pub clamp_row_px: Option<f64>,
    /// Draw the unset values at random.
    pub random: bool,
}

impl Framing {
    /// Whether this is the default framing.
    pub fn is_default(&self) -> bool {
        *self == Framing::default()
    }
}

/// Where the clutter and the uneven light are (fixed for a sequence).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Extras {
    /// Top row of the shelf edge and its height, px.
    shelf: [f64; 2],
    /// Cable: mean row, sag amplitude, wavenumber (rad/px), phase, half width.
    cable: [f64; 5],
    /// Light: direction (cos, sin), fall-off centre (x, y as fractions of
    /// the frame), strength.
    light: [f64; 5],
    /// Frame size, px.
    frame: [f64; 2],
}

/// Grey levels of the clutter.
const SHELF: f64 = 70.0;
const CABLE: f64 = 35.0;

impl Extras {
    /// The background at `(x, y)` with the shelf edge and the cable drawn
    /// over it (pixel-exact vertical coverage of the shelf, the cable's
    /// coverage from its distance to the pixel centre).
    pub(super) fn clutter(&self, bg: f64, x: f64, y: f64) -> f64 {
        let [top, tall] = self.shelf;
        let band = ((y + 0.5) - top).clamp(0.0, 1.0) - ((y + 0.5) - top - tall).clamp(0.0, 1.0);
        let v = bg * (1.0 - band) + SHELF * band;
        let [y0, amp, k, ph, half] = self.cable;
        let yc = y0 + amp * (k * x + ph).sin();
        let slope = amp * k * (k * x + ph).cos();
        let d = (y - yc).abs() / (1.0 + slope * slope).sqrt();
        let c = (half + 0.5 - d).clamp(0.0, 1.0);
        v * (1.0 - c) + CABLE * c
    }

    /// The illumination factor at `(x, y)`.
    pub(super) fn light(&self, x: f64, y: f64) -> f64 {
        let [dc, ds, cx, cy, s] = self.light;
        if self.frame[0] == 0.0 {
            return 1.0;
        }
        let (xn, yn) = (x / self.frame[0], y / self.frame[1]);
        1.0 + s * (0.5 * ((xn - 0.5) * dc + (yn - 0.5) * ds))
            - 0.5 * s * ((xn - cx).powi(2) + (yn - cy).powi(2))
    }
}

/// The highest point of a silhouette seen from elevation `e`, m above the
/// clamp ring's centre: `max(z cos e + rho sin e)` over the profile.
pub fn silhouette_top_m(s: &Silhouette, elevation_rad: f64) -> f64 {
    let (se, ce) = elevation_rad.sin_cos();
    s.rho_m
        .iter()
        .zip(&s.z_m)
        .map(|(r, z)| z * ce + r * se)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The widest latitude of a silhouette, m.
fn rho_max_m(s: &Silhouette) -> f64 {
    s.rho_m.iter().copied().fold(0.0, f64::max)
}

impl Scene {
    /// The scene of a sequence whose tallest silhouette reaches
    /// `reach_m[0]` above the clamp ring's centre (seen from the look's
    /// elevation) and whose widest latitude is `reach_m[1]`: the default scene of
    /// [`Scene::new`] (the same pixels when `framing` and `look` are the
    /// defaults), framed as `framing` says, with the clutter placed across
    /// the apex's path. Fails, saying why, when a framing given by hand
    /// leaves the bubble or the clamp ring out of the picture.
    pub fn framed(
        width: usize,
        height: usize,
        radius_m: f64,
        seed: u64,
        framing: &Framing,
        look: Look,
        reach_m: [f64; 2],
    ) -> Result<Scene, String> {
        let [top_m, rho_max_m] = reach_m;
        let mut sc = Scene::new(width, height, radius_m, seed);
        sc.look = look;
        let (wf, hf) = (width as f64, height as f64);
        let e = look.elevation_deg.to_radians();
        let mut rng = Rng::new(seed ^ 0xF2A3_11E5);
        // Rows the picture needs below the clamp ring's centre: the front
        // of the fixture's top face and its flange.
        let below = |mpp: f64| 1.25 * radius_m / mpp * e.sin() + (0.025 * hf).max(2.0) + 2.0;
        // ... and above it: the tallest silhouette and a margin of 10 %.
        let above = |mpp: f64| top_m / mpp + 0.1 * hf;
        let half = |mpp: f64| 1.02 * rho_max_m.max(radius_m) / mpp + 2.0;
        if let Some(m) = framing.metres_per_pixel {
            sc.metres_per_pixel = m;
        } else if framing.random {
            // The disc spans 35-80 % of the width, less when the bubble
            // would not fit.
            let f = 0.35 + 0.45 * rng.uniform();
            let mut mpp = 2.0 * radius_m / (f * wf);
            while above(mpp) + below(mpp) > 0.95 * hf || 2.0 * half(mpp) > 0.95 * wf {
                mpp *= 1.05;
            }
            sc.metres_per_pixel = mpp;
        }
        let mpp = sc.metres_per_pixel;
        // A value given, else (random framing) drawn in `[lo, hi]`, or
        // `fallback` when that range is empty.
        let mut place =
            |given: Option<f64>, lo: f64, hi: f64, fallback: f64, current: f64| match given {
                Some(v) => v,
                None if framing.random && hi > lo => lo + (hi - lo) * rng.uniform(),
                None if framing.random => fallback,
                None => current,
            };
        sc.axis_x_px = place(
            framing.axis_x_px,
            half(mpp),
            wf - 1.0 - half(mpp),
            0.5 * wf,
            sc.axis_x_px,
        );
        sc.clamp_row_px = place(
            framing.clamp_row_px,
            above(mpp),
            hf - 1.0 - below(mpp),
            0.8 * hf,
            sc.clamp_row_px,
        );
        if !framing.is_default() {
            let out = |what: &str| {
                Err(format!(
                    "the framing (scale {:.4e} m/px, axis at column {:.1}, clamp plane at row {:.1}) leaves {what} out of the {width}x{height} px picture: change --metres-per-pixel, --axis-x-px or --clamp-row-px",
                    mpp, sc.axis_x_px, sc.clamp_row_px
                ))
            };
            if sc.axis_x_px - half(mpp) < 0.0 || sc.axis_x_px + half(mpp) > wf - 1.0 {
                return out("a side of the bubble");
            }
            if sc.clamp_row_px + below(mpp) > hf - 1.0 {
                return out("the clamp ring");
            }
            if sc.clamp_row_px - above(mpp) < 0.0 {
                return out("the tallest bubble's top (with a margin of 10 % of the height)");
            }
        }
        if look.clutter {
            let top_px = top_m / mpp;
            let shelf_top = sc.clamp_row_px - (0.35 + 0.3 * rng.uniform()) * top_px;
            let tall = (5.0 * wf / 1280.0).max(3.0);
            let cable_row = sc.clamp_row_px - (0.6 + 0.3 * rng.uniform()) * top_px;
            let sag = (0.02 + 0.04 * rng.uniform()) * hf;
            let k = std::f64::consts::TAU / (wf * (0.8 + 0.8 * rng.uniform()));
            let ph = std::f64::consts::TAU * rng.uniform();
            sc.extras.shelf = [shelf_top, tall];
            sc.extras.cable = [cable_row, sag, k, ph, (1.5 * wf / 1280.0).max(1.0)];
        }
        if look.uneven_light != 0.0 {
            let a = std::f64::consts::TAU * rng.uniform();
            sc.extras.light = [
                a.cos(),
                a.sin(),
                rng.uniform(),
                rng.uniform(),
                look.uneven_light,
            ];
        }
        sc.extras.frame = [wf, hf];
        Ok(sc)
    }

    /// The scene of a sequence of silhouettes (see [`Scene::framed`]).
    pub fn for_frames(
        width: usize,
        height: usize,
        radius_m: f64,
        seed: u64,
        framing: &Framing,
        look: Look,
        frames: &[&Silhouette],
    ) -> Result<Scene, String> {
        let e = look.elevation_deg.to_radians();
        let top = frames
            .iter()
            .map(|s| silhouette_top_m(s, e))
            .fold(0.0, f64::max);
        let rho = frames.iter().map(|s| rho_max_m(s)).fold(0.0, f64::max);
        Scene::framed(width, height, radius_m, seed, framing, look, [top, rho])
    }
}

/// The fixture's top face per column: the rows of its back and front edges
/// (both the clamp row for a level camera, or outside the fixture).
pub(super) fn fixture_rows(scene: &Scene, half_px: f64) -> (Vec<f64>, Vec<f64>) {
    let se = scene.look.elevation_deg.to_radians().sin();
    let c = scene.clamp_row_px;
    (0..scene.width)
        .map(|x| {
            let d = x as f64 - scene.axis_x_px;
            if se == 0.0 || d.abs() >= half_px {
                (c, c)
            } else {
                let q = (half_px * half_px - d * d).sqrt() * se;
                (c - q, c + q)
            }
        })
        .unzip()
}

/// A specular highlight on the dome: the reflection of a small light above
/// the camera, at a fixed angle (12 degrees) from the pole towards the
/// camera and 20 degrees to the left on the sphere through the apex and the
/// rim, so that it comes closer to the apex as the bubble inflates; a
/// Gaussian spot of 0.05 rad of the sphere, foreshortened vertically.
pub(super) struct Highlight {
    x: f64,
    y: f64,
    sx: f64,
    sy: f64,
    peak: f64,
}

impl Highlight {
    pub(super) fn new(scene: &Scene, s: &Silhouette) -> Option<Self> {
        let peak = scene.look.highlight_grey;
        let (a, h) = (scene.radius_m, s.height_m());
        if peak == 0.0 || h <= 0.0 {
            return None;
        }
        let r = (a * a + h * h) / (2.0 * h);
        let cap = 2.0 * (h / a).atan();
        let (tb, phi) = (12f64.to_radians(), (-20f64).to_radians());
        if tb > 0.8 * cap {
            return None;
        }
        let e = scene.look.elevation_deg.to_radians();
        let (x, y, z) = (
            r * tb.sin() * phi.sin(),
            -r * tb.sin() * phi.cos(),
            h - r + r * tb.cos(),
        );
        let up = y * e.sin() + z * e.cos();
        let mpp = scene.metres_per_pixel;
        let sigma = 0.05 * r / mpp;
        Some(Highlight {
            x: scene.axis_x_px + x / mpp,
            y: scene.clamp_row_px - up / mpp,
            sx: sigma.max(0.8),
            sy: (sigma * (tb + e).sin()).max(0.8),
            peak,
        })
    }

    /// Its brightness at `(x, y)`, grey levels.
    pub(super) fn at(&self, x: f64, y: f64) -> f64 {
        let (u, v) = ((x - self.x) / self.sx, (y - self.y) / self.sy);
        self.peak * (-0.5 * (u * u + v * v)).exp()
    }
}

/// The outline of the silhouette seen from the look's elevation, as a
/// closed polygon in raster coordinates (`x + 0.5`, `y + 0.5`): the upper
/// envelope of the latitude ellipses from left to right, then the lower one
/// back, at columns `rho_max cos(psi)` with `psi` evenly spaced (at most a
/// quarter pixel of arc apart).
pub(super) fn outline_px(scene: &Scene, s: &Silhouette) -> Vec<(f64, f64)> {
    let mpp = scene.metres_per_pixel;
    let (se, ce) = scene.look.elevation_deg.to_radians().sin_cos();
    let dense = densify(s, 0.5 * mpp);
    let rho_max = dense.iter().map(|p| p.0).fold(0.0, f64::max);
    let n = ((std::f64::consts::PI * rho_max / mpp * 4.0).ceil() as usize).max(64);
    let mut top = Vec::with_capacity(n + 1);
    let mut bottom = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let psi = std::f64::consts::PI * (1.0 - k as f64 / n as f64);
        let u = (rho_max * psi.cos()).clamp(-rho_max, rho_max);
        let (mut t, mut b) = (f64::NEG_INFINITY, f64::INFINITY);
        for &(r, z) in &dense {
            if r >= u.abs() {
                let q = (r * r - u * u).max(0.0).sqrt() * se;
                t = t.max(z * ce + q);
                b = b.min(z * ce - q);
            }
        }
        if !t.is_finite() {
            continue;
        }
        let x = scene.axis_x_px + u / mpp + 0.5;
        top.push((x, scene.clamp_row_px - t / mpp + 0.5));
        bottom.push((x, scene.clamp_row_px - b / mpp + 0.5));
    }
    top.extend(bottom.into_iter().rev());
    top
}
