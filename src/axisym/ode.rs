//! Adaptive Dormand–Prince 5(4) integrator for small fixed-size systems.
//!
//! Hairer, Nørsett & Wanner, *Solving ODEs I*, section II.5 (`DOPRI5`):
//! seven stages (first-same-as-last, so six right-hand-side calls per
//! accepted step), fifth-order solution, embedded fourth-order error estimate,
//! PI step-size control (Gustafsson; exponents 0.7/5 and 0.4/5 as in `DOPRI5`).
//!
//! Written here rather than taken from a crate because the shooting needs
//! three things at once that the crates in the dependency list do not give
//! together on a `[f64; N]` state without allocation: a right-hand side that
//! may refuse a state (outside the material's domain: the step is then
//! shrunk, not the run aborted), a stop condition checked after every
//! accepted step, and output at prescribed abscissae hit exactly (the profile
//! grid) without dense-output error.

/// Why an integration ended before the end of the interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// The caller's stop condition fired after an accepted step.
    Condition,
    /// The step size fell below the minimum (the state left the domain of the
    /// right-hand side, or the solution blows up).
    StepUnderflow,
    /// The step budget ran out.
    MaxSteps,
}

/// Settings of one integration.
#[derive(Debug, Clone, Copy)]
pub struct Settings<const N: usize> {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per component (the error weight is
    /// `atol_i + rtol * max(|y_i|, |y_new_i|)`).
    pub atol: [f64; N],
    /// First step size tried.
    pub h0: f64,
    /// Smallest step size allowed before giving up.
    pub h_min: f64,
    /// Budget of accepted plus rejected steps.
    pub max_steps: usize,
    /// The first `norm_dims` components make the error norm (all `N` for a
    /// plain system; the state alone when sensitivities ride along, so that
    /// they follow the steps the state chooses).
    pub norm_dims: usize,
}

/// Result of one integration.
#[derive(Debug, Clone, Copy)]
pub struct Outcome<const N: usize> {
    /// Where the integration ended.
    pub x: f64,
    /// The state there.
    pub y: [f64; N],
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large or state refused).
    pub rejected: usize,
    /// Why it ended early, or `None` when it reached the end.
    pub stopped: Option<Stop>,
}

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

fn lin<const N: usize>(y: &[f64; N], h: f64, terms: &[(f64, &[f64; N])]) -> [f64; N] {
    let mut out = *y;
    for (c, k) in terms {
        if *c != 0.0 {
            for i in 0..N {
                out[i] += h * c * k[i];
            }
        }
    }
    out
}

/// Integrates `y' = f(x, y)` from `x0` to `x1 > x0`.
///
/// `f` returns `None` for a state outside its domain; the step is then
/// rejected and shrunk. `stop(x, y)` is called after each accepted step and
/// ends the run early when it returns true. `outputs` (increasing, inside
/// `(x0, x1]`) are hit exactly by shortening steps; `record(x, y)` is called
/// at each of them.
#[allow(clippy::too_many_arguments)]
pub fn integrate<const N: usize>(
    mut f: impl FnMut(f64, &[f64; N]) -> Option<[f64; N]>,
    x0: f64,
    y0: [f64; N],
    x1: f64,
    s: &Settings<N>,
    mut stop: impl FnMut(f64, &[f64; N]) -> bool,
    outputs: &[f64],
    mut record: impl FnMut(f64, &[f64; N]),
) -> Outcome<N> {
    let mut x = x0;
    let mut y = y0;
    let mut out = Outcome {
        x,
        y,
        accepted: 0,
        rejected: 0,
        stopped: None,
    };
    let Some(mut k1) = f(x, &y) else {
        out.stopped = Some(Stop::StepUnderflow);
        return out;
    };
    let mut h = s.h0.min(x1 - x0);
    let mut err_old: f64 = 1e-4;
    let mut next_out = 0usize;
    while next_out < outputs.len() && outputs[next_out] <= x0 {
        next_out += 1;
    }
    loop {
        if out.accepted + out.rejected >= s.max_steps {
            out.stopped = Some(Stop::MaxSteps);
            break;
        }
        if h < s.h_min {
            out.stopped = Some(Stop::StepUnderflow);
            break;
        }
        // Land exactly on the next output abscissa or the end.
        let target = if next_out < outputs.len() {
            outputs[next_out].min(x1)
        } else {
            x1
        };
        let mut hit = false;
        let mut h_step = h;
        if x + h_step >= target - 1e-14 * target.abs().max(1.0) {
            h_step = target - x;
            hit = true;
        }
        let trial = (|| {
            let k2 = f(x + C2 * h_step, &lin(&y, h_step, &[(A21, &k1)]))?;
            let k3 = f(x + C3 * h_step, &lin(&y, h_step, &[(A31, &k1), (A32, &k2)]))?;
            let k4 = f(
                x + C4 * h_step,
                &lin(&y, h_step, &[(A41, &k1), (A42, &k2), (A43, &k3)]),
            )?;
            let k5 = f(
                x + C5 * h_step,
                &lin(
                    &y,
                    h_step,
                    &[(A51, &k1), (A52, &k2), (A53, &k3), (A54, &k4)],
                ),
            )?;
            let k6 = f(
                x + h_step,
                &lin(
                    &y,
                    h_step,
                    &[(A61, &k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)],
                ),
            )?;
            let y_new = lin(
                &y,
                h_step,
                &[(A71, &k1), (A73, &k3), (A74, &k4), (A75, &k5), (A76, &k6)],
            );
            let k7 = f(x + h_step, &y_new)?;
            let mut e2 = 0.0;
            for i in 0..s.norm_dims.min(N) {
                let ei = h_step
                    * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
                let sc = s.atol[i] + s.rtol * y[i].abs().max(y_new[i].abs());
                e2 += (ei / sc) * (ei / sc);
            }
            let err = (e2 / s.norm_dims.min(N) as f64).sqrt();
            if err.is_finite() {
                Some((y_new, k7, err))
            } else {
                None
            }
        })();
        match trial {
            Some((y_new, k7, err)) if err <= 1.0 => {
                out.accepted += 1;
                x = if hit { target } else { x + h_step };
                y = y_new;
                k1 = k7;
                // PI controller (DOPRI5 defaults).
                let err = err.max(1e-10);
                let fac = (0.9 * err.powf(-0.7 / 5.0) * err_old.powf(0.4 / 5.0)).clamp(0.2, 10.0);
                err_old = err;
                // A step shortened to hit an output does not shrink the next one.
                h = h.max(h_step) * fac;
                if hit && next_out < outputs.len() && target == outputs[next_out].min(x1) {
                    if outputs[next_out] <= x1 {
                        record(x, &y);
                    }
                    next_out += 1;
                }
                if stop(x, &y) {
                    out.stopped = Some(Stop::Condition);
                    break;
                }
                if x >= x1 {
                    break;
                }
            }
            Some((_, _, err)) => {
                out.rejected += 1;
                h = h_step * (0.9 * err.powf(-0.2)).clamp(0.1, 0.9);
            }
            None => {
                out.rejected += 1;
                h = h_step * 0.25;
            }
        }
    }
    out.x = x;
    out.y = y;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(rtol: f64) -> Settings<2> {
        Settings {
            rtol,
            atol: [rtol; 2],
            h0: 1e-3,
            h_min: 1e-14,
            max_steps: 100_000,
            norm_dims: 2,
        }
    }

    /// Harmonic oscillator over 10 periods against cos/sin: the global error
    /// follows the tolerance.
    #[test]
    fn oscillator_error_follows_tolerance() {
        for rtol in [1e-6, 1e-9, 1e-12] {
            let x1 = 20.0 * std::f64::consts::PI;
            let o = integrate(
                |_, y| Some([y[1], -y[0]]),
                0.0,
                [1.0, 0.0],
                x1,
                &settings(rtol),
                |_, _| false,
                &[],
                |_, _| {},
            );
            assert!(o.stopped.is_none());
            let err = (o.y[0] - 1.0).abs().max(o.y[1].abs());
            assert!(err < 200.0 * rtol, "rtol {rtol}: error {err}");
        }
    }

    /// Outputs are hit exactly and carry the solution there.
    #[test]
    fn outputs_are_exact() {
        let xs: Vec<f64> = (1..=10).map(|i| i as f64 * 0.3).collect();
        let mut got = Vec::new();
        let o = integrate(
            |_, y| Some([y[0], 0.0]),
            0.0,
            [1.0, 0.0],
            3.0,
            &settings(1e-11),
            |_, _| false,
            &xs,
            |x, y| got.push((x, y[0])),
        );
        assert_eq!(o.x, 3.0);
        assert_eq!(got.len(), 10);
        for ((x, v), want) in got.iter().zip(&xs) {
            assert_eq!(x, want);
            assert!((v - x.exp()).abs() < 1e-9 * x.exp());
        }
    }

    /// A right-hand side that refuses states makes the run end with a step
    /// underflow at the edge of its domain instead of returning garbage.
    #[test]
    fn refused_state_ends_with_underflow() {
        // y' = 1/(1 - x) blows up at x = 1; refuse y > 30.
        let o = integrate(
            |x, y| (y[0] < 30.0).then(|| [1.0 / (1.0 - x), 0.0]),
            0.0,
            [0.0, 0.0],
            2.0,
            &settings(1e-8),
            |_, _| false,
            &[],
            |_, _| {},
        );
        assert_eq!(o.stopped, Some(Stop::StepUnderflow));
        assert!(o.x < 1.0 && o.y[0] < 30.0);
    }
}
