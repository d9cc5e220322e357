//! Starting points of the least-squares fit: a grid over the nonlinear
//! parameters (Ogden exponents, Gent's locking ratio) with the linear ones
//! solved exactly at each, so that the local solver starts in every basin.

use super::super::linear;
use super::FitError;
use super::StressMeasure;
use nalgebra::{DMatrix, DVector};

use super::*;

/// Starting points (scaled parameters) for the LM runs.
pub(super) fn starting_points(
    kind: Kind,
    data: &Equibiaxial,
    weight: Option<&[f64]>,
    scale: f64,
    jm_min: f64,
) -> Result<Vec<DVector<f64>>, FitError> {
    let w = |i: usize| weight.map_or(1.0, |w| w[i]);
    let target = DVector::from_iterator(
        data.stretch.len(),
        data.stress_pa
            .iter()
            .enumerate()
            .map(|(i, s)| s / scale * w(i)),
    );
    // Design matrix of the linear parameters at fixed nonlinear ones.
    let design = |x_fixed: &[f64]| -> DMatrix<f64> {
        let p = kind.n_params();
        let mut xu = x_fixed.to_vec();
        xu.resize(p, 0.0);
        let mut g = vec![0.0; p];
        let n_lin = match kind {
            Kind::Ogden(n) => n,
            Kind::Gent => 1,
            _ => p,
        };
        let mut a = DMatrix::zeros(data.stretch.len(), n_lin);
        for (i, &l) in data.stretch.iter().enumerate() {
            let factor = match data.measure {
                StressMeasure::Nominal => 1.0,
                StressMeasure::Cauchy => l,
            };
            // For Gent the design column is dP/dmu at mu = 1.
            if let Kind::Gent = kind {
                xu[0] = 1.0;
            }
            nominal_and_grad(kind, &xu, l, &mut g);
            for k in 0..n_lin {
                a[(i, k)] = factor * g[k] * w(i);
            }
        }
        a
    };
    match kind {
        Kind::NeoHookean | Kind::MooneyRivlin | Kind::Yeoh => {
            let a = design(&[]);
            let sol = linear::solve(&a, &target).map_err(|e| FitError::Linear {
                model: kind.label(),
                source: e,
            })?;
            Ok(vec![sol.coefficients])
        }
        Kind::Ogden(n) => {
            let mut out = Vec::new();
            for combo in combinations(OGDEN_ALPHAS.len(), n) {
                let alphas: Vec<f64> = combo.iter().map(|&i| OGDEN_ALPHAS[i]).collect();
                let mut fixed = vec![0.0; n];
                fixed.extend(&alphas);
                let a = design(&fixed);
                if let Ok(sol) = linear::solve(&a, &target) {
                    let mut x: Vec<f64> = sol.coefficients.iter().copied().collect();
                    x.extend(&alphas);
                    out.push(DVector::from_vec(x));
                }
            }
            if out.is_empty() {
                return Err(FitError::Solver(format!(
                    "{}: no usable start",
                    kind.label()
                )));
            }
            Ok(out)
        }
        Kind::Gent => {
            let mut out = Vec::new();
            for ratio in GENT_RATIOS {
                let jm = jm_min.max(1e-6) * ratio;
                let a = design(&[0.0, jm]);
                if let Ok(sol) = linear::solve(&a, &target)
                    && sol.coefficients[0] > 0.0
                {
                    out.push(DVector::from_vec(vec![sol.coefficients[0], jm]));
                }
            }
            if out.is_empty() {
                return Err(FitError::Solver(
                    "gent: no start with a positive shear modulus (is the stress negative?)".into(),
                ));
            }
            Ok(out)
        }
    }
}

/// All `k`-subsets of `0..n` in lexicographic order.
fn combinations(n: usize, k: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut cur = Vec::with_capacity(k);
    fn rec(start: usize, n: usize, k: usize, cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if cur.len() == k {
            out.push(cur.clone());
            return;
        }
        for i in start..n {
            cur.push(i);
            rec(i + 1, n, k, cur, out);
            cur.pop();
        }
    }
    rec(0, n, k, &mut cur, &mut out);
    out
}
