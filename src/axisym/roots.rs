//! Brent's bracketing root finder and minimiser (Brent 1973, *Algorithms for
//! minimization without derivatives*, chapters 4 and 5), with a fallible
//! function so that an evaluation error ends the search.

/// A converged root: where, the function there, and evaluations spent.
#[derive(Debug, Clone, Copy)]
pub struct Root {
    /// The abscissa.
    pub x: f64,
    /// The function value at `x`.
    pub fx: f64,
    /// Function evaluations.
    pub evals: usize,
    /// Whether the stopping test was met (else the budget ran out).
    pub converged: bool,
}

/// Finds a root of `f` in `[a, b]` with `f(a)`, `f(b)` of opposite signs
/// (values passed in). Stops when `|f| <= ftol` or the bracket is narrower
/// than `2 xtol`.
#[allow(clippy::too_many_arguments)]
pub fn brent_zero<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    a: f64,
    fa: f64,
    b: f64,
    fb: f64,
    xtol: f64,
    ftol: f64,
    max_evals: usize,
) -> Result<Root, E> {
    let (mut a, mut fa, mut b, mut fb) = (a, fa, b, fb);
    debug_assert!(fa * fb <= 0.0);
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    let mut evals = 0;
    loop {
        if fb * fc > 0.0 {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let m = 0.5 * (c - b);
        if fb == 0.0 || fb.abs() <= ftol || m.abs() <= tol {
            return Ok(Root {
                x: b,
                fx: fb,
                evals,
                converged: true,
            });
        }
        if evals >= max_evals {
            return Ok(Root {
                x: b,
                fx: fb,
                evals,
                converged: false,
            });
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            // Secant or inverse quadratic interpolation.
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
                q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b)?;
        evals += 1;
    }
}

/// A converged minimum.
#[derive(Debug, Clone, Copy)]
pub struct Min {
    /// The abscissa.
    pub x: f64,
}

/// Minimises `f` on `[a, b]` (golden section with parabolic steps), to an
/// abscissa tolerance `rel * |x| + abs`.
pub fn brent_min<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    a: f64,
    b: f64,
    rel: f64,
    abs: f64,
    max_evals: usize,
) -> Result<Min, E> {
    const CGOLD: f64 = 0.381_966_011_250_105_1;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let mut x = a + CGOLD * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x)?;
    let (mut fw, mut fv) = (fx, fx);
    let mut evals = 1;
    let (mut d, mut e): (f64, f64) = (0.0, 0.0);
    while evals < max_evals {
        let xm = 0.5 * (a + b);
        let tol1 = rel * x.abs() + abs;
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let etemp = e;
            e = d;
            if p.abs() < (0.5 * q * etemp).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(xm - x);
                }
                golden = false;
            }
        }
        if golden {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f(u)?;
        evals += 1;
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if fu <= fv || v == x || v == w {
                v = u;
                fv = fu;
            }
        }
    }
    Ok(Min { x })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_of_cubic() {
        let f = |x: f64| Ok::<_, ()>(x * x * x - 2.0 * x - 5.0);
        let r = brent_zero(
            f,
            2.0,
            f(2.0).unwrap(),
            3.0,
            f(3.0).unwrap(),
            1e-14,
            0.0,
            100,
        )
        .unwrap();
        assert!(r.converged);
        assert!((r.x - 2.094_551_481_542_326_5).abs() < 1e-13, "{}", r.x);
        assert!(r.evals < 15);
    }

    #[test]
    fn minimum_of_smooth_function() {
        // -x e^-x has its minimum at x = 1.
        let mut evals = 0;
        let f = |x: f64| {
            evals += 1;
            Ok::<_, ()>(-x * (-x).exp())
        };
        let m = brent_min(f, 0.0, 4.0, 1e-9, 1e-12, 200).unwrap();
        assert!((m.x - 1.0).abs() < 1e-7, "{}", m.x);
        assert!(evals < 40, "{evals}");
    }
}
