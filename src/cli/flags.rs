//! The command line's names of the settings a library message may name
//! (registered at start-up with `bulge::setting::name_settings_with`).

/// The flag that sets each setting a library message may name.
pub fn flag_of(s: bulge::setting::Setting) -> &'static str {
    use bulge::setting::Setting;
    match s {
        Setting::Fit => "--fit",
        Setting::MaxSamples => "--max-samples",
        Setting::Model => "--model",
        Setting::Solver => "--solver",
        Setting::InnerCorners => "--inner-corners",
        Setting::MinScore => "--min-score",
        Setting::SkipBadFrames => "--skip-bad-frames",
        Setting::Refine => "--refine",
        Setting::CameraDistance => "--camera-distance-m",
        Setting::MetresPerPixel => "--metres-per-pixel",
        Setting::AxisX => "--axis-x-px",
        Setting::ClampRow => "--clamp-row-px",
        Setting::ClampRowStd => "--clamp-row-std-px",
        Setting::PressureMax => "--pressure-max-pa",
        Setting::Degree => "--degree",
        Setting::ToHeights => "--to-heights",
        Setting::Accuracy => "--accuracy",
        Setting::Tolerance => "--tolerance",
        Setting::RadiusM => "--radius-m",
        Setting::ThicknessM => "--thickness-m",
        Setting::Poisson => "--poisson",
        Setting::ElevationDeg => "--elevation-deg",
        Setting::Every => "--every",
        Setting::Glob => "--glob",
        Setting::PointsPx => "--points-px",
        Setting::DistanceM => "--distance-m",
        Setting::Pressure => "--pressure",
        Setting::Camera => "--camera",
        Setting::Orthographic => "--orthographic",
        Setting::Dynamic => "--dynamic",
        Setting::TEnd => "--t-end",
        Setting::Dt => "--dt",
        Setting::Damping => "--damping",
        Setting::DampingLaw => "--damping-law",
        Setting::StepPolicy => "--step-policy",
        Setting::Integrator => "--integrator",
    }
}
