//! Tests of the synthetic photos: geometry, coverage, rendering and files.

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
    assert_eq!(e.what, "a side of the bubble");
    assert_eq!(e.axis_x_px, 20.0);
    let m = e.to_string();
    assert!(
        m.contains("side of the bubble") && m.contains("axis_x_px"),
        "{m}"
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
