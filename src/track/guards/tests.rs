//! The guards' own tests: each rule on fabricated edge fits and apexes,
//! the curvature correction and the residual bound against their references.

use super::*;

/// An edge fit of curvature `k` (1/px, standard error `ks`).
fn edge(k: f64, ks: f64) -> EdgeFit {
    EdgeFit {
        y: 0.0,
        y_std: 0.02,
        x_vertex: 300.0,
        x_std: 0.3,
        curvature: k,
        curvature_std: ks,
        y_curvature_cov: 0.0,
        columns: 120,
        rms: 0.05,
        two_sided: false,
        clutter_on_top: false,
    }
}

/// The trend rule is the only one a jump breaks when every other
/// property holds: a step of the height twice the extrapolated one and
/// more fails [`Guard::check`] (so the apex is searched again near the
/// prediction) but not [`Guard::check_physical`], since near the limit
/// pressure a clean photo's height steps without bound.
#[test]
fn a_jump_alone_breaks_only_the_trend_rule() {
    // Clamp plane at row 400, opening 200 px; heights 40 and 50 px,
    // then 80 px where 60 px are extrapolated.
    let mut g = Guard::new(Some(400.0), Some(200.0), 64, false);
    g.accept(
        1.0,
        [300.0, 360.0],
        [0.3, 0.02],
        Some(&edge(0.92 * cap(40.0, 200.0), 1e-6)),
    );
    g.accept(
        2.0,
        [300.0, 350.0],
        [0.3, 0.02],
        Some(&edge(0.92 * cap(50.0, 200.0), 1e-6)),
    );
    let (apex, e) = ([300.0, 320.0], edge(0.92 * cap(80.0, 200.0), 1e-6));
    let why = g.check(3.0, apex, [0.3, 0.02], Some(&e)).unwrap_err();
    assert!(why.is_trend(), "{why}");
    assert!(
        why.to_string()
            .contains("from where the frames before predict"),
        "{why}"
    );
    let ok = g.check_physical(3.0, apex, [0.3, 0.02], Some(&e));
    assert!(ok.is_ok(), "{ok:?}");
}

/// The curvature of the spherical cap `h` px high through a rim of
/// radius `a` px, 1/px (closed form).
fn cap(h: f64, a: f64) -> f64 {
    2.0 * h / (a * a + h * h)
}

/// Coarse equal pressure steps up to near the limit: the pole's
/// curvature is a fixed 0.91-0.94 of the cap's (the neo-Hookean row of
/// `examples/pole_curvature.rs`) while the curvature per px of height
/// falls by a third from h = 0.5 a to 0.97 a: every photo is accepted,
/// also after a frame left out in between.
#[test]
fn a_dome_near_its_limit_pressure_in_coarse_steps_is_accepted() {
    let (a, clamp, span) = (448.0, 900.0, 64);
    let mut g = Guard::new(Some(clamp), Some(a), span, true);
    let heights = [0.35, 0.5, 0.62, 0.72, 0.8, 0.93, 0.97];
    for (i, f) in heights.iter().enumerate() {
        let h = f * a;
        let r = 0.91 + 0.03 * f;
        let k = r * cap(h, a);
        let e = edge(k, 0.01 * k);
        let apex = [300.0, clamp - h];
        let ok = g.check(1000.0 * (i + 1) as f64, apex, [0.3, 0.02], Some(&e));
        assert!(ok.is_ok(), "h = {f} a: {ok:?}");
        g.accept(1000.0 * (i + 1) as f64, apex, [0.3, 0.02], Some(&e));
    }
}

/// What no membrane's pole does: curved half as much as the cap through
/// the rim (a cable sagging along the top), 1.4 times as much (an edge
/// inside the dome), or its ratio to the cap changing by 0.2 while the
/// height changed by 1 % of the radius.
#[test]
fn a_curvature_no_pole_has_is_refused_with_the_ratio() {
    let (a, clamp, span) = (448.0, 900.0, 64);
    let mut g = Guard::new(Some(clamp), Some(a), span, true);
    let h = 0.5 * a;
    let why = |g: &Guard, r: f64| {
        g.check(
            2000.0,
            [300.0, clamp - h],
            [0.3, 0.02],
            Some(&edge(r * cap(h, a), 1e-3 * cap(h, a))),
        )
    };
    for r in [0.5, 1.4] {
        let e = why(&g, r).unwrap_err();
        assert!(
            e.to_string().contains("times that of the spherical cap"),
            "{e}"
        );
    }
    let h1 = h - 0.01 * a;
    let e1 = edge(0.92 * cap(h1, a), 1e-3 * cap(h1, a));
    g.accept(1000.0, [300.0, clamp - h1], [0.3, 0.02], Some(&e1));
    assert!(why(&g, 0.93).is_ok());
    let e = why(&g, 0.72).unwrap_err();
    assert!(e.to_string().contains("changed from 0.918 to 0.719"), "{e}");
}

/// The lower bound holds however little the cap sags over the span: its
/// test is against the curvature's own standard error. A reference
/// frame 32 px high on an opening of 158 px sags 0.7 px over a 24 px
/// half-span; an edge curved the wrong way there by 2.3 standard errors
/// (a cable's border along the first photo's top) is refused, a dome's
/// curvature known to half its value is not.
#[test]
fn a_flat_first_top_bent_the_wrong_way_is_refused_though_it_sags_under_a_pixel() {
    let (a, clamp, span, h) = (158.0, 155.0, 24, 32.0);
    let g = Guard::new(Some(clamp), Some(a), span, true);
    assert!(0.5 * cap(h, a) * (span * span) as f64 <= 1.0);
    let at = |r: f64, rs: f64| {
        g.check(
            1.0,
            [460.0, clamp - h],
            [0.3, 0.02],
            Some(&edge(r * cap(h, a), rs * cap(h, a))),
        )
    };
    let e = at(-0.35, 0.15).unwrap_err();
    assert!(
        e.to_string().contains("times that of the spherical cap"),
        "{e}"
    );
    assert!(at(0.9, 0.45).is_ok());
    assert!(at(0.45, 0.15).is_ok());
}

/// Without the opening's radius the bounds hold on the ratio of two
/// curvatures; without the clamp row only a downward bend is refused.
#[test]
fn without_the_opening_or_the_clamp_row_the_bounds_are_looser() {
    let mut g = Guard::new(Some(400.0), None, 64, true);
    g.accept(1.0, [300.0, 300.0], [0.3, 0.02], Some(&edge(1e-3, 1e-6)));
    // h 100 -> 110 px: k / k1 within [0.7 / 1.1, 1.1 / 0.7].
    let at = |g: &Guard, k: f64| g.check(2.0, [300.0, 290.0], [0.3, 0.02], Some(&edge(k, 1e-6)));
    assert!(at(&g, 0.7e-3).is_ok());
    assert!(at(&g, 1.5e-3).is_ok());
    assert!(at(&g, 0.6e-3).is_err());
    assert!(at(&g, 1.6e-3).is_err());
    let mut g = Guard::new(None, None, 64, true);
    g.accept(1.0, [300.0, 300.0], [0.3, 0.02], Some(&edge(1e-3, 1e-6)));
    assert!(at(&g, 1e-5).is_ok());
    let e = at(&g, -1e-4).unwrap_err();
    assert!(e.to_string().contains("curves downward"), "{e}");
}

/// The fit's parabola over a half-span `w` of a circle: its curvature
/// against the closed form `kappa (1 + 3/14 (kappa w)^2)`, from a least
/// squares fit to the circle's exact rows.
#[test]
fn the_parabola_over_a_span_of_a_circle_is_corrected() {
    let (r, w) = (300.0f64, 120.0f64);
    let n = 2001;
    let (mut su, mut suu, mut sy, mut suy) = (0.0, 0.0, 0.0, 0.0);
    for j in 0..n {
        let x = w * (2.0 * j as f64 / (n - 1) as f64 - 1.0);
        let y = r - (r * r - x * x).sqrt();
        let u = x * x;
        su += u;
        suu += u * u;
        sy += y;
        suy += u * y;
    }
    let nn = n as f64;
    let k_fit = 2.0 * (nn * suy - su * sy) / (nn * suu - su * su);
    let back = pole_curvature(k_fit, w);
    assert!((back * r - 1.0).abs() < 2e-3, "{}", back * r);
    assert!((k_fit * r - 1.0).abs() > 2e-2, "{}", k_fit * r);
}

/// The residual RMS bound: the F distribution's upper 1e-4 quantile of
/// two variance estimates, against its log-normal approximation, for
/// 40 against 120 degrees of freedom (F(40, 120) at 0.9999 is 2.447,
/// the root of the regularized incomplete beta function
/// `I_{40x/(40x+120)}(20, 60) = 0.9999` computed with mpmath): within
/// 10 % (the approximation gives 2.61, on the side of fewer refusals).
#[test]
fn the_residual_bound_is_the_f_quantile() {
    let b = rms_ratio_bound(40.0, 120.0).powi(2);
    assert!((b / 2.447 - 1.0).abs() < 0.1, "{b}");
}
