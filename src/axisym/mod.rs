//! The exact axisymmetric membrane solution of a clamped, initially flat disc
//! under pressure (Adkins & Rivlin 1952, Yang & Feng 1970).
//!
//! A clamped circular bubble is axisymmetric, so its membrane equilibrium is a
//! two-point boundary-value problem in the reference radius `r` in `[0, a]`:
//! meridional stretch `l1`, hoop stretch `l2 = rho / r`, meridian angle `psi`
//! (0 at the pole), nominal membrane stresses `P_i(l1, l2)` (force per unit
//! reference length over the initial thickness `t`; `P_i = dW/dl_i` for a
//! hyperelastic material):
//!
//! ```text
//! d(r P1)/dr = P2 cos psi                          meridional equilibrium
//! psi'       = (p l1 l2 / t - P2 sin psi / r) / P1  normal equilibrium
//! l2'        = (l1 cos psi - l2) / r                compatibility
//! z'         = -l1 sin psi                          height
//! ```
//!
//! with `l1 = l2 = l0`, `psi = 0` at the pole and `l2(a) = 1` at the clamp.
//! [`solve_pole_stretch`] shoots on the pressure for a given pole stretch (well
//! defined past the pressure maximum); [`solve_pressure`] finds the pole
//! stretch for a given pressure on the stable, rising branch and reports a
//! pressure above the limit point as [`AxisymError::AboveLimitPoint`];
//! [`limit_point`] finds the first pressure maximum. The equations, the start
//! off the axis and the materials are described in the submodules and in
//! `docs/axisym.md`.
//!
//! The reference (stress-free) configuration is the flat disc, or, when the
//! specimen's `prebulge_height_m` is positive, a spherical cap of that height
//! over the clamp (a slack membrane): the same equations in the reference
//! arc length, with the reference radius `rho0` in place of `r` (see
//! `docs/axisym.md`). Heights are above the clamp plane. The `linear` and
//! `quartic` materials use the material's `poisson`.
//!
//! ```
//! use bulge::axisym::{solve_pole_stretch, Options};
//! use bulge::experiment::Specimen;
//! use bulge::material::{Material, Model};
//!
//! let material = Material { model: Model::NeoHookean { c1_pa: 1.0e5 }, poisson: 0.45, fit: None };
//! let specimen = Specimen { radius_m: 0.0375, thickness_m: 3.5e-4, poisson: 0.45, prebulge_height_m: 0.0 };
//! let sol = solve_pole_stretch(&material, &specimen, 1.2, &Options::default()).unwrap();
//! // Adkins & Rivlin (1952), Yang & Feng (1970): P = p a / (C1 t) = 1.99850, h/a = 0.53098.
//! let p_dimless = sol.pressure_pa * 0.0375 / (1.0e5 * 3.5e-4);
//! assert!((p_dimless - 1.99850).abs() < 1e-4 * 1.99850);
//! assert!((sol.height_m / 0.0375 - 0.53098).abs() < 1e-4 * 0.53098);
//! ```

mod law;
mod ode;
mod roots;
mod sens;
mod shoot;

pub use sens::{DIRS, HeightGradient, height_gradient};

use std::cell::Cell;

use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num};
use crate::material::Material;

use law::Law;
use shoot::{Membrane, Point, Reference, Shot};

/// Settings of the shooting. Every tolerance is relative, so they do not
/// depend on units or on the size of the deflection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Relative error tolerance of the ODE integration (per step, on the
    /// stretches relative to the pole strain `l0 - 1`, on the angle and height
    /// relative to their size). Default `1e-10`.
    pub rel_tol: f64,
    /// Shooting tolerance: the clamp residual `(l2(a) - 1) / (l0 - 1)`, and the
    /// relative change of the unknown (pressure, or pole strain `l0 - 1`).
    /// Default `1e-10`.
    pub tol: f64,
    /// Points of the output profile, evenly spaced in the reference radius,
    /// pole and clamp included. Default 201.
    pub n_profile: usize,
    /// Upper end of the pole stretches searched by [`solve_pressure`] and
    /// [`limit_point`]. Default 4 (the neo-Hookean limit point is at 2.196).
    pub max_pole_stretch: f64,
    /// Largest pole-stretch increment of the walk along the pressure curve
    /// that brackets the rising branch; a pressure maximum narrower than this
    /// may be missed. Default 0.15.
    pub max_walk_step: f64,
    /// Function evaluations (shots) allowed per root or maximum search.
    /// Default 200.
    pub max_iterations: usize,
    /// Runge-Kutta steps allowed per shot. Default 20000.
    pub max_steps: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rel_tol: 1e-10,
            tol: 1e-10,
            n_profile: 201,
            max_pole_stretch: 4.0,
            max_walk_step: 0.15,
            max_iterations: 200,
            max_steps: 20_000,
        }
    }
}

impl Options {
    /// Checks every field; the message names the field, the value and the fix.
    pub fn validate(&self) -> Result<(), AxisymError> {
        let bad = |m: String| Err(AxisymError::Options(m));
        if !(self.rel_tol > 0.0 && self.rel_tol <= 1e-3) {
            return bad(format!("rel_tol = {} must be in (0, 1e-3]", self.rel_tol));
        }
        if !(self.tol > 0.0 && self.tol <= 1e-3) {
            return bad(format!("tol = {} must be in (0, 1e-3]", self.tol));
        }
        if self.n_profile < 2 {
            return bad(format!(
                "n_profile = {} must be at least 2 (pole and clamp)",
                self.n_profile
            ));
        }
        if !(self.max_pole_stretch > 1.0 && self.max_pole_stretch.is_finite()) {
            return bad(format!(
                "max_pole_stretch = {} must be above 1",
                self.max_pole_stretch
            ));
        }
        if !(self.max_walk_step > 0.0 && self.max_walk_step.is_finite()) {
            return bad(format!(
                "max_walk_step = {} must be positive",
                self.max_walk_step
            ));
        }
        if self.max_iterations < 10 || self.max_steps < 100 {
            return bad(format!(
                "max_iterations = {} (>= 10) and max_steps = {} (>= 100) are too small",
                self.max_iterations, self.max_steps
            ));
        }
        Ok(())
    }
}

/// The deformed meridian from the pole (`r = 0`) to the clamp (`r = a`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Profile {
    /// Reference radius, m.
    pub r_m: Vec<f64>,
    /// Deformed distance from the axis, m.
    pub rho_m: Vec<f64>,
    /// Height above the clamp plane, m (the apex height at the pole).
    pub z_m: Vec<f64>,
    /// Meridional stretch `l1`.
    pub stretch_meridional: Vec<f64>,
    /// Hoop stretch `l2 = rho / r`.
    pub stretch_hoop: Vec<f64>,
}

/// One equilibrium state.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Stretch at the pole (equibiaxial there).
    pub pole_stretch: f64,
    /// Apex height above the clamp plane, m.
    pub height_m: f64,
    /// Shots (ODE integrations) spent.
    pub iterations: usize,
    /// Final clamp residual `|l2(a) - 1| / (l0 - 1)`.
    pub residual: f64,
    /// The meridian.
    pub profile: Profile,
}

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum AxisymError {
    /// A specimen field is out of range.
    #[error("specimen: {0}")]
    Specimen(#[from] crate::experiment::SpecimenError),
    /// A material parameter is out of range.
    #[error("material: {0}")]
    Material(String),
    /// An option is out of range.
    #[error("axisym options: {0}")]
    Options(String),
    /// A pole stretch below 1 or not finite.
    #[error("pole stretch {0} must be at least 1 (1 is the flat disc)")]
    PoleStretch(f64),
    /// A negative or non-finite pressure.
    #[error("pressure_pa = {0} must be zero or positive and finite")]
    Pressure(f64),
    /// No equilibrium near the rising branch: the pressure is above the
    /// first pressure maximum (snap-through under pressure control).
    #[error(
        "pressure {pressure_pa} Pa is above the limit point of this membrane: the pressure peaks at \
         {limit_pressure_pa:.6e} Pa (apex height {limit_height_m:.6e} m, pole stretch \
         {limit_pole_stretch:.5}); above it a pressure-controlled bubble has no nearby equilibrium \
         (snap-through). Lower the pressure, or follow the falling branch by pole stretch"
    )]
    AboveLimitPoint {
        /// The pressure asked for, Pa.
        pressure_pa: f64,
        /// The pressure maximum, Pa.
        limit_pressure_pa: f64,
        /// Apex height at the maximum, m.
        limit_height_m: f64,
        /// Pole stretch at the maximum.
        limit_pole_stretch: f64,
    },
    /// The pressure was not reached in the pole-stretch range searched.
    #[error(
        "pressure {pressure_pa} Pa is not reached up to pole stretch {max_pole_stretch} (the \
         pressure there is {reached_pa:.6e} Pa and still rising): raise Options::max_pole_stretch"
    )]
    OutOfRange {
        /// The pressure asked for, Pa.
        pressure_pa: f64,
        /// The end of the range searched.
        max_pole_stretch: f64,
        /// The pressure at that end, Pa.
        reached_pa: f64,
    },
    /// The material law has no stable membrane state at this pole stretch
    /// (no meridional tension or stiffness, a quartic modulus `E <= 0`, a
    /// Gent locking stretch).
    #[error("no membrane equilibrium at pole stretch {pole_stretch}: {reason}")]
    OutsideMaterial {
        /// The pole stretch asked for or reached.
        pole_stretch: f64,
        /// What the law does there.
        reason: String,
    },
    /// The rising branch ends at the edge of the material's domain before
    /// reaching the pressure (a material instability acts as a limit point).
    #[error(
        "pressure {pressure_pa} Pa is not reached on the rising branch: the membrane leaves the \
         material's domain after pole stretch {last_pole_stretch:.6} (pressure {last_pressure_pa:.6e} \
         Pa, apex height {last_height_m:.6e} m); {reason}"
    )]
    MaterialLimit {
        /// The pressure asked for, Pa.
        pressure_pa: f64,
        /// The highest pressure found, Pa.
        last_pressure_pa: f64,
        /// Its pole stretch.
        last_pole_stretch: f64,
        /// Its apex height, m.
        last_height_m: f64,
        /// Why the next pole stretch fails.
        reason: String,
    },
    /// The shooting found no solution or did not converge.
    #[error("axisymmetric shooting failed: {0}")]
    NoConvergence(String),
}

/// Shared state of one solve: the membrane, the disc, the options and a
/// count of shots.
struct Ctx<'a> {
    mem: Membrane<'a>,
    a: f64,
    t: f64,
    opts: Options,
    shots: Cell<usize>,
}

/// A point of the pressure curve `pi(l0)`.
#[derive(Debug, Clone, Copy)]
struct Sample {
    l0: f64,
    pi: f64,
    /// Apex height over the radius.
    h: f64,
}

enum WalkEnd {
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
    fn new(
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

    fn shoot(&self, l0: f64, pi: f64, rtol: f64) -> Result<Shot, AxisymError> {
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
    fn pressure_at(
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
    fn walk(&self, target: Option<f64>) -> Result<WalkEnd, AxisymError> {
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
    fn pole_ok(&self, l0: f64) -> Result<(), AxisymError> {
        match self.mem.law.stress(l0, l0) {
            Some(st) if st.p[0] > 0.0 && st.dp[0][0] > 0.0 => Ok(()),
            _ => Err(self.outside(l0)),
        }
    }

    /// The error for a pole stretch outside the law's domain, naming the
    /// strain where a quartic modulus fails.
    fn outside(&self, l0: f64) -> AxisymError {
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
    fn refine_max(&self, lo: f64, hi: f64, best: Sample) -> Result<(Sample, Shot), AxisymError> {
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
    fn stretch_at(&self, pi: f64, lo: f64, hi: f64) -> Result<(f64, Shot), AxisymError> {
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
    fn finish(&self, l0: f64, pi: f64) -> Result<Solution, AxisymError> {
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
    fn flat(&self) -> Solution {
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

/// The equilibrium with pole stretch `pole_stretch` (>= 1): shoots on the
/// pressure. Defined on both sides of a pressure maximum.
pub fn solve_pole_stretch(
    material: &Material,
    specimen: &Specimen,
    pole_stretch: f64,
    opts: &Options,
) -> Result<Solution, AxisymError> {
    let ctx = Ctx::new(material, specimen, opts)?;
    let l0 = pole_stretch;
    if !(l0.is_finite() && l0 >= 1.0) {
        return Err(AxisymError::PoleStretch(l0));
    }
    if l0 == 1.0 {
        return Ok(ctx.flat());
    }
    ctx.pole_ok(l0)?;
    let guess = ctx.mem.cap_estimate(l0).ok_or_else(|| ctx.outside(l0))?;
    let (pi, _) = ctx.pressure_at(l0, guess, opts.tol, opts.rel_tol)?;
    ctx.finish(l0, pi)
}

/// The equilibrium at `pressure_pa` on the stable, rising branch (the first
/// branch from the flat disc); [`AxisymError::AboveLimitPoint`] above its
/// pressure maximum.
pub fn solve_pressure(
    material: &Material,
    specimen: &Specimen,
    pressure_pa: f64,
    opts: &Options,
) -> Result<Solution, AxisymError> {
    let ctx = Ctx::new(material, specimen, opts)?;
    if !(pressure_pa.is_finite() && pressure_pa >= 0.0) {
        return Err(AxisymError::Pressure(pressure_pa));
    }
    if pressure_pa == 0.0 {
        return Ok(ctx.flat());
    }
    let pi = pressure_pa * ctx.a / ctx.t;
    let (l0, _) = match ctx.walk(Some(pi))? {
        WalkEnd::Bracket(lo, hi) => ctx.stretch_at(pi, lo.l0, hi.l0)?,
        WalkEnd::Limit { lo, hi, best } => {
            let (top, top_shot) = ctx.refine_max(lo, hi, best)?;
            if pi > top.pi {
                return Err(AxisymError::AboveLimitPoint {
                    pressure_pa,
                    limit_pressure_pa: top.pi * ctx.t / ctx.a,
                    limit_height_m: top_shot.height() * ctx.a,
                    limit_pole_stretch: top.l0,
                });
            }
            // Below the maximum: the root lies between the samples under it.
            let lo = if best.l0 < top.l0 { best.l0 } else { lo };
            ctx.stretch_at(pi, lo, top.l0)?
        }
        WalkEnd::Exhausted(last) => {
            return Err(AxisymError::OutOfRange {
                pressure_pa,
                max_pole_stretch: opts.max_pole_stretch,
                reached_pa: last.pi * ctx.t / ctx.a,
            });
        }
        WalkEnd::Edge(last, reason) => {
            return Err(AxisymError::MaterialLimit {
                pressure_pa,
                last_pressure_pa: last.pi * ctx.t / ctx.a,
                last_pole_stretch: last.l0,
                last_height_m: last.h * ctx.a,
                reason,
            });
        }
    };
    ctx.finish(l0, pi)
}

/// The first pressure maximum (limit point) of the inflation, searched for
/// pole stretches up to `opts.max_pole_stretch`; `None` when the pressure
/// rises monotonically over that range.
pub fn limit_point(
    material: &Material,
    specimen: &Specimen,
    opts: &Options,
) -> Result<Option<Solution>, AxisymError> {
    let ctx = Ctx::new(material, specimen, opts)?;
    match ctx.walk(None)? {
        WalkEnd::Limit { lo, hi, best } => {
            let (top, _) = ctx.refine_max(lo, hi, best)?;
            ctx.finish(top.l0, top.pi).map(Some)
        }
        WalkEnd::Exhausted(_) | WalkEnd::Edge(..) => Ok(None),
        WalkEnd::Bracket(..) => unreachable!("the walk brackets only a target pressure"),
    }
}

/// The profile as CSV: `r_m,rho_m,z_m,stretch_meridional,stretch_hoop`.
pub fn profile_csv(sol: &Solution) -> CsvOut {
    let p = &sol.profile;
    let mut out = CsvOut::new(&["r_m", "rho_m", "z_m", "stretch_meridional", "stretch_hoop"]);
    for i in 0..p.r_m.len() {
        out.row(&[
            fmt_num(Some(p.r_m[i])),
            fmt_num(Some(p.rho_m[i])),
            fmt_num(Some(p.z_m[i])),
            fmt_num(Some(p.stretch_meridional[i])),
            fmt_num(Some(p.stretch_hoop[i])),
        ]);
    }
    out
}

#[cfg(test)]
mod tests;
