//! A lens with distortion for the synthetic photos, and synthetic photos of a
//! calibration chessboard.
//!
//! Bubble photos ([`distort_light`]): the scene is drawn as the ideal
//! (pinhole) image with the exact coverage of every pixel and blurred; each
//! pixel of the photo then takes the light of the ideal image at its
//! undistorted position ([`Lens::undistort`]), by bicubic (Catmull-Rom)
//! interpolation. The blur (at least 0.5 px) makes the ideal image smooth
//! at the pixel scale, so the interpolation moves an edge by far less than
//! a hundredth of a pixel; a lens blurs in the photo rather than in the
//! ideal image, but the map is within 1 % of a translation over a blur's
//! width, so the difference is a 1 % change of the blur's width.
//!
//! Chessboards ([`render_board`]): a planar board seen by a pinhole camera
//! at a pose, each photo pixel traced back through the lens to the board
//! plane; pixels where a square's edge passes are supersampled 8 x 8 (area
//! anti-aliasing to 1/64 of a pixel's area), then blurred and given noise.

use super::super::image::Gray;
use super::super::lens::Lens;
use super::Rng;

/// The photo's light from the ideal image's: `ideal` is `w` x `h` light
/// values of the ideal (pinhole) image; the result's pixel `p` is
/// `ideal(lens.undistort(p))`.
pub fn distort_light(ideal: &[f64], w: usize, h: usize, lens: &Lens) -> Vec<f64> {
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let u = lens.undistort([x as f64, y as f64]);
            out[y * w + x] = bicubic(ideal, w, h, u[0], u[1]);
        }
    }
    out
}

/// Catmull-Rom interpolation of `img` at `(x, y)`, borders replicated.
fn bicubic(img: &[f64], w: usize, h: usize, x: f64, y: f64) -> f64 {
    let (xf, yf) = (x.floor(), y.floor());
    let (tx, ty) = (x - xf, y - yf);
    let weights = |t: f64| {
        let t2 = t * t;
        let t3 = t2 * t;
        [
            0.5 * (-t3 + 2.0 * t2 - t),
            0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2),
        ]
    };
    let (wx, wy) = (weights(tx), weights(ty));
    let clampi = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
    let mut acc = 0.0;
    for (j, wyj) in wy.iter().enumerate() {
        let yi = clampi(yf + j as f64 - 1.0, h);
        let mut row = 0.0;
        for (i, wxi) in wx.iter().enumerate() {
            let xi = clampi(xf + i as f64 - 1.0, w);
            row += wxi * img[yi * w + xi];
        }
        acc += wyj * row;
    }
    acc
}

/// A chessboard: `inner` = (columns, rows) of inner corners, squares of
/// `square_m` metres, with a white margin of one square around.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Board {
    /// Inner corners (columns, rows).
    pub inner: [usize; 2],
    /// Side of a square, m.
    pub square_m: f64,
}

impl Board {
    /// The inner corners in the board's plane, m, row by row from the
    /// top-left one (OpenCV's order for an upright board).
    pub fn corners_m(&self) -> Vec<[f64; 2]> {
        let mut v = Vec::new();
        for j in 0..self.inner[1] {
            for i in 0..self.inner[0] {
                v.push([
                    (i + 1) as f64 * self.square_m,
                    (j + 1) as f64 * self.square_m,
                ]);
            }
        }
        v
    }

    /// Light at the board point `(bx, by)`, m (the board's top-left square's
    /// corner at the origin): 0.85 on white, 0.08 on black, 0.4 off the board.
    fn light(&self, bx: f64, by: f64) -> f64 {
        let s = self.square_m;
        let (nx, ny) = (self.inner[0] + 1, self.inner[1] + 1);
        let (i, j) = ((bx / s).floor(), (by / s).floor());
        if i < -1.0 || j < -1.0 || i > nx as f64 || j > ny as f64 {
            0.4
        } else if i < 0.0 || j < 0.0 || i >= nx as f64 || j >= ny as f64 {
            0.85
        } else if (i as i64 + j as i64) % 2 == 0 {
            0.08
        } else {
            0.85
        }
    }
}

/// A pose of the board: rotation (a rotation vector, radians) and the
/// position of its origin in the camera's frame, m (z along the view).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation vector (axis times angle), rad.
    pub rvec: [f64; 3],
    /// Translation, m.
    pub t: [f64; 3],
}

impl Pose {
    /// The rotation matrix (Rodrigues' formula).
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        let [a, b, c] = self.rvec;
        let th = (a * a + b * b + c * c).sqrt();
        if th < 1e-15 {
            return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        }
        let k = [a / th, b / th, c / th];
        let (s, cth) = th.sin_cos();
        let v = 1.0 - cth;
        [
            [
                cth + k[0] * k[0] * v,
                k[0] * k[1] * v - k[2] * s,
                k[0] * k[2] * v + k[1] * s,
            ],
            [
                k[1] * k[0] * v + k[2] * s,
                cth + k[1] * k[1] * v,
                k[1] * k[2] * v - k[0] * s,
            ],
            [
                k[2] * k[0] * v - k[1] * s,
                k[2] * k[1] * v + k[0] * s,
                cth + k[2] * k[2] * v,
            ],
        ]
    }

    /// The ideal (pinhole) pixel of the board point `(bx, by)`, m.
    pub fn project(&self, lens: &Lens, b: [f64; 2]) -> [f64; 2] {
        let r = self.matrix();
        let p: Vec<f64> = (0..3)
            .map(|i| r[i][0] * b[0] + r[i][1] * b[1] + self.t[i])
            .collect();
        [
            lens.fx * p[0] / p[2] + lens.cx,
            lens.fy * p[1] / p[2] + lens.cy,
        ]
    }
}

/// `n` poses of `board` filling different parts of a `w` x `h` photo seen
/// with `lens`: tilted by 10-40 degrees about varied axes, the board's
/// centre moved towards the photo's corners and edges, at a distance where
/// it spans about half the photo's width; each pose is moved in until the
/// whole board (with its margin) is inside the photo with 4 % to spare.
pub fn board_poses(
    board: &Board,
    lens: &Lens,
    w: usize,
    h: usize,
    n: usize,
    seed: u64,
) -> Vec<Pose> {
    let mut rng = Rng::new(seed ^ 0xB0A2D);
    let bw = (board.inner[0] + 3) as f64 * board.square_m;
    let bh = (board.inner[1] + 3) as f64 * board.square_m;
    let z0 = lens.fx * bw / (0.55 * w as f64);
    let outline = [
        [-board.square_m; 2],
        [bw - board.square_m, -board.square_m],
        [-board.square_m, bh - board.square_m],
        [bw - board.square_m, bh - board.square_m],
    ];
    let mut poses = Vec::with_capacity(n);
    for i in 0..n {
        let ang = std::f64::consts::TAU * (i as f64 / n as f64 + 0.1 * rng.uniform());
        let tilt = (10.0 + 30.0 * rng.uniform()).to_radians();
        let axis = std::f64::consts::TAU * rng.uniform();
        let roll = (rng.uniform() - 0.5) * 0.4;
        let rvec = [tilt * axis.cos(), tilt * axis.sin(), roll];
        // Where the board's centre goes, as a fraction of the half-photo.
        let reach = if i % 4 == 0 {
            0.0
        } else {
            0.55 + 0.3 * rng.uniform()
        };
        let z = z0 * (0.85 + 0.3 * rng.uniform());
        let mut f = 1.0;
        let pose = loop {
            let cxn = f * reach * ang.cos() * 0.5 * w as f64 / lens.fx;
            let cyn = f * reach * ang.sin() * 0.5 * h as f64 / lens.fy;
            let mut p = Pose {
                rvec,
                t: [0.0, 0.0, z],
            };
            // Put the board's centre on the wanted ray.
            let r = p.matrix();
            let c = [0.5 * bw - board.square_m, 0.5 * bh - board.square_m];
            let rc: Vec<f64> = (0..3).map(|k| r[k][0] * c[0] + r[k][1] * c[1]).collect();
            p.t = [cxn * z - rc[0], cyn * z - rc[1], z - rc[2]];
            let inside = outline.iter().all(|&b| {
                let q = lens.distort(p.project(lens, b));
                let m = 0.04;
                q[0] > m * w as f64
                    && q[0] < (1.0 - m) * w as f64
                    && q[1] > m * h as f64
                    && q[1] < (1.0 - m) * h as f64
            });
            if inside || f < 0.05 {
                break p;
            }
            f *= 0.9;
        };
        poses.push(pose);
    }
    poses
}

/// A photo of `board` at `pose` through `lens`: `w` x `h` px, 8 x 8
/// supersampled where an edge of a square passes, blurred by a Gaussian of
/// `blur_px`, with `noise_grey` grey levels of noise (seeded), levels
/// linear in the light.
#[allow(clippy::too_many_arguments)]
pub fn render_board(
    board: &Board,
    pose: &Pose,
    lens: &Lens,
    w: usize,
    h: usize,
    blur_px: f64,
    noise_grey: f64,
    seed: u64,
) -> Gray {
    // The board point seen at a photo point: undistort, then back along the
    // ray to the plane (the inverse of the homography K [r1 r2 t]).
    let r = pose.matrix();
    let hm = nalgebra::Matrix3::new(
        r[0][0], r[0][1], pose.t[0], r[1][0], r[1][1], pose.t[1], r[2][0], r[2][1], pose.t[2],
    );
    let inv = hm.try_inverse().expect("a board seen edge-on");
    let at = |p: [f64; 2]| -> f64 {
        let u = lens.undistort(p);
        let n = nalgebra::Vector3::new((u[0] - lens.cx) / lens.fx, (u[1] - lens.cy) / lens.fy, 1.0);
        let b = inv * n;
        board.light(b[0] / b[2], b[1] / b[2])
    };
    // The light at every pixel corner, then each pixel: uniform when its
    // corners and centre agree, else supersampled.
    let corners: Vec<f64> = (0..=h)
        .flat_map(|j| (0..=w).map(move |i| (i, j)))
        .map(|(i, j)| at([i as f64 - 0.5, j as f64 - 0.5]))
        .collect();
    let ss = 8;
    let mut img = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let c = [
                corners[y * (w + 1) + x],
                corners[y * (w + 1) + x + 1],
                corners[(y + 1) * (w + 1) + x],
                corners[(y + 1) * (w + 1) + x + 1],
                at([x as f64, y as f64]),
            ];
            img[y * w + x] = if c.iter().all(|&v| v == c[0]) {
                c[0]
            } else {
                let mut acc = 0.0;
                for b in 0..ss {
                    for a in 0..ss {
                        acc += at([
                            x as f64 - 0.5 + (a as f64 + 0.5) / ss as f64,
                            y as f64 - 0.5 + (b as f64 + 0.5) / ss as f64,
                        ]);
                    }
                }
                acc / (ss * ss) as f64
            };
        }
    }
    if blur_px > 0.0 {
        super::gaussian_blur(&mut img, w, h, blur_px);
    }
    let mut rng = Rng::new(seed);
    let data = img
        .iter()
        .map(|&l| {
            (255.0 * l + noise_grey * rng.normal())
                .round()
                .clamp(0.0, 255.0) as u8
        })
        .collect();
    Gray::new(w, h, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight vertical edge in the ideal image, through a lens, lands
    /// where `Lens::distort` puts it (the 50 % crossing of its profile).
    #[test]
    fn distorted_edge_lands_where_the_model_puts_it() {
        let (w, h) = (200, 120);
        let lens = Lens {
            k1: -0.2,
            ..Lens::pinhole(300.0, 300.0, 99.5, 59.5)
        };
        // ideal: dark left of column 150.3, light right, blurred
        let e = 150.3;
        let mut ideal: Vec<f64> = (0..w * h)
            .map(|k| ((k % w) as f64 + 0.5 - e).clamp(0.0, 1.0))
            .collect();
        super::super::gaussian_blur(&mut ideal, w, h, 1.0);
        let photo = distort_light(&ideal, w, h, &lens);
        for y in [20usize, 60, 100] {
            // the photo's edge: the centroid of its row's differences over
            // +-10 px (a blurred step of sigma >= 1 px is well sampled: the
            // centroid does not depend on the sampling's phase)
            let row = &photo[y * w..(y + 1) * w];
            let i = (1..w).find(|&i| row[i - 1] < 0.5 && row[i] >= 0.5).unwrap();
            let (mut sw, mut sx) = (0.0, 0.0);
            for k in i - 10..i + 10 {
                let d = row[k + 1] - row[k];
                sw += d;
                sx += d * (k as f64 + 0.5);
            }
            let x = sx / sw;
            // where the model sends the ideal edge at this photo row
            let mut lo = 100.0;
            let mut hi = 199.0;
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if lens.undistort([m, y as f64])[0] < e {
                    lo = m
                } else {
                    hi = m
                }
            }
            assert!((x - lo).abs() < 0.005, "row {y}: {x} vs {lo}");
        }
    }

    #[test]
    fn the_board_projects_inside_the_photo() {
        let lens = Lens {
            k1: -0.1,
            ..Lens::pinhole(800.0, 800.0, 319.5, 239.5)
        };
        let board = Board {
            inner: [9, 6],
            square_m: 0.02,
        };
        for p in board_poses(&board, &lens, 640, 480, 12, 1) {
            for c in board.corners_m() {
                let q = lens.distort(p.project(&lens, c));
                assert!(
                    q[0] > 0.0 && q[0] < 640.0 && q[1] > 0.0 && q[1] < 480.0,
                    "{q:?}"
                );
            }
        }
    }
}
