//! Heights -> stress and strain (Tudruj et al. (2023), eqs 18-25), corrected where the
//! paper is wrong.
//!
//! A clamped disc of free radius `a` and initial thickness `t` bulges under the
//! gauge pressure `p` into a bubble whose apex stands at height `H` above the
//! clamp plane (`H = h + h0`, the paper's rise `h` plus the pre-bulge height
//! `h0`). The bubble is taken to be a spherical cap. With `x = H / a`:
//!
//! | quantity | formula | Tudruj et al. (2023) |
//! |---|---|---|
//! | cap radius | $R = (a^2 + H^2) / (2H) = \tfrac a2 (x + 1/x)$ | eqs 19, 20 |
//! | cap half-angle | $\theta = 2 \arctan(H/a)$ | eqs 21, 22 (corrected) |
//! | meridian arc length | $s = 2R\theta = 2a\, g(x)$, $g(x) = (x + 1/x)\arctan x$ | eqs 21, 22 |
//! | stretch | $\lambda = s_1 / s_0 = g(x_1) / g(x_0)$ | eq 23 |
//! | strain | $\varepsilon = \lambda - 1$ (engineering) or $\ln\lambda$ (log) | eq 24 (corrected) |
//! | pole stress | $\sigma = pR/(2t)$ | eq 18 |
//! | true stress | $\lambda\sigma$ (`paper`) or $\lambda^2\sigma$ (`incompressible`) | eq 25 |
//! | secant modulus | $(1-\nu) S/\varepsilon$ (`biaxial`) or $S/\varepsilon$ (`uniaxial`) | section 7 |
//!
//! where `x0 = h0/a` (pre-bulge, `s0`) and `x1 = H/a` (loaded, `s1`), and `S`
//! is the stress chosen by [`ModulusStress`].
//!
//! ## Where the paper is wrong, and what is done here
//!
//! * **The asin branch (eqs 21, 22).** The paper writes
//!   $\theta = \arcsin(2aH/(a^2+H^2))$. Since $\sin\theta = a/R$, this is right
//!   only up to the hemisphere (`H <= a`); past it `asin` returns `pi - theta`
//!   and the arc length *falls* as the bubble grows (at `H = 2a` it gives
//!   `s = 2.318 a`, shorter than the hemisphere's `pi a`, instead of `5.536 a`).
//!   `tan(theta/2) = H/a` holds on every branch, so [`cap_half_angle`] uses
//!   `theta = 2 atan(H/a)`.
//! * **The flat limit.** `s = (a^2+H^2)/H * theta` is `0/0` at `H = 0` and
//!   loses digits as `H -> 0`, and `lambda - 1` cancels catastrophically. Here
//!   `g(x) - 1` ([`arc_excess`]) is summed from its series for `x < 1/2`:
//!   $g(x) = (1 + x^2)\,\arctan(x)/x = 1 + \sum_{n\ge1} (-1)^{n-1}\frac{2x^{2n}}{4n^2-1}
//!   = 1 + \tfrac23 x^2 - \tfrac2{15}x^4 + \tfrac2{35}x^6 - \dots$
//!   (multiply $\arctan(x)/x = \sum (-1)^n x^{2n}/(2n+1)$ by $1 + x^2$; the
//!   coefficient of $x^{2n}$ is $(-1)^n[1/(2n+1) - 1/(2n-1)]$), so `s -> 2a`
//!   and the strain `(2/3) x^2` keeps full relative precision down to
//!   `H = 1e-150 a`.
//! * **The pre-bulged case.** With `h0 > 0` the strain is
//!   `(g(x1) - g(x0)) / g(x0)`; in the series range the difference is summed as
//!   `(x1^2 - x0^2) * sum c_n (x1^{2n} - x0^{2n}) / (x1^2 - x0^2)` with the
//!   divided differences built from positive terms and `x1 - x0 = (H - h0)/a`
//!   taken from the inputs, so no digits are lost when `H` is close to `h0`.
//!   Above `x = 1/2` the direct difference loses at most a factor
//!   `g / (x g') <= 4` over the problem's own conditioning.
//! * **Eq 24's sign.** `eps = 1 - lambda` is negative in tension; the strain
//!   here is `lambda - 1` (or `ln lambda`).
//! * **Eq 25's thickness.** `lambda * sigma` is the stress for a thickness
//!   `t / lambda`. An incompressible membrane stretched equibiaxially by
//!   `lambda` thins to `t / lambda^2`, so its Cauchy stress is
//!   `lambda^2 p R / (2t)` ([`TrueStress::Incompressible`]). The paper's form
//!   is kept as the default so that the paper's procedure can be reproduced.
//!   Read differently, `lambda * sigma` needs no thickness assumption at all:
//!   it is the nominal (first Piola-Kirchhoff) stress, the tension
//!   `lambda pR/2` per unit *reference* length over the initial thickness,
//!   which is what feeds the secant modulus by default ([`ModulusStress`]).
//! * **Mean versus pole stretch.** `lambda = s1/s0` is the mean meridional
//!   stretch; the pole, where eq 18 gives the stress, stretches more (for a
//!   neo-Hookean membrane at `h/a = 0.531`: mean 1.178, pole 1.20). Stress and
//!   strain are therefore not measured at the same material point; this is a
//!   property of the method, documented rather than corrected.
//!
//! ## Uncertainty
//!
//! Given a standard deviation `sigma_H` of the height, every derived quantity
//! `q(H)` gets `q_std = |dq/dH| sigma_H` (first-order propagation; pressure,
//! `a`, `t`, `nu` and `h0` are taken as exact). The derivatives are analytic:
//! `dR/dH = (1 - 1/x^2)/2`, `ds/dH = 2 g'(x)` with
//! `g'(x) = (1 - 1/x^2) atan x + 1/x` (series below `x = 1/2`), `dlambda/dH =
//! g'(x1) / (a g(x0))`, and the product and quotient rules for the rest.

mod cap;
pub mod prebulge;
mod stress;
mod types;

pub use cap::*;
pub use stress::*;
pub use types::*;

#[cfg(test)]
mod tests;
