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
use crate::numerics::roots;
mod sens;
mod shoot;
mod walk;

pub use sens::{DIRS, HeightGradient, height_gradient};

use crate::experiment::Specimen;
use crate::io::{CsvOut, fmt_num};
use crate::material::Material;

use walk::{Ctx, WalkEnd};

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

impl Solution {
    /// The meridian's curvature at the pole, 1/m: `z = h - kappa s / 2 + c
    /// s^2` (`s = rho^2`) fitted by least squares to the seven profile
    /// points next to the pole.
    pub fn pole_curvature_per_m(&self) -> f64 {
        let p = &self.profile;
        let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 1..8.min(p.rho_m.len()) {
            let (s, y) = (p.rho_m[i] * p.rho_m[i], p.z_m[i] - self.height_m);
            (a11, a12, a22) = (a11 + s * s, a12 + s * s * s, a22 + s * s * s * s);
            (b1, b2) = (b1 + s * y, b2 + s * s * y);
        }
        -2.0 * (b1 * a22 - b2 * a12) / (a11 * a22 - a12 * a12)
    }
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

impl crate::Refusal for AxisymError {
    /// The specimen, the material and the options are the user's; a
    /// pressure without solution is a result of valid input.
    fn is_bad_input(&self) -> bool {
        matches!(
            self,
            AxisymError::Specimen(_) | AxisymError::Material(_) | AxisymError::Options(_)
        )
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
