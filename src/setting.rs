//! The settings a message may tell the user to change, named by the front
//! end that shows it: the library says which setting, the command line (or
//! another front end) how it is set there. Without a front end's names the
//! library's own are used (the option's field, or the file's key).

use std::fmt;
use std::sync::OnceLock;

/// A setting that a message may point to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// The law to fit (`FitModel`; `[run] fit`).
    Fit,
    /// The bound on the Monte Carlo samples (`[run] max_samples`).
    MaxSamples,
    /// The membrane models simulated.
    Model,
    /// The quasi-static solver.
    Solver,
    /// The chessboard's inner corners (lens calibration).
    InnerCorners,
    /// The smallest template-match score (`track::Options::min_score`).
    MinScore,
    /// Leaving out the frames that cannot be trusted
    /// (`track::Options::skip_bad_frames`).
    SkipBadFrames,
    /// The sub-pixel refinement (`track::Options::refine`).
    Refine,
    /// The camera's distance from the bubble's axis (`[camera]
    /// distance_m`).
    CameraDistance,
    /// The scale (`[calibration] metres_per_pixel`).
    MetresPerPixel,
    /// Synthetic photos: the axis's column.
    AxisX,
    /// The clamp plane's row (synthetic photos: where it is drawn; `bulge
    /// init`: given instead of found).
    ClampRow,
    /// The given clamp row's standard deviation.
    ClampRowStd,
    /// Synthetic photos: the highest pressure.
    PressureMax,
    /// The polynomial modulus law's degree.
    Degree,
    /// The experiment whose heights a fitted law is corrected to.
    ToHeights,
    /// The relative height error a mesh is sized for.
    Accuracy,
    /// The residual at which a static solve stops.
    Tolerance,
    /// The opening's radius.
    RadiusM,
    /// The membrane's thickness.
    ThicknessM,
    /// The membrane's Poisson ratio.
    Poisson,
    /// The camera's angle above the clamp plane, when known.
    ElevationDeg,
    /// A video's frames: every n-th.
    Every,
    /// Which photos of a folder.
    Glob,
    /// Two points a known distance apart (the scale).
    PointsPx,
    /// The distance between those points.
    DistanceM,
    /// The pressure file.
    Pressure,
    /// A calibrated lens's file.
    Camera,
    /// A telecentric lens: no distance.
    Orthographic,
    /// Integrating in time instead of solving for equilibrium.
    Dynamic,
    /// The simulated time.
    TEnd,
    /// The time step.
    Dt,
    /// The fraction of critical damping.
    Damping,
    /// The damping law.
    DampingLaw,
    /// What an explicit integrator does with a step above its limit.
    StepPolicy,
    /// The time integrator.
    Integrator,
}

impl Setting {
    /// The library's own name: the option's field or the file's key.
    pub fn library_name(self) -> &'static str {
        match self {
            Setting::Fit => "`fit`",
            Setting::MaxSamples => "`max_samples`",
            Setting::Model => "`models`",
            Setting::Solver => "`solver`",
            Setting::InnerCorners => "`inner_corners`",
            Setting::MinScore => "`min_score`",
            Setting::SkipBadFrames => "`skip_bad_frames`",
            Setting::Refine => "`refine`",
            Setting::CameraDistance => "`[camera] distance_m`",
            Setting::MetresPerPixel => "`[calibration] metres_per_pixel`",
            Setting::AxisX => "`axis_x_px`",
            Setting::ClampRow => "`clamp_row_px`",
            Setting::ClampRowStd => "`clamp_row_std_px`",
            Setting::PressureMax => "`pressure_max_pa`",
            Setting::Degree => "`degree`",
            Setting::ToHeights => "`to_heights`",
            Setting::Accuracy => "`accuracy`",
            Setting::Tolerance => "`tolerance`",
            Setting::RadiusM => "`radius_m`",
            Setting::ThicknessM => "`thickness_m`",
            Setting::Poisson => "`poisson`",
            Setting::ElevationDeg => "`elevation_deg`",
            Setting::Every => "`every`",
            Setting::Glob => "`glob`",
            Setting::PointsPx => "`points_px`",
            Setting::DistanceM => "`distance_m`",
            Setting::Pressure => "`pressure`",
            Setting::Camera => "`camera`",
            Setting::Orthographic => "`orthographic`",
            Setting::Dynamic => "`dynamic`",
            Setting::TEnd => "`t_end`",
            Setting::Dt => "`dt`",
            Setting::Damping => "`damping`",
            Setting::DampingLaw => "`damping_law`",
            Setting::StepPolicy => "`step_policy`",
            Setting::Integrator => "`integrator`",
        }
    }
}

static NAMES: OnceLock<fn(Setting) -> &'static str> = OnceLock::new();

/// Names the settings in a front end's words from now on (the command line
/// calls it once at start-up with its flags; a later call is ignored).
pub fn name_settings_with(names: fn(Setting) -> &'static str) {
    let _ = NAMES.set(names);
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = NAMES
            .get()
            .map_or_else(|| self.library_name(), |n| n(*self));
        f.write_str(name)
    }
}
