//! Golden-section search for a minimum inside a bracket (Kiefer, "Sequential
//! minimax search for a maximum", Proc. AMS 4, 1953,
//! doi:10.1090/S0002-9939-1953-0055639-3; Press et al., *Numerical Recipes*,
//! 3rd ed., 2007, section 10.2), for the searches whose every evaluation is
//! a fit: the number of sections is set rather than a tolerance (the
//! bracket shrinks by 0.618 each), and each point's value carries what the
//! fit found there.

/// The best point of a search.
#[derive(Debug, Clone, PartialEq)]
pub struct Best<T> {
    /// The abscissa.
    pub x: f64,
    /// Its score (smaller is better).
    pub score: f64,
    /// What the function gave with the score.
    pub value: T,
}

/// Minimises `f` (a score, smaller better, and a value) over `[lo, hi]`
/// with `sections` golden sections after the two first points: `sections +
/// 2` evaluations, the bracket shrunk to `0.618^(sections + 1)` of its
/// width. Returns the better of the two last interior points (the better
/// of every point evaluated, the kept point being the best so far); a tie
/// goes to the upper one. An infinite or NaN score counts as worse than any
/// finite one.
pub fn golden_section<T>(
    lo: f64,
    hi: f64,
    sections: usize,
    mut f: impl FnMut(f64) -> (f64, T),
) -> Best<T> {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (lo, hi);
    let mut eval = |x: f64| {
        let (score, value) = f(x);
        Best {
            x,
            score: if score.is_nan() { f64::INFINITY } else { score },
            value,
        }
    };
    let mut p1 = eval(hi - g * (hi - lo));
    let mut p2 = eval(lo + g * (hi - lo));
    for _ in 0..sections {
        if p1.score < p2.score {
            hi = p2.x;
            p2 = p1;
            p1 = eval(hi - g * (hi - lo));
        } else {
            lo = p1.x;
            p1 = p2;
            p2 = eval(lo + g * (hi - lo));
        }
    }
    if p1.score < p2.score { p1 } else { p2 }
}

/// The sections that shrink a bracket of `width` below `tol`.
pub fn sections_for(width: f64, tol: f64) -> usize {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    if !(width > tol && tol > 0.0) {
        return 0;
    }
    ((tol / width).ln() / g.ln()).ceil() as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_parabola_s_vertex_to_the_bracket_s_width() {
        let mut calls = 0;
        let b = golden_section(0.0, 3.0, 40, |x| {
            calls += 1;
            ((x - 1.234).powi(2), x * 2.0)
        });
        assert_eq!(calls, 42);
        // the bracket after 41 shrinks: 3 * 0.618^41 ~ 8e-9
        assert!((b.x - 1.234).abs() < 2e-8, "{}", b.x);
        assert_eq!(b.value, b.x * 2.0);
    }

    #[test]
    fn a_point_without_a_score_is_never_the_best() {
        let b = golden_section(0.0, 1.0, 20, |x| {
            (if x > 0.5 { f64::NAN } else { (x - 0.3).abs() }, ())
        });
        assert!((b.x - 0.3).abs() < 1e-3, "{}", b.x);
        assert!(b.score.is_finite());
    }

    #[test]
    fn sections_shrink_the_bracket_below_the_tolerance() {
        let n = sections_for(1.0, 1e-6);
        let g: f64 = 0.5 * (5f64.sqrt() - 1.0);
        assert!(g.powi(n as i32) < 1e-6 && g.powi(n as i32 - 1) >= 1e-6);
        assert_eq!(sections_for(1.0, 2.0), 0);
    }
}
