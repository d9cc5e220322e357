//! One solve's shared state and the walk along the pressure curve `pi(l0)`
//! of the pole stretch: bracketing a target pressure or the limit point.

use std::cell::Cell;

use crate::experiment::Specimen;
use crate::material::Material;

use super::law::Law;
use super::shoot::{Membrane, Point, Reference, Shot};
use super::*;

/// Shared state of one solve: the membrane, the disc, the options and a
/// count of shots.
pub(super) struct Ctx<'a> {
    pub(super) mem: Membrane<'a>,
    pub(super) a: f64,
    pub(super) t: f64,
    pub(super) opts: Options,
    pub(super) shots: Cell<usize>,
}

/// A point of the pressure curve `pi(l0)`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub(super) l0: f64,
    pub(super) pi: f64,
    /// Apex height over the radius.
    pub(super) h: f64,
}

pub(super) enum WalkEnd {
    /// `lo.pi < target <= hi.pi` on the rising branch.
    Bracket(Sample, Sample),
    /// The pressure fell between samples: a maximum in `[lo, hi]`, highest
    /// sample `best`.
    Limit { lo: f64, hi: f64, best: Sample },
    /// The range ended with the pressure still rising.
    Exhausted(Sample),
    /// The material's domain ended (last good sample, reason) with the
    /// pressure still rising.
    Edge(Sample, String),
}

impl<'a> Ctx<'a> {
    pub(super) fn new(
        material: &'a Material,
        specimen: &Specimen,
        opts: &Options,
    ) -> Result<Self, AxisymError> {
        specimen.validate().map_err(AxisymError::Specimen)?;
        opts.validate()?;
        let law = Law::new(material)?;
        Ok(Self {
            mem: Membrane {
                law,
                max_steps: opts.max_steps,
                reference: Reference::of(specimen),
            },
            a: specimen.radius_m,
            t: specimen.thickness_m,
            opts: *opts,
            shots: Cell::new(0),
        })
    }

    pub(super) fn shoot(&self, l0: f64, pi: f64, rtol: f64) -> Result<Shot, AxisymError> {
        self.shots.set(self.shots.get() + 1);
        let s = self.mem.shoot(l0, pi, rtol, &[], None);
        if self.mem.out_of_steps(&s) {
            return Err(AxisymError::NoConvergence(format!(
                "more than {} Runge-Kutta steps at pole stretch {l0}, pressure {} Pa ({}); raise \
                 Options::max_steps or loosen rel_tol",
                self.opts.max_steps,
                pi * self.t / self.a,
                Membrane::describe(&s)
            )));
        }
        Ok(s)
    }

    /// The pressure `pi` with `l2(a) = 1` for pole stretch `l0`, starting from
    /// `guess`: bracket by expanding steps, then Brent.
    pub(super) fn pressure_at(
        &self,
        l0: f64,
        guess: f64,
        tol: f64,
        rtol: f64,
    ) -> Result<(f64, Shot), AxisymError> {
        self.pole_ok(l0)?;
        let mut last: Vec<(f64, Shot)> = Vec::new();
        let mut g = |pi: f64| -> Result<f64, AxisymError> {
            let s = self.shoot(l0, pi, rtol)?;
            last.push((pi, s));
            Ok(s.residual(l0))
        };
        let budget = self.opts.max_iterations;
        let (mut lo, mut hi);
        let g0 = g(guess)?;
        let mut f = 1.1f64;
        if g0 > 0.0 {
            lo = (guess, g0);
            hi = (guess * f, g(guess * f)?);
            let mut n = 0;
            while hi.1 > 0.0 {
                lo = hi;
                f = (f * f).min(4.0);
                hi = (hi.0 * f, g(hi.0 * f)?);
                n += 1;
                if n > 60 {
                    return Err(AxisymError::NoConvergence(format!(
                        "no pressure closes the bubble at pole stretch {l0} (tried up to {:e} Pa)",
                        hi.0 * self.t / self.a
                    )));
                }
            }
        } else {
            hi = (guess, g0);
            lo = (guess / f, g(guess / f)?);
            let mut n = 0;
            while lo.1 <= 0.0 {
                hi = lo;
                f = (f * f).min(4.0);
                lo = (lo.0 / f, g(lo.0 / f)?);
                n += 1;
                if n > 30 {
                    return Err(AxisymError::OutsideMaterial {
                        pole_stretch: l0,
                        reason: format!(
                            "no pressure down to {:e} Pa lets the meridian reach the clamp (no \
                             meridional tension or stiffness on the way)",
                            lo.0 * self.t / self.a
                        ),
                    });
                }
            }
        }
        let root = roots::brent_zero(&mut g, lo.0, lo.1, hi.0, hi.1, tol * lo.0, tol, budget)?;
        if !root.converged {
            return Err(AxisymError::NoConvergence(format!(
                "the pressure at pole stretch {l0} did not converge in {} shots (residual {:.3e})",
                root.evals, root.fx
            )));
        }
        let shot = last
            .iter()
            .rev()
            .find(|(x, _)| *x == root.x)
            .map(|(_, s)| *s)
            .expect("Brent returns an evaluated point");
        Ok((root.x, shot))
    }

    /// Walks up the pressure curve `pi(l0)` from the flat state, at loose
    /// tolerances, until it passes `target` (bracket), falls (limit point) or
    /// reaches `max_pole_stretch`.
    pub(super) fn walk(&self, target: Option<f64>) -> Result<WalkEnd, AxisymError> {
        let tol = self.opts.tol.max(1e-6);
        let rtol = self.opts.rel_tol.max(1e-7);
        let top = self.opts.max_pole_stretch - 1.0;
        let sample = |d: f64, guess: Option<f64>| -> Result<Sample, AxisymError> {
            let l0 = 1.0 + d;
            self.pole_ok(l0)?;
            let guess = match guess {
                Some(g) => g,
                None => self.mem.cap_estimate(l0).ok_or_else(|| self.outside(l0))?,
            };
            let (pi, shot) = self.pressure_at(l0, guess, tol, rtol)?;
            Ok(Sample {
                l0,
                pi,
                h: shot.height(),
            })
        };
        // First pole strain: Hencky's small-deflection pole strain (Hencky 1915)
        // `e0 = s0 (E p^2 a^2 / t^2)^(1/3) / M`, M the biaxial modulus, a
        // little below so that the walk starts on the rising branch.
        let m = self.mem.law.biaxial_modulus();
        let mut d = match target {
            Some(pi) => (0.8 * 0.365 * (pi / m).powf(2.0 / 3.0)).min(0.3),
            None => 0.02,
        }
        .clamp(1e-9, 0.5 * top);
        let mut cur = loop {
            match sample(d, None) {
                Ok(s) => break s,
                Err(AxisymError::OutsideMaterial { .. } | AxisymError::NoConvergence(_))
                    if d > 1e-6 =>
                {
                    d /= 4.0
                }
                Err(e) => return Err(e),
            }
        };
        if let Some(t) = target
            && cur.pi >= t
        {
            // Started above the target: step down (the small-strain end of
            // the curve rises monotonically, p ~ (l0 - 1)^(3/2)).
            loop {
                d /= 3.0;
                if d < 1e-12 {
                    return Err(AxisymError::NoConvergence(format!(
                        "pressure {:e} Pa is below what the solver resolves",
                        t * self.t / self.a
                    )));
                }
                let s = sample(d, Some(cur.pi * 3f64.powf(-1.5)))?;
                if s.pi < t {
                    return Ok(WalkEnd::Bracket(s, cur));
                }
                cur = s;
            }
        }
        let mut prev: Option<Sample> = None;
        let mut n = 1.5; // local exponent of pi ~ d^n
        // Largest increment allowed after a failed sample (edge of the
        // material's domain ahead).
        let mut cap = f64::INFINITY;
        loop {
            let dc = cur.l0 - 1.0;
            let ratio = match target {
                Some(t) if n > 0.1 => (1.05 * (t / cur.pi).powf(1.0 / n)).clamp(1.1, 2.5),
                _ => 1.6,
            };
            let mut dn = (dc * ratio)
                .min(dc + self.opts.max_walk_step)
                .min(dc + cap)
                .min(top);
            if dn <= dc * (1.0 + 1e-12) {
                return Ok(WalkEnd::Exhausted(cur));
            }
            let s = loop {
                match sample(dn, Some(cur.pi * (dn / dc).powf(n))) {
                    Ok(s) => break s,
                    Err(
                        e @ (AxisymError::OutsideMaterial { .. } | AxisymError::NoConvergence(_)),
                    ) => {
                        let step = 0.5 * (dn - dc);
                        cap = step;
                        if step < 1e-9 * (1.0 + dc) {
                            return Ok(WalkEnd::Edge(cur, e.to_string()));
                        }
                        dn = dc + step;
                    }
                    Err(e) => return Err(e),
                }
            };
            if cap.is_finite() {
                cap *= 2.0;
            }
            if s.pi < cur.pi {
                let lo = prev.map(|p| p.l0).unwrap_or(1.0 + 0.5 * dc);
                return Ok(WalkEnd::Limit {
                    lo,
                    hi: s.l0,
                    best: cur,
                });
            }
            n = ((s.pi / cur.pi).ln() / (dn / dc).ln()).clamp(0.2, 3.0);
            if let Some(t) = target
                && s.pi >= t
            {
                return Ok(WalkEnd::Bracket(cur, s));
            }
            prev = Some(cur);
            cur = s;
        }
    }

    /// Checks that the law has meridional tension and stiffness at the
    /// equibiaxial pole state.
    pub(super) fn pole_ok(&self, l0: f64) -> Result<(), AxisymError> {
        match self.mem.law.stress(l0, l0) {
            Some(st) if st.p[0] > 0.0 && st.dp[0][0] > 0.0 => Ok(()),
            _ => Err(self.outside(l0)),
        }
    }

    /// The error for a pole stretch outside the law's domain, naming the
    /// strain where a quartic modulus fails.
    pub(super) fn outside(&self, l0: f64) -> AxisymError {
        let law = &self.mem.law;
        let reason = match (law.stress(l0, l0), law.quartic_modulus(l0, l0)) {
            (_, Some((eps, young))) if young <= 0.0 => format!(
                "the quartic modulus E(eps) = {young:.4e} Pa is not positive at the pole strain \
                 eps = {eps:.4} (outside the fitted strain range?)"
            ),
            (Some(st), q) => {
                let extra = q
                    .map(|(eps, young)| {
                        format!(" (quartic E = {young:.4e} Pa at the pole strain eps = {eps:.4})")
                    })
                    .unwrap_or_default();
                format!(
                    "the equibiaxial nominal stress is {:.4e} Pa and its slope dP1/dl1 = {:.4e} Pa; \
                     both must be positive for a stable membrane{extra}",
                    st.p[0], st.dp[0][0]
                )
            }
            (None, _) => "the material law is undefined there (e.g. beyond a Gent locking \
                          stretch)"
                .to_string(),
        };
        AxisymError::OutsideMaterial {
            pole_stretch: l0,
            reason,
        }
    }

    /// The pressure maximum inside `[lo, hi]`.
    pub(super) fn refine_max(
        &self,
        lo: f64,
        hi: f64,
        best: Sample,
    ) -> Result<(Sample, Shot), AxisymError> {
        let mut guess = best.pi;
        let mut evals: Vec<(f64, f64, Shot)> = Vec::new();
        let m = roots::brent_min(
            |l0| match self.pressure_at(l0, guess, self.opts.tol, self.opts.rel_tol) {
                Ok((pi, s)) => {
                    guess = pi;
                    evals.push((l0, pi, s));
                    Ok(-pi)
                }
                // Outside the material's domain: worse than any equilibrium.
                Err(AxisymError::OutsideMaterial { .. }) => Ok(0.0),
                Err(e) => Err(e),
            },
            lo,
            hi,
            1e-6,
            1e-9,
            self.opts.max_iterations,
        )?;
        let (l0, pi, shot) = evals
            .iter()
            .find(|(x, _, _)| *x == m.x)
            .copied()
            .or_else(|| evals.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1)))
            .ok_or_else(|| self.outside(m.x))?;
        Ok((
            Sample {
                l0,
                pi,
                h: shot.height(),
            },
            shot,
        ))
    }

    /// The pole stretch in `[lo, hi]` at which pressure `pi` holds the clamp,
    /// with `pi(lo) < pi <= pi(hi)` on a rising stretch of the curve.
    pub(super) fn stretch_at(&self, pi: f64, lo: f64, hi: f64) -> Result<(f64, Shot), AxisymError> {
        let (tol, rtol) = (self.opts.tol, self.opts.rel_tol);
        let mut last: Vec<(f64, Shot)> = Vec::new();
        let mut g = |l0: f64| -> Result<f64, AxisymError> {
            let s = self.shoot(l0, pi, rtol)?;
            last.push((l0, s));
            Ok(s.residual(l0))
        };
        let (glo, ghi) = (g(lo)?, g(hi)?);
        let xtol = tol * (lo - 1.0);
        if glo <= 0.0 && ghi >= 0.0 {
            let root = roots::brent_zero(
                &mut g,
                lo,
                glo,
                hi,
                ghi,
                xtol,
                tol,
                self.opts.max_iterations,
            )?;
            if root.converged {
                let shot = last
                    .iter()
                    .rev()
                    .find(|(x, _)| *x == root.x)
                    .map(|(_, s)| *s)
                    .expect("Brent returns an evaluated point");
                return Ok((root.x, shot));
            }
        }
        // The clamp residual at fixed pressure did not bracket (not expected
        // on a rising branch): solve pi(l0) = pi with nested shooting instead.
        let mut guess = pi;
        let mut h = |l0: f64| -> Result<f64, AxisymError> {
            let (p, _) = self.pressure_at(l0, guess, tol, rtol)?;
            guess = p;
            Ok(p / pi - 1.0)
        };
        let (hlo, hhi) = (h(lo)?, h(hi)?);
        if hlo * hhi > 0.0 {
            return Err(AxisymError::NoConvergence(format!(
                "pressure {} Pa is not between the pressures at pole stretches {lo} and {hi}",
                pi * self.t / self.a
            )));
        }
        let root = roots::brent_zero(
            &mut h,
            lo,
            hlo,
            hi,
            hhi,
            xtol,
            tol,
            self.opts.max_iterations,
        )?;
        if !root.converged {
            return Err(AxisymError::NoConvergence(format!(
                "the pole stretch at pressure {} Pa did not converge (residual {:.3e})",
                pi * self.t / self.a,
                root.fx
            )));
        }
        let (p, shot) = self.pressure_at(root.x, guess, tol, rtol)?;
        // The nested shooting can land on another branch from another
        // guess (laws with a rising and falling stiffness, met by the
        // inverse fit's trial laws): refuse rather than return a solution
        // at another pressure.
        let agrees = (p / pi - 1.0).abs() < 1e-6;
        if !agrees {
            return Err(AxisymError::NoConvergence(format!(
                "at pressure {} Pa the pole stretch {} solves for {} Pa on re-evaluation: two branches of the shooting meet; the law may not be monotonic there",
                pi * self.t / self.a,
                root.x,
                p * self.t / self.a
            )));
        }
        Ok((root.x, shot))
    }

    /// The solution with its profile, from the converged pole stretch and
    /// pressure.
    pub(super) fn finish(&self, l0: f64, pi: f64) -> Result<Solution, AxisymError> {
        let n = self.opts.n_profile;
        let xs: Vec<f64> = (0..n).map(|j| j as f64 / (n - 1) as f64).collect();
        let mut pts: Vec<Point> = Vec::with_capacity(n);
        self.shots.set(self.shots.get() + 1);
        let s = self
            .mem
            .shoot(l0, pi, self.opts.rel_tol, &xs, Some(&mut pts));
        if !s.complete || pts.len() != n {
            return Err(AxisymError::NoConvergence(format!(
                "the profile run at pole stretch {l0} did not reach the clamp ({})",
                Membrane::describe(&s)
            )));
        }
        let h = s.height();
        let a = self.a;
        // A solution meets the clamp: the scaled residual `(l2(a) - 1) / (l0 -
        // 1)` is the clamp's hoop strain as a fraction of the pole's strain
        // (1 for a flat shot); the root is found to `tol`. One left above a
        // millionth (a nearly inextensible membrane, where the shooting loses
        // the root) is no solution; nor is an apex below the reference's
        // under a pressure (the hoop-compressed equilibria of a slack cap).
        let residual = s.residual(l0).abs();
        let h0 = self.mem.reference.height(0.0);
        let below = pi > 0.0 && h < h0 - 1e-9;
        if residual.is_nan() || residual > 1e-6 || below {
            return Err(AxisymError::NoConvergence(format!(
                "at pole stretch {l0} the profile meets the clamp with a hoop strain {residual:.1e} times the pole's{}: the membrane is nearly inextensible at this pressure (strains of order {:.0e}); a lower modulus or a higher pressure, or the spring and membrane models, which take such a disc",
                if below {
                    format!(
                        " and its apex at {:.4e} m, below the unloaded dome's {:.4e} m",
                        h * a,
                        h0 * a
                    )
                } else {
                    String::new()
                },
                (l0 - 1.0).abs()
            )));
        }
        Ok(Solution {
            pressure_pa: pi * self.t / a,
            pole_stretch: l0,
            height_m: h * a,
            iterations: self.shots.get(),
            residual,
            profile: Profile {
                r_m: pts.iter().map(|p| p.x * a).collect(),
                rho_m: pts.iter().map(|p| p.x * p.l2 * a).collect(),
                z_m: pts.iter().map(|p| (h - p.d) * a).collect(),
                stretch_meridional: pts.iter().map(|p| p.l1).collect(),
                stretch_hoop: pts.iter().map(|p| p.l2).collect(),
            },
        })
    }

    /// The unloaded membrane: its stress-free reference (the flat disc, or
    /// the cap of a slack membrane).
    pub(super) fn flat(&self) -> Solution {
        let n = self.opts.n_profile;
        let re = self.mem.reference;
        let xi: Vec<f64> = (0..n).map(|j| re.end * j as f64 / (n - 1) as f64).collect();
        let r: Vec<f64> = xi.iter().map(|&x| self.a * re.radius(x).0).collect();
        Solution {
            pressure_pa: 0.0,
            pole_stretch: 1.0,
            height_m: self.a * re.height(0.0),
            iterations: 0,
            residual: 0.0,
            profile: Profile {
                rho_m: r.clone(),
                r_m: r,
                z_m: xi.iter().map(|&x| self.a * re.height(x)).collect(),
                stretch_meridional: vec![1.0; n],
                stretch_hoop: vec![1.0; n],
            },
        }
    }
}
