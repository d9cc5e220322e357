//! The sparse linear solve of a Newton step, `K d = r`.
//!
//! The tangent `K` of a membrane is nearly symmetric: Van Gelder's and
//! Lloyd's springs with a constant modulus derive from an energy, and so
//! does the follower pressure on a membrane clamped along its boundary
//! (its load stiffness is antisymmetric per triangle, but the shares cancel
//! between neighbours). What breaks the symmetry is small: TP MSS's forces,
//! which derive from no energy (about 4 % of the tangent), a modulus that
//! follows the strain, the load stiffness along free or mirror edges.
//!
//! So the solve factors only the symmetric part `S = (K + K^T) / 2`, as
//! `S = P^T L D L^T P` with the approximate-minimum-degree ordering `P`
//! (Amestoy, Davis & Duff, "An approximate minimum degree ordering
//! algorithm", SIAM J. Matrix Anal. Appl. 17(4), 1996,
//! doi:10.1137/S0895479894278952) and a supernodal `LDL^T` (faer), and
//! solves `K d = r` by BiCGSTAB (van der Vorst, "Bi-CGSTAB: a fast and
//! smoothly converging variant of Bi-CG for the solution of nonsymmetric
//! linear systems", SIAM J. Sci. Stat. Comput. 13(2), 1992,
//! doi:10.1137/0913035) preconditioned by that factorisation, in double
//! precision, to the relative residual [`SparseSolver::tolerance`] (1e-12
//! by default; Newton loosens it while its own residual is large). Where
//! `K` is symmetric one or two iterations reach 1e-12; TP MSS takes a
//! handful.
//!
//! The factorisation and the triangular solves run on one thread: on a
//! 1e5-node disc faer's parallel supernodal kernels spent more time
//! synchronising than they saved (a Newton solve took 19.5 s with two threads,
//! 14.0 s with one, on two cores).
//!
//! The factor is what fills memory (on a full disc of 1e5 nodes, 3e5
//! unknowns, `L` has 4.4e7 entries), so it is first computed in single
//! precision: a preconditioner needs only to be close to `S^-1`, and the
//! iteration on `K` itself, in double precision, gives the step its full
//! accuracy (mixed-precision refinement: Higham, "Accuracy and Stability of
//! Numerical Algorithms", 2nd ed., SIAM 2002, ch. 12,
//! doi:10.1137/1.9780898718027). With single-precision factors the
//! preconditioned operator is the identity up to about `cond(S) 6e-8`; a
//! membrane's tangent (condition numbers of 1e5 to 1e7) stays well inside
//! that. When the single-precision solve does not converge, the factor is
//! recomputed in double precision, and kept in double from then on.
//!
//! When the double-precision factorisation meets a zero pivot or the
//! iteration does not reach its tolerance (a tangent far from symmetric, or
//! nearly singular), the step falls back to a sparse LU of `K` itself,
//! COLAMD-ordered, whose symbolic analysis is then kept for the next steps.
//!
//! Indices are 32-bit: a pattern of up to 4e9 entries, far beyond the
//! meshes the solver is sized for, at half the memory of `usize`.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::matrix_free::bicgstab::{BicgParams, bicgstab, bicgstab_scratch};
use faer::matrix_free::{IdentityPrecond, InitialGuessStatus, LinOp, Precond};
use faer::prelude::Solve;
use faer::sparse::linalg::cholesky::{
    LdltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use faer::traits::ComplexField;
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

/// How the last solves went (for statistics and tests).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinearStats {
    /// Solves by the iteration preconditioned with single-precision factors.
    pub single: usize,
    /// Numeric factorisations of the symmetric part.
    pub factorisations: usize,
    /// Solves by the iteration preconditioned with double-precision factors.
    pub double: usize,
    /// BiCGSTAB iterations summed over those solves.
    pub iterations: usize,
    /// Solves that fell back to the LU of the whole tangent.
    pub lu: usize,
    /// Entries of the factor `L` of the symmetric part (0 before the first
    /// solve).
    pub factor_entries: usize,
}

/// The symmetric part's pattern (lower triangle) and its symbolic `LDL^T`.
struct SymmetricPart {
    lower: SymbolicSparseColMat<u32>,
    /// For each entry `(i, j)` of `lower`, the position of its mirror `K_ji`
    /// in the values of the whole pattern (`K_ij` is found by walking column
    /// `j`, whose entries from the diagonal down are those of `lower`).
    mirror: Vec<u32>,
    symbolic: SymbolicCholesky<u32>,
}

/// Precision of the factors of the symmetric part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Precision {
    Single,
    Double,
    /// Neither converged (or the analysis failed): LU only.
    None,
}

/// A sparse solver for one sparsity pattern, reused over Newton iterations
/// and pressures.
pub struct SparseSolver {
    pattern: SymbolicSparseColMat<u32>,
    symmetric: Option<SymmetricPart>,
    precision: Precision,
    symbolic_lu: Option<SymbolicLu<u32>>,
    /// The factor's values, kept between solves to spare a fresh allocation
    /// of 1e8 bytes (and its page faults) per Newton step.
    buffers: Buffers,
    /// Relative residual the iteration reaches (default 1e-12).
    pub tolerance: f64,
    /// Cap on BiCGSTAB iterations per solve before the next way is tried
    /// (default 60).
    pub max_iterations: usize,
    /// What the solves did so far.
    pub stats: LinearStats,
}

impl SparseSolver {
    /// A solver for matrices with this pattern (square, structurally
    /// symmetric, columns sorted); `None` when it has 2^32 entries or more.
    pub fn new(pattern: &SymbolicSparseColMat<usize>) -> Option<SparseSolver> {
        let narrow = |v: &[usize]| -> Option<Vec<u32>> {
            v.iter().map(|&i| u32::try_from(i).ok()).collect()
        };
        let n = pattern.ncols();
        let pattern = SymbolicSparseColMat::new_checked(
            n,
            n,
            narrow(pattern.col_ptr())?,
            None,
            narrow(pattern.row_idx())?,
        );
        Some(SparseSolver {
            pattern,
            symmetric: None,
            precision: Precision::Single,
            symbolic_lu: None,
            buffers: Buffers::default(),
            tolerance: 1e-12,
            max_iterations: 60,
            stats: LinearStats::default(),
        })
    }

    /// Memory the solver holds for one solve, bytes: the pattern, the
    /// symmetric part's pattern and the factor in its current precision (not
    /// the LU, which is built only when the iteration fails).
    pub fn bytes(&self) -> usize {
        let pattern = 4 * (self.pattern.col_ptr().len() + self.pattern.row_idx().len());
        let symmetric = self.symmetric.as_ref().map_or(0, |s| {
            let value = match self.precision {
                Precision::Single => 4,
                _ => 8,
            };
            4 * (s.lower.col_ptr().len() + 2 * s.lower.row_idx().len())
                + value * (s.lower.row_idx().len() + s.symbolic.len_val())
        });
        pattern + symmetric
    }

    /// Solves by the LU of the whole matrix only (the reference the
    /// preconditioned solve is tested against).
    pub fn use_lu_only(&mut self) {
        self.precision = Precision::None;
    }

    /// The sparsity pattern (32-bit indices).
    pub fn pattern(&self) -> &SymbolicSparseColMat<u32> {
        &self.pattern
    }

    /// Solves `K d = r` for the matrix with `values` on the solver's pattern;
    /// `None` when every way fails (a singular matrix) or the answer is not
    /// finite.
    pub fn solve(&mut self, values: &[f64], r: &[f64]) -> Option<Vec<f64>> {
        if self.precision == Precision::Single {
            if let Some(d) = self.solve_preconditioned::<f32>(values, r) {
                self.stats.single += 1;
                return Some(d);
            }
            if self.precision == Precision::Single {
                self.precision = Precision::Double;
            }
            self.buffers.single = Default::default();
        }
        if self.precision == Precision::Double
            && let Some(d) = self.solve_preconditioned::<f64>(values, r)
        {
            self.stats.double += 1;
            return Some(d);
        }
        self.stats.lu += 1;
        self.solve_lu(values, r)
    }

    /// BiCGSTAB on `K`, preconditioned by the `LDL^T` factors of its
    /// symmetric part computed in `T`. (Factors of the last matrix tried
    /// first, refactoring only when they needed more than 6 iterations, cost
    /// more than they saved on a 1e5-node disc: their failures took 6
    /// iterations each, a factorisation about 5.)
    fn solve_preconditioned<T: FactorScalar>(
        &mut self,
        values: &[f64],
        r: &[f64],
    ) -> Option<Vec<f64>> {
        if self.symmetric.is_none() {
            match analyse_symmetric(&self.pattern) {
                Some(s) => {
                    self.stats.factor_entries = s.symbolic.len_val();
                    self.symmetric = Some(s)
                }
                None => {
                    self.precision = Precision::None;
                    return None;
                }
            }
        }
        self.factor::<T>(values)?;
        let (d, its) = self.iterate::<T>(values, r, self.max_iterations)?;
        self.stats.iterations += its;
        Some(d)
    }

    /// Factors the symmetric part of the matrix with `values` in `T` into
    /// the kept buffer.
    fn factor<T: FactorScalar>(&mut self, values: &[f64]) -> Option<()> {
        let par = Par::Seq;
        let sym = self.symmetric.as_ref()?;
        let n = self.pattern.ncols();
        let mut s_values: Vec<T> = Vec::with_capacity(sym.mirror.len());
        let (col_ptr, lower_ptr) = (self.pattern.col_ptr(), sym.lower.col_ptr());
        for j in 0..n {
            let count = (lower_ptr[j + 1] - lower_ptr[j]) as usize;
            let below = col_ptr[j + 1] as usize - count;
            for (k, &q) in sym.mirror[lower_ptr[j] as usize..lower_ptr[j + 1] as usize]
                .iter()
                .enumerate()
            {
                s_values.push(T::from_f64(0.5 * (values[below + k] + values[q as usize])));
            }
        }
        let s = SparseColMatRef::new(sym.lower.as_ref(), &s_values);
        let mut scratch = MemBuffer::try_new(
            sym.symbolic
                .factorize_numeric_ldlt_scratch::<T>(par, Default::default()),
        )
        .ok()?;
        let l_values = T::buffer(&mut self.buffers);
        l_values.resize(sym.symbolic.len_val(), T::from(0.0f32));
        sym.symbolic
            .factorize_numeric_ldlt(
                l_values,
                s,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .ok()?;
        self.stats.factorisations += 1;
        Some(())
    }

    /// BiCGSTAB with the kept factors, at most `cap` iterations: the step and
    /// the iterations it took.
    fn iterate<T: FactorScalar>(
        &mut self,
        values: &[f64],
        r: &[f64],
        cap: usize,
    ) -> Option<(Vec<f64>, usize)> {
        let n = r.len();
        let par = Par::Seq;
        let sym = self.symmetric.as_ref()?;
        let l_values = T::buffer(&mut self.buffers);
        let precond = LdltPrecond {
            ldlt: LdltRef::new(&sym.symbolic, l_values),
            n,
        };
        let k = SparseColMatRef::new(self.pattern.as_ref(), values);
        let rhs = Mat::<f64>::from_fn(n, 1, |i, _| r[i]);
        let mut d = Mat::<f64>::zeros(n, 1);
        let identity = IdentityPrecond { dim: n };
        let mut mem = MemBuffer::try_new(bicgstab_scratch(identity, &precond, k, 1, par)).ok()?;
        let params = BicgParams {
            // (with `Zero`, faer 0.24's BiCGSTAB leaves its first residual
            // unset: start from an explicit zero instead)
            initial_guess: InitialGuessStatus::MaybeNonZero,
            abs_tolerance: 0.0,
            rel_tolerance: self.tolerance,
            max_iters: cap,
            ..Default::default()
        };
        let info = bicgstab(
            d.as_mut(),
            identity,
            &precond,
            k,
            rhs.as_ref(),
            params,
            |_| {},
            par,
            MemStack::new(&mut mem),
        )
        .ok()?;
        let d: Vec<f64> = (0..n).map(|i| d[(i, 0)]).collect();
        d.iter()
            .all(|v| v.is_finite())
            .then_some((d, info.iter_count))
    }

    fn solve_lu(&mut self, values: &[f64], r: &[f64]) -> Option<Vec<f64>> {
        let mat = SparseColMat::new(self.pattern.clone(), values.to_vec());
        if self.symbolic_lu.is_none() {
            self.symbolic_lu = Some(SymbolicLu::try_new(mat.symbolic()).ok()?);
        }
        let sym = self.symbolic_lu.clone().expect("set above");
        let lu = Lu::try_new_with_symbolic(sym, mat.as_ref()).ok()?;
        let mut rhs = Mat::<f64>::from_fn(r.len(), 1, |i, _| r[i]);
        lu.solve_in_place(rhs.as_mut());
        let d: Vec<f64> = (0..r.len()).map(|i| rhs[(i, 0)]).collect();
        d.iter().all(|v| v.is_finite()).then_some(d)
    }
}

/// The factor's values in both precisions.
#[derive(Default)]
struct Buffers {
    single: Vec<f32>,
    double: Vec<f64>,
}

/// The precision of a factor: `f32` or `f64`.
trait FactorScalar:
    ComplexField<Real = Self> + faer::traits::RealField + Copy + From<f32> + Into<f64>
{
    /// A double rounded to this precision.
    fn from_f64(v: f64) -> Self;

    /// The factor's buffer in this precision.
    fn buffer(b: &mut Buffers) -> &mut Vec<Self>;
}

impl FactorScalar for f32 {
    fn from_f64(v: f64) -> f32 {
        v as f32
    }

    fn buffer(b: &mut Buffers) -> &mut Vec<f32> {
        &mut b.single
    }
}

impl FactorScalar for f64 {
    fn from_f64(v: f64) -> f64 {
        v
    }

    fn buffer(b: &mut Buffers) -> &mut Vec<f64> {
        &mut b.double
    }
}

/// The lower triangle of a structurally symmetric pattern, the positions of
/// each entry and its mirror, and the AMD-ordered symbolic factorisation.
fn analyse_symmetric(pattern: &SymbolicSparseColMat<u32>) -> Option<SymmetricPart> {
    let n = pattern.ncols();
    let col_ptr = pattern.col_ptr();
    let row_idx = pattern.row_idx();
    let mut lower_ptr = Vec::with_capacity(n + 1);
    let mut lower_idx = Vec::new();
    let mut mirror = Vec::new();
    lower_ptr.push(0u32);
    for j in 0..n {
        for p in col_ptr[j] as usize..col_ptr[j + 1] as usize {
            let i = row_idx[p] as usize;
            if i < j {
                continue;
            }
            let column = &row_idx[col_ptr[i] as usize..col_ptr[i + 1] as usize];
            let q = col_ptr[i] as usize + column.binary_search(&(j as u32)).ok()?;
            lower_idx.push(i as u32);
            mirror.push(q as u32);
        }
        lower_ptr.push(lower_idx.len() as u32);
    }
    let lower = SymbolicSparseColMat::new_checked(n, n, lower_ptr, None, lower_idx);
    let symbolic = factorize_symbolic_cholesky(
        lower.as_ref(),
        Side::Lower,
        SymmetricOrdering::Amd,
        Default::default(),
    )
    .ok()?;
    Some(SymmetricPart {
        lower,
        mirror,
        symbolic,
    })
}

/// `S^-1` applied through its `LDL^T` factors (in `T`) to double vectors.
struct LdltPrecond<'a, T> {
    ldlt: LdltRef<'a, u32, T>,
    n: usize,
}

impl<T> std::fmt::Debug for LdltPrecond<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LdltPrecond({})", self.n)
    }
}

impl<T: FactorScalar> LinOp<f64> for LdltPrecond<'_, T> {
    fn apply_scratch(&self, rhs_ncols: usize, par: Par) -> StackReq {
        self.ldlt
            .symbolic()
            .solve_in_place_scratch::<T>(rhs_ncols, par)
    }

    fn nrows(&self) -> usize {
        self.n
    }

    fn ncols(&self) -> usize {
        self.n
    }

    fn apply(
        &self,
        mut out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        let mut x = Mat::<T>::from_fn(rhs.nrows(), rhs.ncols(), |i, j| T::from_f64(rhs[(i, j)]));
        self.ldlt
            .solve_in_place_with_conj(Conj::No, x.as_mut(), par, stack);
        for j in 0..rhs.ncols() {
            for i in 0..rhs.nrows() {
                out[(i, j)] = x[(i, j)].into();
            }
        }
    }

    fn conj_apply(
        &self,
        out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out, rhs, par, stack);
    }
}

impl<T: FactorScalar> Precond<f64> for LdltPrecond<'_, T> {}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D Laplacian plus an antisymmetric part of size `skew`: the
    /// preconditioned iteration and the LU give the same answer, and the
    /// answer solves the system.
    fn system(n: usize, skew: f64) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                row_idx.push(i);
                values.push(if i == j {
                    2.0
                } else if i < j {
                    -1.0 + skew
                } else {
                    -1.0 - skew
                });
            }
            col_ptr.push(row_idx.len());
        }
        (
            SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            values,
        )
    }

    fn residual(p: &SymbolicSparseColMat<usize>, v: &[f64], d: &[f64], r: &[f64]) -> f64 {
        let mut kd = vec![0.0; r.len()];
        for (j, dj) in d.iter().enumerate() {
            for q in p.col_ptr()[j]..p.col_ptr()[j + 1] {
                kd[p.row_idx()[q]] += v[q] * dj;
            }
        }
        kd.iter()
            .zip(r)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
            / r.iter().map(|b| b * b).sum::<f64>().sqrt()
    }

    #[test]
    fn symmetric_systems_take_one_iteration() {
        let (p, v) = system(200, 0.0);
        let r: Vec<f64> = (0..200).map(|i| ((i * 7) % 13) as f64 - 6.0).collect();
        let mut s = SparseSolver::new(&p).unwrap();
        let d = s.solve(&v, &r).unwrap();
        assert!(residual(&p, &v, &d, &r) < 1e-10);
        assert_eq!((s.stats.single, s.stats.double, s.stats.lu), (1, 0, 0));
        assert!(s.stats.iterations <= 2, "{:?}", s.stats);
    }

    #[test]
    fn nearly_symmetric_systems_converge_without_the_lu() {
        let (p, v) = system(200, 0.04);
        let r: Vec<f64> = (0..200).map(|i| ((i * 7) % 13) as f64 - 6.0).collect();
        let mut s = SparseSolver::new(&p).unwrap();
        let d = s.solve(&v, &r).unwrap();
        assert!(residual(&p, &v, &d, &r) < 1e-10);
        assert_eq!((s.stats.single, s.stats.lu), (1, 0));
        let lu = s.solve_lu(&v, &r).unwrap();
        let diff = d
            .iter()
            .zip(&lu)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let scale = lu.iter().map(|b| b.abs()).fold(0.0, f64::max);
        assert!(diff <= 1e-9 * scale, "{diff} vs {scale}");
    }

    #[test]
    fn a_singular_symmetric_part_falls_back_to_the_lu() {
        // [[0, 1], [-1, 0]] + I: S = I is fine; [[0, 1], [-1, 0]] alone has
        // S = 0, which no LDL^T factors; the LU solves it.
        let p = SymbolicSparseColMat::new_checked(2, 2, vec![0, 2, 4], None, vec![0, 1, 0, 1]);
        let v = vec![0.0, -1.0, 1.0, 0.0];
        let mut s = SparseSolver::new(&p).unwrap();
        let d = s.solve(&v, &[1.0, 2.0]).unwrap();
        assert!(residual(&p, &v, &d, &[1.0, 2.0]) < 1e-14);
        assert_eq!((s.stats.single, s.stats.double, s.stats.lu), (0, 0, 1));
    }
}
