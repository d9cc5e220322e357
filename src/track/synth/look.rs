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

use super::draw::envelope;
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
    /// Where that highlight lies on the dome and how its light spreads.
    pub highlight: HighlightShape,
    /// A dark shelf edge and a cable behind the bubble, across the apex's
    /// path.
    pub clutter: bool,
    /// The camera's tone curve: the scene's grey levels are the encoded
    /// values of its light; the lens blur, the exposure and the uneven light
    /// act on the light, which the curve then encodes (default sRGB;
    /// `Linear` draws in pixel values throughout).
    pub response: crate::camera::Response,
    /// Grey level of the clamp ring's visible top face, the encoded value
    /// of its light (0: the default 58, a dull face a little lighter than
    /// the ring's side at 38; e.g. 230 for a machined metal ring lit from
    /// above, 20 for a face darker than its side).
    pub ring_face_grey: f64,
    /// Grey level of the bubble at its centre (0: the default 72, a dark
    /// membrane; e.g. 215 for translucent latex lit in front of a dark
    /// wall, with `background_grey`).
    pub bubble_grey: f64,
    /// Mean grey level of the background (0: the default 190, a light
    /// wall; e.g. 50 for a dark wall).
    pub background_grey: f64,
    /// Light from one side: the light is multiplied by
    /// `1 + side_light * clamp((x - axis) / a, -1, 1)` (`a` the disc's
    /// radius in px), so the dome is brighter on one side of its apex and
    /// the background behind it too (0: lit evenly; negative: from the
    /// left).
    pub side_light: f64,
    /// Defocus: a pillbox point-spread function (a uniform disc, the image
    /// of a point through a defocused circular aperture) of this radius,
    /// px, applied to the light after the Gaussian blur (0: in focus).
    pub defocus_px: f64,
    /// Linear motion blur: a line point-spread function of this length, px
    /// (the camera or the specimen moving during the exposure at a steady
    /// speed), applied to the light (0: none).
    pub motion_px: f64,
    /// Direction of the motion blur, degrees from the image's x axis
    /// towards its y axis (down).
    pub motion_deg: f64,
    /// Vignetting: the light falls off towards the corners as
    /// `cos^4(theta)` of the angle of view from the optical axis (the
    /// picture's centre) of a lens whose focal length makes the corners
    /// receive `1 - vignetting` of the centre's light (0: none; e.g. 0.3).
    pub vignetting: f64,
    /// A lens with distortion (`None`: a pinhole camera): the photo's pixels
    /// take the ideal image's light at their undistorted positions
    /// ([`super::lens::distort_light`]); positions in `truth.csv` stay the
    /// ideal image's.
    pub lens: Option<crate::track::lens::Lens>,
    /// A pinhole camera this far from the bubble's axis, m, looking down at
    /// the clamp ring's centre at `elevation_deg` ([`super::pinhole`]; 0:
    /// an orthographic camera).
    pub camera_distance_m: f64,
}

/// Where a specular highlight lies on the dome and how its light spreads
/// ([`Look::highlight_grey`]). A lamp over and behind the bubble is
/// mirrored where the dome's normal bisects the directions to the lamp and
/// to the camera; its image's size is the lamp's angular size and the
/// coat's roughness together, and its fall-off the coat's microfacet
/// distribution: Beckmann's, near a Gaussian, or Trowbridge and Reitz's
/// (GGX), whose tail is much heavier (B. Walter, S. R. Marschner, H. Li,
/// K. E. Torrance, "Microfacet models for refraction through rough
/// surfaces", Eurographics Symposium on Rendering 2007,
/// doi:10.2312/EGWR/EGSR07/195-206).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HighlightShape {
    /// The highlight's angle from the pole towards the camera, degrees, on
    /// the sphere through the apex and the rim.
    pub polar_deg: f64,
    /// Its angle about the axis from the plane through the axis and the
    /// camera, degrees (negative: to the left).
    pub azimuth_deg: f64,
    /// Its size, radians of that sphere: the standard deviation of the
    /// Gaussian spot, or the width `alpha / sqrt(2)` of the heavy-tailed
    /// one.
    pub size_rad: f64,
    /// The heavy-tailed lobe `(1 + r^2 / 2)^-2` (GGX's near its peak, `r`
    /// the distance over the size) instead of the Gaussian `exp(-r^2 / 2)`.
    pub heavy_tail: bool,
}

impl Default for HighlightShape {
    /// 12 degrees from the pole, 20 degrees to the left, a Gaussian spot of
    /// 0.05 rad.
    fn default() -> Self {
        HighlightShape {
            polar_deg: 12.0,
            azimuth_deg: -20.0,
            size_rad: 0.05,
            heavy_tail: false,
        }
    }
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

/// A framing given by hand that leaves part of the scene out of the
/// picture.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the framing (scale {metres_per_pixel:.4e} m/px, axis at column {axis_x_px:.1}, clamp plane at row {clamp_row_px:.1}) leaves {what} out of the {width}x{height} px picture: change {}, {} or {}",
    crate::setting::Setting::MetresPerPixel,
    crate::setting::Setting::AxisX,
    crate::setting::Setting::ClampRow
)]
pub struct FramingError {
    /// The scale, m/px.
    pub metres_per_pixel: f64,
    /// The axis's column.
    pub axis_x_px: f64,
    /// The clamp plane's row.
    pub clamp_row_px: f64,
    /// The picture's width, px.
    pub width: usize,
    /// The picture's height, px.
    pub height: usize,
    /// What is left out.
    pub what: &'static str,
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
    ) -> Result<Scene, FramingError> {
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
            let out = |what: &'static str| {
                Err(FramingError {
                    metres_per_pixel: mpp,
                    axis_x_px: sc.axis_x_px,
                    clamp_row_px: sc.clamp_row_px,
                    width,
                    height,
                    what,
                })
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
    ) -> Result<Scene, FramingError> {
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

/// A specular highlight on the dome: the reflection of a small light over
/// the bubble, at a fixed place on the sphere through the apex and the rim
/// ([`HighlightShape`]; by default 12 degrees from the pole towards the
/// camera and 20 degrees to the left), so that it comes closer to the apex
/// as the bubble inflates; a spot of a fixed size on the sphere,
/// foreshortened vertically.
pub(super) struct Highlight {
    x: f64,
    y: f64,
    sx: f64,
    sy: f64,
    peak: f64,
    heavy_tail: bool,
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
        let shape = scene.look.highlight;
        let (tb, phi) = (shape.polar_deg.to_radians(), shape.azimuth_deg.to_radians());
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
        let sigma = shape.size_rad * r / mpp;
        Some(Highlight {
            x: scene.axis_x_px + x / mpp,
            y: scene.clamp_row_px - up / mpp,
            sx: sigma.max(0.8),
            sy: (sigma * (tb + e).sin()).max(0.8),
            peak,
            heavy_tail: shape.heavy_tail,
        })
    }

    /// Its brightness at `(x, y)`, grey levels.
    pub(super) fn at(&self, x: f64, y: f64) -> f64 {
        let (u, v) = ((x - self.x) / self.sx, (y - self.y) / self.sy);
        let r2 = u * u + v * v;
        if self.heavy_tail {
            self.peak / (1.0 + 0.5 * r2).powi(2)
        } else {
            self.peak * (-0.5 * r2).exp()
        }
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
        // Heights negated: the envelope takes the least first value.
        let Some((t, b)) = envelope(&dense, |r, z| {
            (r >= u.abs()).then(|| {
                let q = (r * r - u * u).max(0.0).sqrt() * se;
                (-(z * ce + q), -(z * ce - q))
            })
        }) else {
            continue;
        };
        let (t, b) = (-t, -b);
        let x = scene.axis_x_px + u / mpp + 0.5;
        top.push((x, scene.clamp_row_px - t / mpp + 0.5));
        bottom.push((x, scene.clamp_row_px - b / mpp + 0.5));
    }
    top.extend(bottom.into_iter().rev());
    top
}

/// The vignetting factor `cos^4(theta)` at pixel `(x, y)` of a `w` x `h`
/// picture whose corner pixels receive `1 - v` of the light of the optical
/// centre `((w - 1) / 2, (h - 1) / 2)`: with `tan(theta) = r / f`,
/// `cos^4(theta) = (1 + r^2 / f^2)^-2`, and `f` chosen so that the factor is
/// `1 - v` at the corner pixels' centres.
pub fn vignette(v: f64, w: usize, h: usize, x: f64, y: f64) -> f64 {
    if v <= 0.0 {
        return 1.0;
    }
    let (cx, cy) = (0.5 * (w as f64 - 1.0), 0.5 * (h as f64 - 1.0));
    let rc2 = cx * cx + cy * cy;
    // (1 + rc^2 / f^2)^-2 = 1 - v
    let inv_f2 = ((1.0 - v.min(0.99)).powf(-0.5) - 1.0) / rc2.max(1e-12);
    let r2 = (x - cx).powi(2) + (y - cy).powi(2);
    (1.0 + r2 * inv_f2).powi(-2)
}

/// A point-spread function on a square grid of `2 r + 1` pixels a side,
/// centred on the middle pixel, summing to 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Psf {
    /// Half width, px.
    pub r: usize,
    /// Weights, row by row.
    pub k: Vec<f64>,
}

impl Psf {
    /// The defocus disc of radius `radius_px`: each weight is the area of
    /// the pixel inside the disc (sampled on a 16 x 16 grid per pixel),
    /// then all divided by their sum (close to `pi r^2`).
    pub fn pillbox(radius_px: f64) -> Psf {
        let (k, r) = Self::pillbox_areas(radius_px);
        Psf::normalised(r, k)
    }

    /// The areas of the pixels inside a disc of radius `radius_px` centred
    /// on a pixel's centre, and the grid's half width.
    pub fn pillbox_areas(radius_px: f64) -> (Vec<f64>, usize) {
        let r = (radius_px + 0.5).ceil() as usize;
        let n = 2 * r + 1;
        const S: usize = 16;
        let rr = radius_px * radius_px;
        let mut k = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                let mut inside = 0usize;
                for sj in 0..S {
                    let y = j as f64 - r as f64 - 0.5 + (sj as f64 + 0.5) / S as f64;
                    for si in 0..S {
                        let x = i as f64 - r as f64 - 0.5 + (si as f64 + 0.5) / S as f64;
                        inside += usize::from(x * x + y * y <= rr);
                    }
                }
                k[j * n + i] = inside as f64 / (S * S) as f64;
            }
        }
        (k, r)
    }

    /// A line of length `length_px` through the middle pixel's centre at
    /// `angle_deg` from the x axis towards y: the middles of its pieces
    /// 1/8 px long, each spread over its four nearest pixels (bilinear
    /// weights).
    pub fn line(length_px: f64, angle_deg: f64) -> Psf {
        let r = (0.5 * length_px).ceil() as usize + 1;
        let n = 2 * r + 1;
        let (s, c) = angle_deg.to_radians().sin_cos();
        let m = (8.0 * length_px).ceil().max(1.0) as usize;
        let mut k = vec![0.0; n * n];
        for q in 0..m {
            let t = length_px * ((q as f64 + 0.5) / m as f64 - 0.5);
            let (x, y) = (t * c + r as f64, t * s + r as f64);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let (x0, y0) = (x0 as usize, y0 as usize);
            for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
                for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                    let (xi, yi) = ((x0 + dx).min(n - 1), (y0 + dy).min(n - 1));
                    k[yi * n + xi] += wx * wy;
                }
            }
        }
        Psf::normalised(r, k)
    }

    fn normalised(r: usize, mut k: Vec<f64>) -> Psf {
        let sum: f64 = k.iter().sum();
        for v in &mut k {
            *v /= sum;
        }
        Psf { r, k }
    }

    /// Convolves `img` (`w` x `h`, row by row) with the spread, borders
    /// replicated.
    pub fn apply(&self, img: &mut [f64], w: usize, h: usize) {
        let r = self.r as isize;
        let n = 2 * self.r + 1;
        let taps: Vec<(isize, isize, f64)> = (0..n * n)
            .filter(|&i| self.k[i] != 0.0)
            .map(|i| ((i % n) as isize - r, (i / n) as isize - r, self.k[i]))
            .collect();
        let src = img.to_vec();
        let hi = h as isize;
        // The image of a point at (x + dx, y + dy) spreads to (x, y) with
        // the weight at (-dx, -dy). The taps are added in order to every
        // pixel of a row at once (each pixel's sum formed in the same order
        // as tap by tap).
        img.fill(0.0);
        for (y, dst) in img.chunks_exact_mut(w).enumerate() {
            for &(dx, dy, kv) in &taps {
                let ys = (y as isize - dy).clamp(0, hi - 1) as usize;
                super::draw::add_shifted(dst, &src[ys * w..(ys + 1) * w], -dx, kv);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Degradation, Scene, Silhouette, render};
    use super::*;
    use crate::camera::Response;

    /// A level, linear-response 320 x 240 scene of a cap 10 mm high.
    fn linear_scene(look: Look) -> (Scene, Silhouette) {
        let s = Silhouette::spherical_cap(0.0375, 0.01, 200);
        let look = Look {
            response: Response::Linear,
            ..look
        };
        let sc = Scene::framed(
            320,
            240,
            0.0375,
            7,
            &Framing::default(),
            look,
            [0.01, 0.0375],
        )
        .unwrap();
        (sc, s)
    }

    const SHARP: Degradation = Degradation {
        blur_px: 0.0,
        noise_grey: 0.0,
        gain: 1.0,
    };

    /// The disc's area is `pi r^2` (the pixels' areas inside it sum to
    /// it), and spreading a point keeps its light.
    #[test]
    fn the_pillbox_covers_the_disc_area_and_keeps_the_light() {
        for r in [0.7, 1.5, 2.5, 4.0] {
            let (k, _) = Psf::pillbox_areas(r);
            let area: f64 = k.iter().sum();
            let exact = std::f64::consts::PI * r * r;
            assert!(
                (area / exact - 1.0).abs() < 0.01,
                "r {r}: {area} vs {exact}"
            );
            let psf = Psf::pillbox(r);
            let (w, h) = (31, 29);
            let mut img = vec![0.0; w * h];
            img[14 * w + 15] = 100.0;
            psf.apply(&mut img, w, h);
            let total: f64 = img.iter().sum();
            assert!((total - 100.0).abs() < 1e-9, "r {r}: {total}");
            // Symmetric: as far left as right.
            for d in 1..=psf.r {
                let (l, rr) = (img[14 * w + 15 - d], img[14 * w + 15 + d]);
                assert!((l - rr).abs() < 1e-12);
            }
        }
    }

    /// A uniform image stays uniform under every spread (the weights sum
    /// to 1; the borders are replicated).
    #[test]
    fn spreads_keep_a_uniform_image() {
        let (w, h) = (20, 15);
        for psf in [Psf::pillbox(2.0), Psf::line(5.0, 30.0)] {
            let mut img = vec![42.0; w * h];
            psf.apply(&mut img, w, h);
            assert!(img.iter().all(|v| (v - 42.0).abs() < 1e-9));
        }
    }

    /// A line of length `L` spreads light uniformly along it: its mean is
    /// the centre, its variance along it `L^2 / 12` (a uniform
    /// distribution; `L^2 / 12 (1 - 1/m^2)` for the middles of its `m`
    /// pieces) plus at most 1/4 px^2 of bilinear splatting, and none across
    /// it.
    #[test]
    fn the_motion_line_has_the_variance_of_a_uniform_segment() {
        let l = 8.0;
        for (deg, along_x) in [(0.0, true), (90.0, false)] {
            let psf = Psf::line(l, deg);
            let n = 2 * psf.r + 1;
            let (mut mx, mut my, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
            for (i, &k) in psf.k.iter().enumerate() {
                let x = (i % n) as f64 - psf.r as f64;
                let y = (i / n) as f64 - psf.r as f64;
                mx += k * x;
                my += k * y;
                vx += k * x * x;
                vy += k * y * y;
            }
            assert!(mx.abs() < 1e-9 && my.abs() < 1e-9);
            let (va, vc) = if along_x { (vx, vy) } else { (vy, vx) };
            let u = l * l / 12.0;
            let m = 8.0 * l;
            assert!(
                va >= u * (1.0 - 1.0 / (m * m)) - 1e-12 && va <= u + 0.25,
                "{deg} deg: variance {va} vs {u}"
            );
            assert!(vc < 1e-9, "{deg} deg: across {vc}");
        }
    }

    /// The cos^4 law is 1 at the optical centre, `1 - v` at the corners,
    /// and `cos^4(atan(r / f))` between them.
    #[test]
    fn vignetting_is_one_at_the_centre_and_falls_to_the_corners() {
        let (w, h, v) = (641, 481, 0.3);
        assert_eq!(vignette(v, w, h, 320.0, 240.0), 1.0);
        for (x, y) in [(0.0, 0.0), (640.0, 0.0), (0.0, 480.0), (640.0, 480.0)] {
            assert!((vignette(v, w, h, x, y) - 0.7).abs() < 1e-12);
        }
        // The focal length, px, from the corner's angle of view.
        let rc = (320.0f64 * 320.0 + 240.0 * 240.0).sqrt();
        let f = rc / 0.7f64.powf(0.25).acos().tan();
        let theta = (100.0f64 / f).atan();
        assert!((vignette(v, w, h, 420.0, 240.0) - theta.cos().powi(4)).abs() < 1e-12);
        assert_eq!(vignette(0.0, w, h, 0.0, 0.0), 1.0);
    }

    /// The ring's top face has the grey level given (lighter than the
    /// background here), the ring's side keeps its level.
    #[test]
    fn the_lighter_ring_face_rows_have_the_face_level() {
        let (sc, s) = linear_scene(Look {
            ring_face_grey: 230.0,
            ..Look::default()
        });
        let img = render(&sc, &s, &SHARP, 1);
        let a_px = sc.radius_m / sc.metres_per_pixel;
        let x = (sc.axis_x_px + 1.1 * a_px).round() as usize;
        let y_face = sc.clamp_row_px.ceil() as usize + 1;
        assert_eq!(img.data[y_face * sc.width + x], 230);
        let y_side = sc.height - 2;
        assert_eq!(img.data[y_side * sc.width + x], 38);
    }

    /// A light bubble on a dark wall: the dome's centre has the bubble's
    /// level, brighter than the wall above the apex.
    #[test]
    fn a_light_bubble_on_a_dark_wall() {
        let (sc, s) = linear_scene(Look {
            bubble_grey: 215.0,
            background_grey: 50.0,
            ..Look::default()
        });
        let img = render(&sc, &s, &SHARP, 1);
        let [ax, ay] = sc.apex_px(&s);
        let x = ax.round() as usize;
        let inside = img.data[(ay + 8.0) as usize * sc.width + x];
        let above = img.data[(ay - 8.0) as usize * sc.width + x];
        assert!(
            inside >= 215 && above <= 70,
            "inside {inside}, above {above}"
        );
    }

    /// Light from one side scales the dome's light at `u = +-0.5 a` from
    /// the axis by `1 +- 0.5 S`; the shading is symmetric about the axis,
    /// so their ratio is `(1 + 0.5 S) / (1 - 0.5 S)`.
    #[test]
    fn side_light_shades_the_dome_across_its_columns() {
        let side = 0.4;
        let (sc, s) = linear_scene(Look {
            side_light: side,
            ..Look::default()
        });
        let img = render(&sc, &s, &SHARP, 1);
        // The axis on a pixel centre so that +-0.5 a are mirror columns.
        let a_px = sc.radius_m / sc.metres_per_pixel;
        let y = (sc.clamp_row_px - 3.0).round() as usize;
        let mut ratios = Vec::new();
        for d in [0.3, 0.5, 0.7] {
            let xr = sc.axis_x_px + d * a_px;
            let xl = sc.axis_x_px - d * a_px;
            // Linear interpolation between the columns either side.
            let at = |x: f64| {
                let x0 = x.floor();
                let f = x - x0;
                let x0 = x0 as usize;
                let p = |x: usize| f64::from(img.data[y * sc.width + x]);
                p(x0) * (1.0 - f) + p(x0 + 1) * f
            };
            ratios.push((d, at(xr) / at(xl)));
        }
        for (d, r) in ratios {
            let want = (1.0 + side * d) / (1.0 - side * d);
            assert!((r / want - 1.0).abs() < 0.03, "u {d}: {r} vs {want}");
        }
    }
}
