//! The plausibility guards of the apex, frame by frame (region
//! coordinates, rows growing downward).
//!
//! A lab photo has things behind the bubble (a shelf edge, a cable) that the
//! template or the edge fit can lock on. Each guard is a property that an
//! inflating membrane, or the measurement of its edge, has whatever the
//! material law, the pressure step and the number of photos; a frame that
//! breaks one is searched again near the predicted apex and otherwise
//! refused with the property it breaks and the fix (docs/track.md,
//! *Plausibility guards*, gives the derivations and the figures):
//!
//! - **a measurement**: with `--refine edge` the apex is the edge fit's; a
//!   frame where no edge was found at the template's match has none;
//! - **clutter shown on the emptiest photo's top** (the matcher's
//!   [`EdgeFit::clutter_on_top`]): a line found a few rows above the top;
//! - **the axis stays put**: the apex column within 4 standard errors of the
//!   difference (and 3 px of camera shake) of the last well-placed one;
//! - **above the clamp plane**;
//! - **an apex at all**: an edge fit that cannot place its vertex within
//!   the span (standard error half the span), after frames that could;
//! - **the pole's curvature against the spherical cap through the rim**:
//!   `R = kappa / (2 h / (a^2 + h^2))` lies within [`POLE_RATIO`] for every
//!   flat or slack clamped disc of every law bulge knows, up to 0.97 of the
//!   limit pressure (the exact axisymmetric solutions,
//!   `examples/pole_curvature.rs`), measured by the edge's parabola over the
//!   span; between two photos it changes by at most [`POLE_RATIO_SLOPE`]
//!   times the change of `h / a`. Without the opening's radius, the same
//!   bounds give the curvature's ratio between two photos from their
//!   heights alone; without the clamp row (heights unknown) only a dome
//!   bent the wrong way is refused;
//! - **with the pressure**: the apex does not move against the pressure;
//! - **the trend** ([`Guard::check_trend`]), not a physical bound: the apex
//!   near the row extrapolated from the frames before. It starts the search
//!   near the prediction; a frame that breaks only it is kept with a
//!   warning (near a limit point the height's step is unbounded);
//! - **the fit's residuals are the image's noise**, not a physical bound
//!   either: the residual RMS against that of the frames before, a
//!   chi-square bound for the columns' degrees of freedom (from the first
//!   frame after the reference on). The noise at the edge changes between
//!   photos (a codec's blocks, the exposure), and the stated error grows
//!   with the residual: a frame that breaks only it, and not the trend, is
//!   kept with a warning;
//! - **the columns**: the robust fit keeps a majority of the columns the
//!   frames before kept (its breakdown point).

use super::matcher::EdgeFit;
use super::types::Elevation;

/// The property of an inflating membrane, or of the measurement of its
/// edge, that a frame's apex breaks (see the module doc); each message says
/// what to do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(crate) enum Implausible {
    /// No edge at the template's match.
    #[error(
        "no edge of the bubble's top was found at the template's match (the top is hidden, outside the region, too faint, or level with something behind it): check the region and the template on this photo, or track with {} quadratic",
        crate::setting::Setting::Refine
    )]
    NoEdge,
    /// A line just above the top on the emptiest photo.
    #[error(
        "a line behind the bubble (clutter) lies a few rows above the top in this photo at the lowest pressure, and no emptier photo shows the background there to tell the two apart: clear the background or add a photo at a lower pressure"
    )]
    ClutterOnTop,
    /// The apex column moved off the axis.
    #[error(
        "the apex column moved from {from:.1} to {to:.1} px (tolerance {tol:.1} px), while the bubble's axis stays put: the edge found is off the axis (something beside the top, or the camera moved: then track the photos after the move separately)"
    )]
    AxisMoved { from: f64, to: f64, tol: f64 },
    /// The apex at or below the clamp plane.
    #[error(
        "the apex found at row {row:.1} is at or below the clamp plane ({clamp:.1} in the region), while the frames before were above it: the edge found is not the bubble's top; check the region on this photo"
    )]
    BelowClamp { row: f64, clamp: f64 },
    /// A straight edge: no vertex within the span.
    #[error(
        "the edge found has no apex (its vertex column is uncertain by {x_std:.0} px, half the {span:.0} px span or more), while the frames before had one: the edge fitted is straight, not the bubble's top"
    )]
    NoApex { x_std: f64, span: f64 },
    /// An edge bent the wrong way.
    #[error(
        "the edge found curves downward ({k:.2e} +- {ks:.2e} 1/px), which the top of a bubble does not: it is not the bubble's top; check the region and the template on this photo"
    )]
    CurvesDown { k: f64, ks: f64 },
    /// An edge whose curvature cannot be told from a straight one's.
    #[error(
        "the edge found does not show a dome's curvature ({k:.2e} +- {ks:.2e} 1/px, against {cap:.2e} for a spherical cap {h:.1} px high on an opening of radius {a:.1} px): it cannot be told from a straight edge, so the edge fitted may not be the bubble's top; open the photo to check"
    )]
    NotDomed {
        k: f64,
        ks: f64,
        cap: f64,
        h: f64,
        a: f64,
    },
    /// The pole's curvature outside the range of every membrane law.
    #[error(
        "the edge's curvature {k:.2e} +- {ks:.2e} 1/px is {r:.2} times that of the spherical cap through the rim {h:.1} px high on an opening of radius {a:.1} px ({cap:.2e} 1/px), while an inflated membrane's pole is {lo}-{hi} times it: the edge found is not the bubble's top, or clamp_row_px or radius_m is wrong"
    )]
    PoleRatio {
        k: f64,
        ks: f64,
        r: f64,
        h: f64,
        a: f64,
        cap: f64,
        lo: f64,
        hi: f64,
    },
    /// The pole's ratio changed faster than any membrane's.
    #[error(
        "the edge's curvature against the spherical cap through the rim changed from {r1:.3} to {r:.3} between heights {h1:.1} and {h:.1} px (at most {tol:.3} for a membrane whose height changed so): the edge found is not the bubble's top"
    )]
    PoleRatioChanged {
        r1: f64,
        r: f64,
        h1: f64,
        h: f64,
        tol: f64,
    },
    /// Without the opening: the curvature changed beyond the bounds.
    #[error(
        "the edge's curvature changed from {k1:.2e} to {k:.2e} 1/px between heights {h1:.1} and {h:.1} px, beyond what a membrane's pole does ({min:.2e} to {max:.2e}): the edge found is not the bubble's top"
    )]
    CurvatureChanged {
        k1: f64,
        k: f64,
        h1: f64,
        h: f64,
        min: f64,
        max: f64,
    },
    /// The apex moved against the pressure.
    #[error(
        "the apex moved {dy:+.2} px against the pressure ({p1} -> {p} Pa; rows grow downward), which a membrane does not do: the edge found is not the bubble's, or the pressures are not the photos' (check pressure.csv)"
    )]
    AgainstPressure { dy: f64, p1: f64, p: f64 },
    /// Fewer than half the columns of the frames before.
    #[error(
        "the edge is seen in {columns} columns against {typical} in the frames before: fewer than half, so the columns kept may be something else's (something hides the bubble's top, or the light changed); open the photo to check"
    )]
    FewColumns { columns: usize, typical: usize },
    /// A residual beyond the image noise's bound.
    #[error(
        "the edge's columns disagree (residual RMS {rms:.2} px against {typical:.2} px in the frames before, at most {bound:.2} px from the image's noise): something crosses the bubble's top edge, or the photo is blurred; open the photo to check"
    )]
    ColumnsDisagree { rms: f64, typical: f64, bound: f64 },
    /// The trend rule ([`Guard::check_trend`]): not a physical bound.
    #[error(
        "the apex jumped to row {y:.1}, {:.1} px from where the frames before predict it ({pred:.1}; tolerance {tol:.1} px): the edge found is not the bubble's, or the pressures are not the photos'",
        y - pred
    )]
    Jumped { y: f64, pred: f64, tol: f64 },
}

impl Implausible {
    /// Whether only the trend rule is broken (no physical property): such
    /// a frame may be kept with a warning.
    fn is_trend(&self) -> bool {
        matches!(self, Implausible::Jumped { .. })
    }

    /// The warning to keep a frame with when the rule it breaks is none
    /// that a membrane's physics bounds (`None` for a physical rule):
    /// - the trend ([`Guard::check_trend`]): near the limit pressure the
    ///   height's step between two photos is unbounded;
    /// - the residual ([`Guard::check_physical`] tests it last, so every
    ///   physical property held): the noise at the edge is not the same in
    ///   every photo (a codec's blocks, the exposure), and the height's
    ///   stated error grows with the residual.
    ///
    /// [`Guard::kept_warning`] adds that the trend must hold for the second.
    fn kept_warning(&self) -> Option<String> {
        if self.is_trend() {
            return Some(format!(
                "{self}; kept, since no membrane law bounds the height's step between two photos (near the limit pressure the height grows without bound): check this photo's height, or add photos between it and the one before"
            ));
        }
        match self {
            Implausible::ColumnsDisagree {
                rms,
                typical,
                bound,
            } => Some(format!(
                "the edge's residual RMS is {rms:.2} px against {typical:.2} px in the frames before (at most {bound:.2} px from the image's noise alone); kept, since every physical rule holds: the noise at the edge changes between photos (a JPEG's or a video's blocks, the exposure) and the height's stated error grows with the residual. Open the photo to check that nothing crosses the bubble's top"
            )),
            _ => None,
        }
    }
}

/// The range of `R = kappa_pole / (2 h / (a^2 + h^2))`, the pole's curvature
/// against the spherical cap through the rim with the same height, that the
/// tracker's edge fit can measure on an inflated clamped disc: the exact
/// axisymmetric solutions of `examples/pole_curvature.rs` (neo-Hookean,
/// Mooney-Rivlin C2/C1 0-1, Yeoh, Ogden, Gent Jm 10-100, linear and quartic
/// laws; flat and slack discs; apex heights from 0.02 a up to 0.97 of the
/// limit pressure or a pole stretch of 3), at the pole: 0.700 (Gent Jm 10
/// at h = 1.8 a) to 0.992 (a slack Mooney-Rivlin disc near its stress-free
/// cap, whose own ratio is 1). The edge fit's parabola over a half-span `w`
/// measures `kappa (1 + 3/14 (kappa w)^2)` ([`pole_curvature`] removes it).
pub(crate) const POLE_RATIO: [f64; 2] = [0.70, 1.00];

/// The largest `|dR / d(h / a)|` over the same solutions (2.53, a slack
/// disc leaving its stress-free cap; 0.23 on flat discs): two photos of
/// heights `h1`, `h2` differ in `R` by at most this times `|h2 - h1| / a`.
pub(crate) const POLE_RATIO_SLOPE: f64 = 2.6;

/// The standard normal quantile of the guards' statistical bounds: a clean
/// photo is refused by one with probability 1e-4 (one-sided).
const Z: f64 = 3.72;

/// Standard errors by which a measured value may lie beyond a bound that
/// holds exactly (the tracker's usual 4).
pub(crate) const SIGMAS: f64 = 4.0;

/// Columns over which the edge rows of neighbouring columns are correlated
/// (the blur spreads the noise of one column over its neighbours, about
/// twice the blur's standard deviation of 1-2 px): the residuals of `n`
/// columns carry about `n / 3` degrees of freedom.
const CORRELATED_COLUMNS: f64 = 3.0;

/// What the guards keep of an accepted frame.
#[derive(Debug, Clone, Copy)]
struct Accepted {
    /// Pressure, Pa.
    p: f64,
    /// Apex, px (region coordinates).
    apex: [f64; 2],
    /// Standard error of the apex column, px.
    x_std: f64,
    /// The edge fit's residual RMS (px), curvature and its standard error
    /// (1/px), and columns.
    edge: Option<(f64, f64, f64, usize)>,
}

/// The guards' state: the set-up and the frames accepted so far.
pub(super) struct Guard {
    /// The clamp plane's row in the region, px, when known.
    clamp_row: Option<f64>,
    /// The opening's radius, px, when known and finite.
    opening_px: Option<f64>,
    /// Half-width of the edge fit's span of columns, px.
    span: f64,
    /// The apex is the edge fit's (`--refine edge`): a frame without an
    /// edge has no measurement, only the template's match.
    edge_required: bool,
    /// A camera above the clamp plane: the silhouette's top is not the
    /// pole's projection.
    elevation: Option<Elevation>,
    /// The accepted frames.
    history: Vec<Accepted>,
}

/// The upper `Z` quantile of `s1^2 / s2^2`, the ratio of two independent
/// variance estimates of the same variance with `n1` and `n2` degrees of
/// freedom (log-normal approximation of the F distribution:
/// `var ln s^2 = 2 / n`), as a ratio of standard deviations.
pub(crate) fn rms_ratio_bound(n1: f64, n2: f64) -> f64 {
    (0.5 * Z * (2.0 / n1.max(1.0) + 2.0 / n2.max(1.0)).sqrt()).exp()
}

/// The pole's curvature from the curvature `k` (1/px) of a parabola fitted
/// by least squares over the columns within `w` px of the axis: a circle of
/// curvature `kappa` fits `kappa (1 + 3/14 (kappa w)^2)` (the `x^4 / 8 R^3`
/// term of the circle projected on `x^2` over `[-w, w]`: `6/7 w^2`); on the
/// exact membranes this leaves less than 0.002 of `R` over 0.3 a.
pub(crate) fn pole_curvature(k: f64, w: f64) -> f64 {
    k / (1.0 + 3.0 / 14.0 * (k * w).powi(2))
}

impl Guard {
    pub(super) fn new(
        clamp_row: Option<f64>,
        opening_px: Option<f64>,
        span_px: usize,
        edge_required: bool,
    ) -> Self {
        Guard {
            clamp_row,
            opening_px: opening_px.filter(|a| a.is_finite() && *a > 0.0),
            span: span_px as f64,
            edge_required,
            elevation: None,
            history: Vec::new(),
        }
    }

    /// The same guards for a camera raised above the clamp plane.
    pub(super) fn with_elevation(mut self, elevation: Option<Elevation>) -> Self {
        self.elevation = elevation.filter(|e| e.radians != 0.0);
        self
    }

    /// The apex height above the clamp plane of an apex at row `y`, px,
    /// when the clamp row is known: the silhouette's top `t` above the
    /// ring's centre, corrected for the camera's elevation with the
    /// membrane's pole radius (not the edge's curvature, which the guards
    /// test against it).
    fn height(&self, y: f64) -> Option<f64> {
        let t = self.clamp_row? - y;
        match (self.elevation, self.opening_px) {
            (Some(el), Some(a)) if t > 0.0 => Some(el.height_px(t, None, a).0),
            _ => Some(t),
        }
    }

    /// The apex predicted at pressure `p` from the last two accepted
    /// frames (the last one's when only one, or equal pressures).
    pub(super) fn predict(&self, p: f64) -> Option<[f64; 2]> {
        let n = self.history.len();
        let Accepted {
            p: p1, apex: a1, ..
        } = *self.history.last()?;
        if n < 2 {
            return Some(a1);
        }
        let Accepted {
            p: p0, apex: a0, ..
        } = self.history[n - 2];
        if (p1 - p0).abs() <= f64::EPSILON * p1.abs().max(1.0) {
            return Some(a1);
        }
        let t = (p - p1) / (p1 - p0);
        Some([a1[0], a1[1] + t * (a1[1] - a0[1])])
    }

    /// Why the apex `apex` (standard errors `[x_std, y_std]`, px) at
    /// pressure `p` is not plausible, if it is not: the property broken and
    /// what to do.
    pub(super) fn check(
        &self,
        p: f64,
        apex: [f64; 2],
        stds: [f64; 2],
        edge: Option<&EdgeFit>,
    ) -> Result<(), Implausible> {
        self.check_physical(p, apex, stds, edge)?;
        self.check_trend(p, apex[1], stds[1])
    }

    /// [`Guard::check`] without the trend rule ([`Guard::check_trend`]):
    /// the properties every inflating membrane and every measurement of its
    /// edge have, whatever the law and the pressure step.
    pub(super) fn check_physical(
        &self,
        p: f64,
        apex: [f64; 2],
        stds: [f64; 2],
        edge: Option<&EdgeFit>,
    ) -> Result<(), Implausible> {
        // The template's match alone is no measurement of the top.
        if self.edge_required && edge.is_none() {
            return Err(Implausible::NoEdge);
        }
        if edge.is_some_and(|e| e.clutter_on_top) {
            return Err(Implausible::ClutterOnTop);
        }
        let [x_std, std] = stds;
        let y = apex[1];
        // The axis does not move: the apex column stays within 4 standard
        // errors of the difference, plus 3 px of camera shake, of the last
        // well-placed one.
        if let Some(&Accepted {
            apex: a1,
            x_std: xs1,
            ..
        }) = self.history.iter().rev().find(|h| h.x_std.is_finite())
            && x_std.is_finite()
        {
            let tol = 3.0 + SIGMAS * x_std.hypot(xs1);
            if (apex[0] - a1[0]).abs() > tol {
                return Err(Implausible::AxisMoved {
                    from: a1[0],
                    to: apex[0],
                    tol,
                });
            }
        }
        // (When the first frame's apex is below it too, the clamp row is
        // wrong, which the check after tracking reports.)
        if let Some(c) = self.clamp_row
            && y >= c
            && self.history.first().is_some_and(|h| h.apex[1] < c)
        {
            return Err(Implausible::BelowClamp { row: y, clamp: c });
        }
        // A curved top places its vertex: an edge fit whose vertex column is
        // uncertain by half the span has no apex in the span, while the
        // frames before had one.
        let placed: Vec<f64> = self.history.iter().map(|h| h.x_std).collect();
        if placed.len() >= 2
            && placed[placed.len() - 2..]
                .iter()
                .all(|&s| s < 0.25 * self.span)
            && (x_std >= 0.5 * self.span || x_std.is_nan())
        {
            return Err(Implausible::NoApex {
                x_std,
                span: 2.0 * self.span,
            });
        }
        if let Some(e) = edge {
            self.check_curvature(y, e)?;
        }
        let noise = 3.0 * std + 0.5;
        if let Some(&Accepted {
            p: p1, apex: a1, ..
        }) = self.history.last()
        {
            let dy = y - a1[1];
            if (p > p1 && dy > noise) || (p < p1 && dy < -noise) {
                return Err(Implausible::AgainstPressure { dy, p1, p });
            }
        }
        if let Some(e) = edge {
            self.check_columns(e)?;
        }
        Ok(())
    }

    /// When the frame whose check gave `why` (apex row `y`, standard
    /// error `std`, px, at pressure `p`) broke only a rule no physics
    /// bounds, the warning to keep it with
    /// ([`Implausible::kept_warning`]): the trend rule alone, or the
    /// residual rule alone with the trend holding ([`Guard::check`] tests
    /// the trend only after every other rule). `None` otherwise.
    pub(super) fn kept_warning(
        &self,
        why: &Implausible,
        p: f64,
        y: f64,
        std: f64,
    ) -> Option<String> {
        match why {
            Implausible::ColumnsDisagree { .. } if self.check_trend(p, y, std).is_err() => None,
            _ => why.kept_warning(),
        }
    }

    /// The trend rule: the apex row `y` (standard error `std`, px) at
    /// pressure `p` lies within `2 px + |predicted step| + 4 std` of the
    /// row extrapolated linearly in pressure from the last two accepted
    /// frames (the step may double). No membrane law bounds it: near a
    /// limit point `dh/dp` grows without bound, so a coarse step there
    /// breaks it on a clean photo. It is the trigger of the search near
    /// the predicted apex; a frame that breaks only this rule, and whose
    /// search finds nothing better, is kept with a warning
    /// ([`Guard::kept_warning`]).
    pub(super) fn check_trend(&self, p: f64, y: f64, std: f64) -> Result<(), Implausible> {
        if self.history.len() >= 2
            && let Some(pred) = self.predict(p)
        {
            let last = self.history[self.history.len() - 1].apex[1];
            let tol = 2.0 + (pred[1] - last).abs() + SIGMAS * std;
            if (y - pred[1]).abs() > tol {
                return Err(Implausible::Jumped {
                    y,
                    pred: pred[1],
                    tol,
                });
            }
        }
        Ok(())
    }

    /// The pole's curvature against the spherical cap through the rim
    /// ([`POLE_RATIO`], [`POLE_RATIO_SLOPE`]); see the module doc.
    fn check_curvature(&self, y: f64, e: &EdgeFit) -> Result<(), Implausible> {
        let k = pole_curvature(e.curvature, self.span);
        let ks = e.curvature_std;
        let Some(h) = self.height(y).filter(|h| *h > 2.0) else {
            // No height: a dome is convex upward (positive curvature); a
            // curvature below zero by 4 standard errors is no dome.
            if k < -SIGMAS * ks {
                return Err(Implausible::CurvesDown { k, ks });
            }
            return Ok(());
        };
        let [lo, hi] = POLE_RATIO;
        if let Some(a) = self.opening_px {
            let cap = 2.0 * h / (a * a + h * h);
            let (r, rs) = (k / cap, ks / cap);
            // The span is measured where the cap's top sags by 1 px or more
            // over it; elsewhere the edge is nearly straight whatever it is.
            let visible = 0.5 * cap * self.span * self.span >= 1.0;
            // There the curvature must tell the dome from a straight edge
            // (a shelf edge along a flat top, the lower edge of a highlight
            // inside the dome) by 2 standard errors: `rs <= lo / 2`.
            if visible && rs > 0.5 * lo {
                return Err(Implausible::NotDomed { k, ks, cap, h, a });
            }
            // With no frame before (the reference frame), nothing else tests
            // the edge: the dome must be shown, 2 standard errors inside.
            let low = if self.history.is_empty() { 2.0 } else { SIGMAS };
            // The bounds hold at every sag, and each test is against the
            // curvature's own standard error, so they are tested however
            // little the cap sags over the span (as the ratio of two
            // photos' curvatures is where the opening is not known, below):
            // a first photo's top that sags under a pixel but bends the
            // wrong way by 2 standard errors is no dome (a cable's border
            // along it: -0.35 +- 0.15 of the cap's curvature on a sweep
            // photo written 3.7 px high before), and an edge that curves
            // visibly where the cap through the rim would be nearly
            // straight is no pole of that opening (radius_m wrong).
            if r < lo - low * rs || r > hi + SIGMAS * rs {
                return Err(Implausible::PoleRatio {
                    k,
                    ks,
                    r,
                    h,
                    a,
                    cap,
                    lo,
                    hi,
                });
            }
            if let Some((k1, ks1, h1)) = self.recent_curvature() {
                let cap1 = 2.0 * h1 / (a * a + h1 * h1);
                let (r1, rs1) = (k1 / cap1, ks1 / cap1);
                let tol = POLE_RATIO_SLOPE * (h - h1).abs() / a + SIGMAS * rs.hypot(rs1);
                if (r - r1).abs() > tol {
                    return Err(Implausible::PoleRatioChanged { r1, r, h1, h, tol });
                }
            }
        } else if let Some((k1, ks1, h1)) = self.recent_curvature() {
            // Without the opening's radius: k / k1 lies within
            // [lo / hi / q, hi / lo * q], q = max(h, h1) / min(h, h1).
            let q = h.max(h1) / h.min(h1);
            let noise = SIGMAS * ks.hypot(ks1 * k / k1.max(f64::MIN_POSITIVE));
            let (min, max) = (k1 * lo / hi / q, k1 * hi / lo * q);
            if k < min - noise || k > max + noise {
                return Err(Implausible::CurvatureChanged {
                    k1,
                    k,
                    h1,
                    h,
                    min,
                    max,
                });
            }
        }
        Ok(())
    }

    /// The edge fit's columns against the frames before: a majority of the
    /// columns kept (the robust fit's breakdown point), and a residual RMS
    /// within the chi-square bound of the image noise the frames before
    /// show.
    fn check_columns(&self, e: &EdgeFit) -> Result<(), Implausible> {
        let mut cols: Vec<usize> = self
            .history
            .iter()
            .filter_map(|h| h.edge.map(|e| e.3))
            .collect();
        if !cols.is_empty() {
            cols.sort_unstable();
            let typical = cols[cols.len() / 2];
            if 2 * e.columns < typical {
                return Err(Implausible::FewColumns {
                    columns: e.columns,
                    typical,
                });
            }
        }
        // (The last three: the residual of a parabola grows with the dome's
        // curvature.)
        let recent: Vec<(f64, usize)> = self
            .history
            .iter()
            .rev()
            .filter_map(|h| h.edge.map(|e| (e.0, e.3)))
            .take(3)
            .collect();
        if !recent.is_empty() {
            let mut rms: Vec<f64> = recent.iter().map(|r| r.0).collect();
            rms.sort_by(f64::total_cmp);
            let typical = rms[rms.len() / 2];
            let dof = |n: usize| (n as f64 - 3.0).max(1.0) / CORRELATED_COLUMNS;
            let before: f64 = recent.iter().map(|r| dof(r.1)).sum();
            let bound = typical * rms_ratio_bound(dof(e.columns), before);
            if e.rms > bound {
                return Err(Implausible::ColumnsDisagree {
                    rms: e.rms,
                    typical,
                    bound,
                });
            }
        }
        Ok(())
    }

    /// Of the last three accepted frames with an edge fit, the one of
    /// median curvature per px of height: its curvature, standard error
    /// and height above the clamp row, px (`None` without the clamp row).
    fn recent_curvature(&self) -> Option<(f64, f64, f64)> {
        let mut c: Vec<(f64, f64, f64)> = self
            .history
            .iter()
            .rev()
            .filter_map(|h| {
                let hh = self.height(h.apex[1]).filter(|v| *v > 2.0)?;
                h.edge.map(|e| (pole_curvature(e.1, self.span), e.2, hh))
            })
            .take(3)
            .collect();
        if c.is_empty() {
            return None;
        }
        c.sort_by(|a, b| (a.0 / a.2).total_cmp(&(b.0 / b.2)));
        Some(c[c.len() / 2])
    }

    /// Records an accepted frame.
    pub(super) fn accept(
        &mut self,
        p: f64,
        apex: [f64; 2],
        stds: [f64; 2],
        edge: Option<&EdgeFit>,
    ) {
        self.history.push(Accepted {
            p,
            apex,
            x_std: stds[0],
            edge: edge.map(|e| (e.rms, e.curvature, e.curvature_std, e.columns)),
        });
    }
}

#[cfg(test)]
mod tests;
