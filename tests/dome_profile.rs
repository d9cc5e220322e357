//! The dome height's uncertainty from the profile of the misfit, on
//! misfits of closed form: a parabola in `h0` (a determined dome, whose
//! 95 % interval is known exactly) and a flat profile (heights that cannot
//! tell the dome), where no deviation may be stated.

use bulge::dome::search;

const RADIUS: f64 = 0.1;
const LOWEST: f64 = 0.03;
const N: usize = 20;
const P: usize = 5;

/// `rms(h0)^2 = q0^2 + c (h0 - h)^2`: with `s^2 = n q0^2 / (n - p - 1)` the
/// 95 % interval is `|h0 - h| <= sqrt(3.841 s^2 / (n c))`.
fn parabola(h: f64, q0: f64, c: f64) -> impl Fn(f64, f64) -> Option<f64> + Sync {
    move |_z, h0| Some((q0 * q0 + c * (h0 - h) * (h0 - h)).sqrt())
}

#[test]
fn a_sharp_profile_gives_a_closed_interval_about_the_dome() {
    let (h, q0, c) = (0.012, 2e-3, 1.0);
    let f = search(RADIUS, LOWEST, false, (N, P), parabola(h, q0, c)).unwrap();
    let s2 = N as f64 * q0 * q0 / (N - P - 1) as f64;
    let half = (3.841 * s2 / (N as f64 * c)).sqrt();
    let (lo, hi) = f.h0_interval_m.unwrap();
    assert!(f.h0_determined);
    assert!((f.h0_m - h).abs() < 0.05 * half, "h0 {} for {h}", f.h0_m);
    // the interval holds the truth and lies inside the exact one (its ends
    // are trials of the search)
    assert!(lo <= h && h <= hi, "[{lo}, {hi}]");
    assert!(
        lo >= h - half - 1e-12 && hi <= h + half + 1e-12,
        "[{lo}, {hi}] vs +-{half}"
    );
    // the 68 % deviation: sqrt(s^2 / (n c)) from the curvature 2c of Q
    let sd = f.h0_std_m.unwrap();
    let exact = (s2 / (N as f64 * c)).sqrt();
    assert!((sd / exact - 1.0).abs() < 0.05, "std {sd} vs {exact}");
}

#[test]
fn a_flat_profile_is_said_to_leave_the_dome_undetermined() {
    // the misfit barely depends on h0 over the whole range
    let f = search(RADIUS, LOWEST, false, (N, P), parabola(0.012, 2e-3, 1e-4)).unwrap();
    assert!(!f.h0_determined);
    assert!(f.h0_std_m.is_none(), "a deviation stated: {:?}", f.h0_std_m);
    let (lo, hi) = f.h0_interval_m.unwrap();
    assert!(lo <= 1e-12 && hi >= LOWEST - 1e-12, "[{lo}, {hi}]");
}
