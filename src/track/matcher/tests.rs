//! Tests of the template match, the edge model, the apex fit and its
//! stated error.

use super::*;

mod light;

#[test]
fn quadratic_peak_recovers_offset_of_a_paraboloid() {
    let (px, py) = (0.3, -0.2);
    let mut f = [[0.0; 3]; 3];
    for (j, row) in f.iter_mut().enumerate() {
        for (i, v) in row.iter_mut().enumerate() {
            let (x, y) = (i as f64 - 1.0, j as f64 - 1.0);
            *v = 1.0 - 0.2 * (x - px).powi(2) - 0.1 * (y - py).powi(2) + 0.05 * (x - px) * (y - py);
        }
    }
    let (ox, oy) = quadratic_peak(&f);
    assert!(
        (ox - px).abs() < 1e-12 && (oy - py).abs() < 1e-12,
        "{ox} {oy}"
    );
}

#[test]
fn reduce_is_the_rounded_block_mean() {
    let (w, h) = (37usize, 23usize);
    let img = Gray {
        width: w,
        height: h,
        data: (0..w * h).map(|i| ((i * 7919) % 251) as u8).collect(),
        tone: crate::track::image::Tone::LINEAR,
    };
    for f in [2usize, 3] {
        let r = reduce(&img, f).unwrap();
        assert_eq!((r.width, r.height), (w / f, h / f));
        for y in 0..h / f {
            for x in 0..w / f {
                let mut sum = 0u32;
                for j in 0..f {
                    for i in 0..f {
                        sum += u32::from(img.at(x * f + i, y * f + j));
                    }
                }
                let want = (f64::from(sum) / (f * f) as f64).round();
                assert!(
                    (f64::from(r.at(x, y)) - want).abs() <= 0.5,
                    "f {f} ({x}, {y})"
                );
            }
        }
    }
}

/// The O(1) evaluation of the even fit's RSS against refitting the
/// points directly (SVD of the design matrix) at several axes.
#[test]
fn even_fit_rss_matches_a_direct_refit() {
    let pts: Vec<(f64, f64)> = (0..150)
        .map(|i| {
            let x = 100.0 + i as f64;
            let u = x - 173.4;
            (
                x,
                40.0 + 0.01 * u * u - 2e-7 * u.powi(4) + 0.3 * (i as f64 * 1.7).sin(),
            )
        })
        .collect();
    let rss = even_fit_rss(&pts, 175.0, 75.0);
    for s in [167.0, 171.2, 173.4, 175.0, 180.9] {
        let a = nalgebra::DMatrix::from_fn(pts.len(), 3, |r, c| {
            ((pts[r].0 - s) / 75.0).powi(2 * c as i32)
        });
        let y = nalgebra::DVector::from_iterator(pts.len(), pts.iter().map(|p| p.1));
        let coef = a.clone().svd(true, true).solve(&y, 1e-14).unwrap();
        let direct = (&y - &a * coef).norm_squared();
        let fast = rss(s);
        assert!(
            (fast - direct).abs() <= 1e-9 * direct.max(1.0),
            "s = {s}: {fast} vs {direct}"
        );
    }
}

/// A step blurred by a Gaussian and averaged over each pixel, built by
/// numerical quadrature (not through the model's closed forms): 200
/// above the edge, `60 + ramp (y - e)` below it.
fn blurred_step(e: f64, sigma: f64, ramp: f64, len: usize) -> Vec<f64> {
    blurred(
        |y| if y < e { 200.0 } else { 60.0 + ramp * (y - e) },
        sigma,
        len,
    )
}

/// The step model finds the edge of blurred, pixel-averaged steps to
/// 0.01 px at blurs of 0.8-2.5 px and any sub-pixel position, also with
/// a slope on the dome side that starts at the edge, which moves the
/// centroid by more than 0.05 px.
#[test]
fn the_step_model_is_not_moved_by_a_slope_under_the_edge() {
    for sigma in [0.8, 1.5, 2.5] {
        for e in [20.0, 20.27, 20.5, 20.81] {
            for ramp in [0.0, 10.0] {
                let p = blurred_step(e, sigma, ramp, 40);
                let px = |j: i64| p[j as usize];
                let m = step_model_edge(px, 40, e.round() + 0.3).unwrap();
                assert!(
                    (m - e).abs() < 0.01,
                    "sigma {sigma} edge {e} ramp {ramp}: model {m}"
                );
                if ramp > 0.0 && sigma >= 1.5 {
                    let (c, _) = profile_edge(px, 40, e, 3.0).unwrap();
                    assert!(
                        (c - e).abs() > 0.05,
                        "sigma {sigma} edge {e}: centroid {c}, no bias to show"
                    );
                }
            }
        }
    }
}

/// A dome with an area-sampled edge: rows covered by a parabola
/// `y = y0 + k (x - xa)^2`, background 200 above, 60 below, integrated
/// exactly per pixel (supersampled 64x in x, exact in y).
#[test]
fn edge_fit_finds_sub_pixel_apex() {
    let (w, h) = (80usize, 60usize);
    let (xa, y0, k) = (40.3, 25.37, 0.004);
    let mut data = vec![0u8; w * h];
    let mut fdata = vec![0.0f64; w * h];
    for x in 0..w {
        for sx in 0..64 {
            let xs = x as f64 - 0.5 + (sx as f64 + 0.5) / 64.0;
            let e = y0 + k * (xs - xa).powi(2);
            for y in 0..h {
                // pixel y spans [y - 0.5, y + 0.5); below the edge is dome.
                let cov = ((y as f64 + 0.5) - e).clamp(0.0, 1.0);
                fdata[y * w + x] += cov / 64.0;
            }
        }
    }
    for (d, f) in data.iter_mut().zip(&fdata) {
        *d = (200.0 - 140.0 * f).round() as u8;
    }
    let img = Gray {
        width: w,
        height: h,
        data,
        tone: crate::track::image::Tone::LINEAR,
    };
    let fit = edge_fit(
        &img,
        40.0,
        25.0,
        EdgeSettings {
            half_span_px: 20,
            half_window_px: 6,
        },
    )
    .unwrap();
    assert!((fit.y - y0).abs() < 0.02, "apex row {} vs {y0}", fit.y);
    assert!(
        (fit.curvature - 2.0 * k).abs() < 1e-3,
        "curvature {}",
        fit.curvature
    );
}

/// A camera blurs light and then encodes it with its tone curve: the
/// blurred step in light is odd about the edge, so its halfway level
/// is on the edge; the encoded step is not. A dome edge (a dark dome,
/// grey 72, on a light wall, grey 190, as encoded levels) blurred by a
/// Gaussian of 1.5 px in light and written through the sRGB curve is
/// found within 0.03 px when read back through the curve, and a fifth
/// of a pixel off (towards the dark side) when its grey levels are
/// taken for light.
#[test]
fn an_edge_written_through_the_srgb_curve_is_found_in_light() {
    use crate::camera::Response;
    let (w, h) = (90usize, 60usize);
    let (xa, y0, k) = (45.2, 28.63, 0.003);
    let srgb = Response::Srgb;
    let (wall, dome_l) = (srgb.to_linear(190.0 / 255.0), srgb.to_linear(72.0 / 255.0));
    let mut data = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let cov = coverage(x, y, (xa, y0, k), 1.5);
            let light = wall + (dome_l - wall) * cov;
            data[y * w + x] = (255.0 * srgb.encode(light)).round() as u8;
        }
    }
    let settings = EdgeSettings {
        half_span_px: 20,
        half_window_px: 6,
    };
    let img = Gray::new(w, h, data);
    let as_pixels = edge_fit(&img, 45.0, 29.0, settings).unwrap();
    let img = img.with_tone(crate::track::image::Tone::of(srgb));
    let in_light = edge_fit(&img, 45.0, 29.0, settings).unwrap();
    assert!(
        (in_light.y - y0).abs() < 0.03,
        "in light: apex row {} vs {y0}",
        in_light.y
    );
    assert!(
        as_pixels.y - y0 > 0.15,
        "grey levels taken for light: apex row {} vs {y0}",
        as_pixels.y
    );
}

/// The share of pixel `(x, y)` below a dome's top edge `y0 + k (x -
/// xa)^2` blurred by a Gaussian of `sigma` px (8x8 samples a pixel).
pub(crate) fn coverage(x: usize, y: usize, (xa, y0, k): (f64, f64, f64), sigma: f64) -> f64 {
    let mut cov = 0.0;
    for sx in 0..8 {
        let xs = x as f64 - 0.5 + (sx as f64 + 0.5) / 8.0;
        let e = y0 + k * (xs - xa).powi(2);
        for sy in 0..8 {
            let ys = y as f64 - 0.5 + (sy as f64 + 0.5) / 8.0;
            cov += normal_cdf((ys - e) / sigma) / 64.0;
        }
    }
    cov
}

/// A dome's top edge `y0 + k (x - xa)^2` (background 200 above, dome 60
/// below, blurred by a Gaussian of 1.5 px, each pixel the mean over its
/// area) with `extra(x, y)` grey levels added.
fn dome(
    (w, h): (usize, usize),
    (xa, y0, k): (f64, f64, f64),
    extra: impl Fn(f64, f64) -> f64,
) -> Gray {
    let mut data = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let cov = coverage(x, y, (xa, y0, k), 1.5);
            let v = 200.0 - 140.0 * cov + extra(x as f64, y as f64);
            data[y * w + x] = v.round().clamp(0.0, 255.0) as u8;
        }
    }
    Gray {
        width: w,
        height: h,
        data,
        tone: crate::track::image::Tone::LINEAR,
    }
}

#[test]
fn the_even_fit_on_the_axis_holds_the_apex_when_one_side_is_spoiled() {
    // A broad highlight on the dome just under the edge, left of the
    // axis (as a small light reflected off the pole's side): it
    // brightens the dome side of the columns there.
    let (xa, y0, k) = (60.4, 30.3, 0.006);
    let img = dome((120, 70), (xa, y0, k), |x, y| {
        let e = y0 + k * (x - xa).powi(2);
        if y + 0.5 > e {
            100.0 * (-0.5 * (((x - xa + 14.0) / 9.0).powi(2) + ((y - e - 4.0) / 2.5).powi(2))).exp()
        } else {
            0.0
        }
    });
    let s = EdgeSettings {
        half_span_px: 24,
        half_window_px: 3,
    };
    let mut cols = Columns::new(&img, s.half_window_px);
    let free = edge_fit_in(&mut cols, 58.0, 30.0, 2.0 * k, s).unwrap();
    // The scene spoils the free parabola (else the test shows nothing):
    // its apex comes out 0.19 px high, 8 of its standard errors; on the
    // axis 0.07 px, 3 of them.
    assert!(
        (free.y - y0).abs() > 0.1,
        "free fit apex ({}, {}) against ({xa}, {y0})",
        free.x_vertex,
        free.y
    );
    let on_axis = edge_fit_about(&mut cols, (xa, 0.1), &free, s).unwrap();
    assert!(
        (on_axis.y - y0).abs() < 0.1,
        "apex row {} +- {} against {y0}",
        on_axis.y,
        on_axis.y_std
    );
    assert!((on_axis.y - y0).abs() < 4.0 * on_axis.y_std.hypot(0.01));
    assert_eq!(on_axis.x_vertex, xa);
}

/// The edge fit of `img` from `(x0, y0)` with the starting curvature
/// given, against the emptiest frame `emptiest` (half-window 3 px).
fn fit_against_emptiest(
    img: &Gray,
    emptiest: &Gray,
    (x0, y0, curvature): (f64, f64, f64),
    s: EdgeSettings,
) -> Option<EdgeFit> {
    let extremes = Extremes {
        fullest: None,
        emptiest: Some(emptiest),
        is_emptiest: false,
    };
    edge_fit_in(
        &mut Columns::with_extremes(img, 3, extremes),
        x0,
        y0,
        curvature,
        s,
    )
}

#[test]
fn a_static_line_above_the_edge_cancels_against_the_emptiest_frame() {
    // A dark line behind the bubble (a cable, 3 px wide) whose lower
    // border lies 2-3 px above the top edge, in this frame and in the
    // emptiest one, whose top is 15 px lower.
    let (xa, y0, k) = (60.2, 30.4, 0.004);
    // The line, blurred like the edge, seen where the dome (`top` its
    // edge) does not hide it.
    let line = |x: f64, y: f64, top: f64| {
        let on = normal_cdf((y - (y0 - 7.0)) / 1.5) - normal_cdf((y - (y0 - 3.0)) / 1.5);
        let seen = 1.0 - normal_cdf((y - top - k * (x - xa).powi(2)) / 1.5);
        -110.0 * on * seen
    };
    let img = dome((120, 80), (xa, y0, k), |x, y| line(x, y, y0));
    let emptiest = dome((120, 80), (xa, y0 + 15.0, k), |x, y| line(x, y, y0 + 15.0));
    let s = EdgeSettings {
        half_span_px: 24,
        half_window_px: 3,
    };
    let plain = edge_fit_in(&mut Columns::new(&img, 3), 60.0, 30.0, 2.0 * k, s);
    assert!(
        plain.is_none_or(|f| (f.y - y0).abs() > 0.1),
        "without the emptiest frame the line biases the edge: {plain:?}"
    );
    let fit = fit_against_emptiest(&img, &emptiest, (60.0, 30.0, 2.0 * k), s).unwrap();
    assert!((fit.y - y0).abs() < 0.05, "apex row {} against {y0}", fit.y);
}

#[test]
fn a_line_along_the_top_is_left_out_not_taken_for_it() {
    // A dark line behind the bubble (a cable, 3 px wide, as dark as the
    // dome) across the apex: from 2 px above the top to 1 px below it,
    // so that the top runs along it, dark against dark, and the columns
    // near the apex show only the line's upper border. The emptiest
    // frame's top is 15 px lower.
    let (xa, y0, k) = (80.2, 30.4, 0.01);
    // The scene blurred: the whole line less its part the dome hides
    // (the edge taken as straight across the line, the blur linear).
    let band = |y: f64, a: f64, b: f64| normal_cdf((y - a) / 1.5) - normal_cdf((y - b) / 1.5);
    let (a, b) = (y0 - 2.0, y0 + 1.0);
    let line = |x: f64, y: f64, top: f64| {
        let t = top + k * (x - xa).powi(2);
        let hidden = if t < b { band(y, t.max(a), b) } else { 0.0 };
        -140.0 * (band(y, a, b) - hidden)
    };
    let img = dome((160, 80), (xa, y0, k), |x, y| line(x, y, y0));
    let emptiest = dome((160, 80), (xa, y0 + 15.0, k), |x, y| line(x, y, y0 + 15.0));
    let s = EdgeSettings {
        half_span_px: 40,
        half_window_px: 3,
    };
    let plain = edge_fit_in(&mut Columns::new(&img, 3), 80.0, 30.0, 2.0 * k, s).unwrap();
    assert!(
        y0 - plain.y > 1.0,
        "without the emptiest frame the edge sits on the line: {plain:?}"
    );
    // The apex column's edge is the line's upper border, and so known.
    let (e, step) = column_edge(&img, 80, y0, 3.0).unwrap();
    assert!(y0 - e > 1.0 && static_line_on_edge(&img, &emptiest, 80, e, 3.0, step));
    let fit = fit_against_emptiest(&img, &emptiest, (80.0, 30.0, 2.0 * k), s).unwrap();
    assert!(
        (fit.y - y0).abs() < 0.05 && (fit.y - y0).abs() < 4.0 * fit.y_std,
        "apex row {} +- {} against {y0}",
        fit.y,
        fit.y_std
    );
    // Without the line, an emptiest frame whose top lies only 1 px
    // lower shows its own dome under the edge, not a line: no column
    // is taken for one.
    let clean = dome((160, 80), (xa, y0, k), |_, _| 0.0);
    let close = dome((160, 80), (xa, y0 + 1.0, k), |_, _| 0.0);
    for c in 40..=120 {
        let t = y0 + k * (c as f64 - xa).powi(2);
        let (e, step) = column_edge(&clean, c, t, 3.0).unwrap();
        assert!(
            !static_line_on_edge(&clean, &close, c, e, 3.0, step),
            "column {c}"
        );
    }
}

#[test]
fn a_broad_flank_under_the_edge_widens_the_apex_uncertainty() {
    // A broad highlight on the dome (40 grey levels, 8 px under the
    // top, 4 px high and 25 px wide in standard deviations) whose
    // upper flank rises slowly from the edge and turns within the
    // slope rows: no spot, no weakened column, but the centroids are
    // lifted.
    let (xa, y0, k) = (80.2, 30.4, 0.004);
    let glow = |x: f64, y: f64| {
        let on = normal_cdf((y - y0 - k * (x - xa).powi(2)) / 1.5);
        40.0 * on * (-0.5 * (((x - xa) / 25.0).powi(2) + ((y - y0 - 8.0) / 4.0).powi(2))).exp()
    };
    let img = dome((160, 80), (xa, y0, k), glow);
    let (e, step) = column_edge(&img, 80, y0, 3.0).unwrap();
    assert!(turns_back(&img, 80, e, 3.0, step) && !spot_below(&img, 80, e, 3.0, step));
    let s = EdgeSettings {
        half_span_px: 40,
        half_window_px: 3,
    };
    let fit = edge_fit_in(&mut Columns::new(&img, 3), 80.0, 30.0, 2.0 * k, s).unwrap();
    let err = fit.y - y0;
    assert!(
        err.abs() > 0.15 && err.abs() < 4.0 * fit.y_std,
        "apex row {err:+.3} px off, stated std {:.3} px",
        fit.y_std
    );
}

#[test]
fn a_faint_blurred_line_above_the_top_is_found() {
    // One column: a background of 150 above a weak edge at row 40.3
    // (down to 90, blur 1.5 px), and a cable 60 grey levels dark and 3
    // px wide (40 after the blur) whose centre lies 8 px above the edge:
    // its flanks change by less than 15 grey levels a row, by more
    // than 22.5 over two.
    let column = |cable: f64| {
        let band = |y: f64, a: f64, b: f64| normal_cdf((y - a) / 1.5) - normal_cdf((y - b) / 1.5);
        let data = (0..60)
            .map(|j| {
                let y = j as f64;
                let v = 150.0 - 60.0 * normal_cdf((y - 40.3) / 1.5) - cable * band(y, 30.8, 33.8);
                v.round() as u8
            })
            .collect();
        Gray {
            width: 1,
            height: 60,
            data,
            tone: crate::track::image::Tone::LINEAR,
        }
    };
    let with = column(60.0);
    let rows: Vec<i32> = (25..36).map(|j| i32::from(with.at(0, j))).collect();
    assert!(
        rows.windows(2).all(|w| (w[1] - w[0]).abs() <= 15),
        "{rows:?}"
    );
    let (e, step) = column_edge(&with, 0, 40.0, 3.0).unwrap();
    assert!(line_above(&with, 0, e, 3.0, step));
    let (e, step) = column_edge(&column(0.0), 0, 40.0, 3.0).unwrap();
    assert!(!line_above(&column(0.0), 0, e, 3.0, step));
}

#[test]
fn a_spot_under_the_edge_is_told_from_shading_and_the_clamp() {
    // One column, 40 rows: background 200 above an edge at row 15.3,
    // a dome at 60 below it (blur 1.2 px), with what lies under it.
    let column = |under: &dyn Fn(f64) -> f64| {
        let p = blurred_step(15.3, 1.2, 0.0, 40);
        Gray {
            width: 1,
            height: 40,
            data: p
                .iter()
                .enumerate()
                .map(|(j, v)| (v + under(j as f64)).round().clamp(0.0, 255.0) as u8)
                .collect(),
            tone: crate::track::image::Tone::LINEAR,
        }
    };
    let found = |img: &Gray| {
        let (e, step) = column_edge(img, 0, 15.0, 3.0).unwrap();
        spot_below(img, 0, e, 3.0, step)
    };
    let below = |y: f64| if y > 15.3 { 1.0 } else { 0.0 };
    // A highlight 40 grey levels high (29 % of the step), 5 px under
    // the edge: a spot.
    let spot = |y: f64| 40.0 * (-0.5 * ((y - 20.3) / 1.5).powi(2)).exp() * below(y);
    assert!(found(&column(&spot)));
    // Half as high (14 %): below the share.
    assert!(!found(&column(&|y| 0.5 * spot(y))));
    // Shading that brightens steadily away from the edge (3 grey
    // levels a row) turns back but never away again.
    assert!(!found(&column(&|y| 3.0 * (y - 15.3).max(0.0))));
    // A brighter clamp fixture 6 px under a low top: a step, no spot.
    assert!(!found(&column(&|y| if y > 21.3 { 80.0 } else { 0.0 })));
}

#[test]
fn the_mirror_test_measures_a_one_sided_shift() {
    // An even edge about the axis, the columns of one side lifted by
    // 0.4 px (a highlight's bias): the sides' apex rows differ by 0.4,
    // and half of it is the joint fit's bias; a symmetric edge has none.
    let edge = |lift: f64| -> Vec<(f64, f64)> {
        (-20..=20)
            .filter(|&u| u != 0)
            .map(|u| {
                let u = f64::from(u);
                (u, 30.0 + 0.005 * u * u - if u < 0.0 { lift } else { 0.0 })
            })
            .collect()
    };
    assert!(sides_bias2(&edge(0.0)).abs() < 1e-12);
    assert!((sides_bias2(&edge(0.4)) - 0.04).abs() < 1e-9);
    // Too few columns on one side: no test.
    let one_sided: Vec<(f64, f64)> = edge(0.4).into_iter().filter(|p| p.0 > -4.0).collect();
    assert_eq!(sides_bias2(&one_sided), 0.0);
}

#[test]
fn the_tail_of_a_spot_beyond_the_columns_left_out_widens_the_apex_uncertainty() {
    // An even edge `y = 30 + 0.002 u^2` about the axis, its columns
    // left of u = 4 left out for a spot (located, but spotted or
    // weakened), the right side's kept with noise. The spot's tail lifts
    // the kept columns next to it, by `tail` px at u = 4, fading over
    // `fade` px (as on 640x480 photos with the highlight beside the
    // top, where the apex came out 0.12-0.16 px high at 4-5 standard
    // errors).
    let edge = |us: &[i32], tail: f64, fade: f64, noise: f64| -> Vec<(f64, f64)> {
        us.iter()
            .map(|&u| {
                let u = f64::from(u);
                let hash = ((((u as u64) * 2_654_435_761) >> 9) % 11) as f64;
                let lift = tail * (-(u - 4.0) / fade).exp();
                (u, 30.0 + 0.002 * u * u - lift + noise * (hash - 5.0) / 5.0)
            })
            .collect()
    };
    let apex = |pts: &[(f64, f64)]| {
        let f = parabola(pts, true).unwrap();
        let std = f.var_at(0.0).sqrt() * lag1_inflation(&f.residuals(pts));
        (f.coef[0] - 30.0, std)
    };
    let widened = |std: f64, term: f64| (std * std + term).sqrt();
    let out: Vec<f64> = (-16..4).map(f64::from).collect();
    let us: Vec<i32> = (4..=32).collect();
    // With the tail the fit alone puts the apex high, beyond 4 of its
    // standard errors (0.116 px at 0.027 px); the tail's term covers
    // it (0.055 px).
    let lifted = edge(&us, 0.2, 8.0, 0.02);
    let (err, std) = apex(&lifted);
    let tail = tail_bias2(&lifted, &out, 32.0, 0.0, true, false);
    assert!(
        err < -0.1 && err.abs() > 4.0 * std,
        "{err:+.3} px at {std:.3} px: the scene shows nothing"
    );
    assert!(
        err.abs() < 4.0 * widened(std, tail),
        "{err:+.3} px off, stated {:.3} px with the tail",
        widened(std, tail)
    );
    // Without it the term stays within the noise.
    let clean = edge(&us, 0.0, 8.0, 0.02);
    let (_, std) = apex(&clean);
    assert!(tail_bias2(&clean, &out, 32.0, 0.0, true, false) < std * std);
    // Nothing left out: no term.
    assert_eq!(tail_bias2(&lifted, &[], 32.0, 0.0, true, false), 0.0);

    // Fewer columns, all within the tail's reach, and one amid them
    // left out too (u = 9), as where a cable hides the far side: the
    // columns beyond the reach are too few to tell the tail from
    // noise, and the fit's error only covers it as the one side's
    // (0.111 px off at 0.018 px; 0.051 px as one side's).
    let us: Vec<i32> = (4..24).filter(|&u| u != 9).collect();
    let out: Vec<f64> = (-16..4).chain([9]).map(f64::from).collect();
    let pts = edge(&us, 0.12, 12.0, 0.06);
    let (err, std) = apex(&pts);
    let two = widened(std, tail_bias2(&pts, &out, 32.0, 0.0, true, false));
    let one = widened(std, tail_bias2(&pts, &out, 32.0, 0.0, true, true));
    assert!(
        err < -0.1 && err.abs() > 4.0 * two,
        "{err:+.3} px at {two:.3} px: the scene shows nothing"
    );
    assert!(
        err.abs() < 4.0 * one,
        "{err:+.3} px off, stated {one:.3} px as one side's"
    );
}

/// A profile `f(y)` blurred by a Gaussian and averaged over each pixel, by
/// numerical quadrature.
fn blurred(f: impl Fn(f64) -> f64, sigma: f64, len: usize) -> Vec<f64> {
    let (n_px, n_k) = (24, 3000);
    (0..len)
        .map(|j| {
            let (mut acc, mut wsum) = (0.0, 0.0);
            for a in 0..n_px {
                let y = j as f64 - 0.5 + (a as f64 + 0.5) / n_px as f64;
                for b in 0..n_k {
                    let t = -6.0 * sigma + 12.0 * sigma * (b as f64 + 0.5) / n_k as f64;
                    let w = (-0.5 * (t / sigma).powi(2)).exp();
                    acc += w * f(y - t);
                    wsum += w;
                }
            }
            acc / wsum
        })
        .collect()
}

/// A step at row `e` from `above` to the dome's light `dome(d)` `d` px
/// under it, blurred by a Gaussian of `sigma` px and pixel-averaged, 64
/// rows ([`blurred`]; [`blurred_step`] with a straight dome side).
fn blurred_dome(above: f64, dome: impl Fn(f64) -> f64, e: f64, sigma: f64) -> Vec<f64> {
    blurred(|y| if y < e { above } else { dome(y - e) }, sigma, 64)
}

/// A profile as a `width`-column image of grey levels (linear light).
fn columns_image(p: &[f64], width: usize) -> Gray {
    Gray {
        width,
        height: p.len(),
        data: p
            .iter()
            .flat_map(|v| std::iter::repeat_n(v.round() as u8, width))
            .collect(),
        tone: crate::track::image::Tone::LINEAR,
    }
}

/// A plain step (200 over a dark dome of 60) blurred wider than the
/// window (a Gaussian of 2-3 px, whose tail reaches past the rows the
/// rim is read on) shows no rim: the tail under the edge is the mirror
/// of the tail above it, and what [`rim_tail`] reads of what is left
/// would shift the centroid ([`rim_shift`]) by less than 0.01 px in every
/// shape.
#[test]
fn a_blur_wider_than_the_window_is_not_read_as_a_rim() {
    let r = 300.0;
    for sigma in [2.0, 2.5, 3.0] {
        for e in [30.0, 30.4] {
            let p = blurred_step(e, sigma, 0.0, 64);
            let img = columns_image(&p, 1);
            let (c, step) = column_edge(&img, 0, e, 3.0).unwrap();
            for shape in RimShape::ALL {
                let (share, _) = rim_tail(&img, 0, c, 3.0, step, r, shape).unwrap();
                let shift = rim_shift(shape, share.abs(), 3.0, r);
                assert!(
                    shift < 0.01,
                    "sigma {sigma} e {e} {shape:?}: {shift:.4} px from the blur (share {share:.4})"
                );
            }
        }
    }
}

/// A matte light dome (a level of 200 falling as the cosine towards its
/// outline, `60 + 140 t`, Lambert's law lit from the camera's side) on a
/// dark wall (30), blurred and pixel-averaged over eight columns: the
/// matte shape fits it best, and the shift [`rim_bias`] states is within
/// half of the centroid's pull. Schlick's glossy shape fitted to the same
/// rows states more than 1.5 times the matte one's.
#[test]
fn a_matte_domes_fall_off_is_told_from_a_glossy_rim() {
    let r = 300.0;
    for sigma in [0.8, 1.5] {
        for e in [30.0, 30.4] {
            let p = blurred_dome(30.0, |d| 60.0 + 140.0 * (2.0 * d / r).sqrt(), e, sigma);
            let img = columns_image(&p, 8);
            let (c, step) = column_edge(&img, 0, e, 3.0).unwrap();
            let columns: Vec<(f64, f64, f64)> = (0..8).map(|u| (u as f64 - 3.5, c, step)).collect();
            let stated = rim_bias(&img, &columns, 3.5, 3.0, r);
            let fit = |shape| rim_tail(&img, 0, c, 3.0, step, r, shape).unwrap();
            let (matte, glossy) = (fit(RimShape::Matte), fit(RimShape::Glossy));
            assert!(
                matte.1 < glossy.1,
                "sigma {sigma} e {e}: {matte:?} {glossy:?}"
            );
            let glossy_shift = rim_shift(RimShape::Glossy, glossy.0, 3.0, r);
            let pulled = c - e;
            assert!(
                pulled > 0.05 && (pulled - stated).abs() <= 0.5 * stated,
                "sigma {sigma} e {e}: pulled {pulled:.3} px, stated {stated:.3}"
            );
            assert!(
                glossy_shift > 1.5 * stated,
                "sigma {sigma} e {e}: glossy {glossy_shift:.3} px, matte {stated:.3}"
            );
        }
    }
}

/// The first photo of a glossy light dome on a dark wall (45): near its
/// outline the coat reflects the wall, so its rows under the top (147)
/// lie 102 grey levels over the wall and 71 under the fullest frame's
/// (218) at the same rows, deeper inside that dome. The fullest frame's
/// test refuses the column ([`below_is_dome`]); the wall above the edge
/// tells it is a step from the wall ([`below_is_not_wall`]). The upper
/// border of a thin dark line on a light wall (190), under which the wall
/// resumes, is no such step.
#[test]
fn a_glossy_first_top_stands_off_the_wall_and_a_lines_border_does_not() {
    for sigma in [0.8, 1.5] {
        for e in [30.0, 30.4] {
            let first = columns_image(&blurred_dome(45.0, |_| 147.0, e, sigma), 1);
            let fullest = columns_image(&blurred_dome(218.0, |_| 218.0, e, sigma), 1);
            let (c, step) = column_edge(&first, 0, e, 3.0).unwrap();
            assert!(
                (c - e).abs() < 0.1,
                "sigma {sigma}: edge at {c}, drawn at {e}"
            );
            assert!(!below_is_dome(&first, &fullest, 0, c, step));
            assert!(below_is_not_wall(&first, 0, c, step));
            let line = blurred(
                |y| {
                    if (e..e + 2.0).contains(&y) {
                        95.0
                    } else {
                        190.0
                    }
                },
                sigma,
                64,
            );
            let line = columns_image(&line, 1);
            let (c, step) = column_edge(&line, 0, e, 3.0).unwrap();
            // the line's upper border (its lower one steps up)
            assert!(step < 0.0 && c < e + 1.0, "sigma {sigma}: {c} {step}");
            assert!(
                !below_is_not_wall(&line, 0, c, step),
                "sigma {sigma} e {e}: the line's border at {c} taken for a step"
            );
        }
    }
}
