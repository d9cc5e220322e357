//! The experiment file (`experiment.toml`): the specimen, and for later stages
//! the photos, the calibration and the pressure log.
//!
//! ```toml
//! [specimen]
//! radius_m = 0.0375          # free radius a of the clamped disc
//! thickness_m = 0.00035      # initial thickness t
//! poisson = 0.45             # Poisson ratio nu, in [0, 0.5)
//! prebulge_height_m = 0.0    # apex height h0 at p = 0+ (default 0)
//! thickness_std_m = 1e-5     # standard deviation of t (default 0: exact)
//! radius_std_m = 1e-4        # standard deviation of a (default 0: exact)
//!
//! [window]                   # optional: a non-circular clamped opening
//! shape = "ellipse"          # circle (default) | ellipse | rectangle
//! semi_axes_m = [0.0375, 0.01875]   # ellipse; rectangle: length_m, width_m
//! ```
//!
//! With a non-circular `[window]`, `bulge run` simulates the window with the
//! membrane model and corrects the law to the heights through it (the
//! stress stage's spherical-cap formulas take `radius_m`, best the
//! window's half-width: their law is only the correction's start).
//!
//! The standard deviations of the inputs (`[specimen] thickness_std_m`,
//! `radius_std_m`; `[pressure] std_pa`, `relative_std`; `[calibration]
//! metres_per_pixel_std`, `clamp_row_std_px`, with `scale_per_clamp_row`
//! where the scale was read at the clamp row) are gathered by
//! [`Experiment::uncertainty`] and carried to the fitted parameters
//! ([`crate::fit::uncertainty`]).
//!
//! Names may grow, never change. Paths inside the file are relative to the
//! file's own folder.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::io::{BadValue, InputError};

mod tables;
#[cfg(test)]
mod tests;
mod write;

pub use tables::{
    CalibrationConfig, CameraConfig, HeightsConfig, HeightsOrigin, PhotosConfig, PressureConfig,
};
pub use write::{Commented, Draft, Place};

/// The clamped disc under test. All lengths in metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Specimen {
    /// Free radius `a` of the clamped disc, m (> 0).
    pub radius_m: f64,
    /// Initial thickness `t`, m (> 0).
    pub thickness_m: f64,
    /// Poisson ratio, in [0, 0.5).
    pub poisson: f64,
    /// Height `h0` of the stress-free shape over the clamp plane, m (>= 0,
    /// default 0: a flat disc; a slack membrane's stress-free shape is a
    /// spherical cap of this height). An experiment file may ask for it to
    /// be estimated instead ([`PrebulgeHeight::Fit`]); the specimen then
    /// holds 0 until it is.
    #[serde(default)]
    pub prebulge_height_m: f64,
}

/// `[specimen] prebulge_height_m` as an experiment file gives it: a height,
/// or `"fit"`, estimated from the heights by `bulge run`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PrebulgeHeight {
    /// A height in metres.
    Metres(f64),
    /// `"fit"`: to be estimated from the heights.
    Fit,
}

impl Default for PrebulgeHeight {
    fn default() -> Self {
        PrebulgeHeight::Metres(0.0)
    }
}

impl Serialize for PrebulgeHeight {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            PrebulgeHeight::Metres(v) => s.serialize_f64(*v),
            PrebulgeHeight::Fit => s.serialize_str("fit"),
        }
    }
}

impl<'de> Deserialize<'de> for PrebulgeHeight {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum HeightOrWord {
            Number(f64),
            Word(String),
        }
        match HeightOrWord::deserialize(d)? {
            HeightOrWord::Number(v) => Ok(PrebulgeHeight::Metres(v)),
            HeightOrWord::Word(w) if w == "fit" => Ok(PrebulgeHeight::Fit),
            HeightOrWord::Word(w) => Err(serde::de::Error::custom(format!(
                "prebulge_height_m = \"{w}\": give a height in metres (e.g. 0.0035) or \"fit\" (estimated from the heights by bulge run)"
            ))),
        }
    }
}

/// `[window]`: the shape of the clamped opening (default a circle of the
/// specimen's `radius_m`). The window is centred on the apex, its first
/// axis along x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "shape", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Window {
    /// The circle of radius `radius_m` (the exact axisymmetric path).
    #[default]
    Circle,
    /// An ellipse.
    Ellipse {
        /// Semi-axes, m.
        semi_axes_m: [f64; 2],
    },
    /// A rectangle.
    Rectangle {
        /// Side along x, m.
        length_m: f64,
        /// Side along y, m.
        width_m: f64,
    },
}

impl Window {
    /// True for the circular window.
    pub fn is_circle(&self) -> bool {
        matches!(self, Window::Circle)
    }

    /// Checks the sizes; the message names the key, the value and the fix.
    pub fn validate(&self) -> Result<(), BadValue> {
        let bad = |key: &'static str, v: f64| {
            BadValue::new(
                key,
                format!("[window] {key} = {v} must be a positive length in metres"),
            )
        };
        match *self {
            Window::Circle => Ok(()),
            Window::Ellipse { semi_axes_m } => {
                match semi_axes_m.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
                    Some(v) => Err(bad("semi_axes_m", *v)),
                    None => Ok(()),
                }
            }
            Window::Rectangle { length_m, width_m } => {
                for (k, v) in [("length_m", length_m), ("width_m", width_m)] {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(bad(k, v));
                    }
                }
                Ok(())
            }
        }
    }
}

/// `[specimen]` as the file has it: the specimen, its dome height or
/// `"fit"`, and the standard deviations of its dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecimenTable {
    /// Free radius `a`, m.
    pub radius_m: f64,
    /// Initial thickness `t`, m.
    pub thickness_m: f64,
    /// Poisson ratio.
    pub poisson: f64,
    /// The stress-free dome height, or `"fit"`.
    #[serde(default)]
    pub prebulge_height_m: PrebulgeHeight,
    /// Standard deviation of the thickness, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_std_m: Option<f64>,
    /// Standard deviation of the free radius, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_std_m: Option<f64>,
}

impl SpecimenTable {
    /// The table of a specimen whose dimensions are exact.
    pub fn of(s: &Specimen) -> Self {
        SpecimenTable {
            radius_m: s.radius_m,
            thickness_m: s.thickness_m,
            poisson: s.poisson,
            prebulge_height_m: PrebulgeHeight::Metres(s.prebulge_height_m),
            thickness_std_m: None,
            radius_std_m: None,
        }
    }

    /// The specimen (a dome height to be fitted is 0 until it is).
    pub fn specimen(&self) -> Specimen {
        Specimen {
            radius_m: self.radius_m,
            thickness_m: self.thickness_m,
            poisson: self.poisson,
            prebulge_height_m: match self.prebulge_height_m {
                PrebulgeHeight::Metres(h) => h,
                PrebulgeHeight::Fit => 0.0,
            },
        }
    }

    /// The standard deviations, checked: zero or positive, and below the
    /// dimension itself.
    fn std(&self) -> Result<SpecimenStd, BadValue> {
        for (key, sd, of) in [
            ("thickness_std_m", self.thickness_std_m, self.thickness_m),
            ("radius_std_m", self.radius_std_m, self.radius_m),
        ] {
            if let Some(v) = sd
                && !(v.is_finite() && v >= 0.0 && v < of)
            {
                return Err(BadValue::new(
                    key,
                    format!(
                        "{key} = {v} must be a standard deviation in metres, zero or positive and below the dimension itself ({of} m); e.g. 1e-5 for a thickness measured to 10 micrometres"
                    ),
                ));
            }
        }
        Ok(SpecimenStd {
            thickness_std_m: self.thickness_std_m.unwrap_or(0.0),
            radius_std_m: self.radius_std_m.unwrap_or(0.0),
        })
    }
}

/// The standard deviations of the specimen's dimensions, m (0: exact).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SpecimenStd {
    /// Of the thickness.
    pub thickness_std_m: f64,
    /// Of the free radius.
    pub radius_std_m: f64,
}

fn specimen_of_file<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Specimen, D::Error> {
    SpecimenTable::deserialize(d).map(|f| f.specimen())
}

/// A `[specimen]` field out of its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpecimenError {
    /// The free radius is not a positive length.
    #[error(
        "radius_m = {0} must be a positive length in metres (the free radius of the disc, e.g. 0.0375)"
    )]
    Radius(f64),
    /// The thickness is not a positive length.
    #[error("thickness_m = {0} must be a positive length in metres (e.g. 0.00035)")]
    Thickness(f64),
    /// The Poisson ratio is outside [0, 0.5).
    #[error(
        "poisson = {0} must be in [0, 0.5) (rubber: 0.45 to 0.499; 0.5 is singular in the plane-stress formulas)"
    )]
    Poisson(f64),
    /// The pre-bulge height is negative or not finite.
    #[error("prebulge_height_m = {0} must be zero or a positive height in metres")]
    Prebulge(f64),
    /// `prebulge_height_m = "fit"` where a number is needed.
    #[error(
        "prebulge_height_m = \"fit\" is estimated from the heights by `bulge run` (from photos, or from measured heights with [heights] csv = \"heights.csv\"); this command needs it as a number (the value bulge run reports in its notes and material.toml, [fit.refined] prebulge_height_m)"
    )]
    PrebulgeToFit,
}

impl SpecimenError {
    /// The key of the field at fault, as the experiment file spells it.
    pub fn field(&self) -> &'static str {
        match self {
            SpecimenError::Radius(_) => "radius_m",
            SpecimenError::Thickness(_) => "thickness_m",
            SpecimenError::Poisson(_) => "poisson",
            SpecimenError::Prebulge(_) | SpecimenError::PrebulgeToFit => "prebulge_height_m",
        }
    }
}

impl Specimen {
    /// The latex disc of Tudruj et al. (2023): a = 37.5 mm, t = 0.35 mm,
    /// nu = 0.45, flat (the tests' specimen).
    #[cfg(test)]
    pub(crate) fn latex() -> Specimen {
        Specimen {
            radius_m: 0.0375,
            thickness_m: 3.5e-4,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        }
    }

    /// Checks every field; the error names the field, the value and the fix.
    pub fn validate(&self) -> Result<(), SpecimenError> {
        let Specimen {
            radius_m,
            thickness_m,
            poisson,
            prebulge_height_m,
        } = *self;
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(SpecimenError::Radius(radius_m));
        }
        if !(thickness_m.is_finite() && thickness_m > 0.0) {
            return Err(SpecimenError::Thickness(thickness_m));
        }
        if !(poisson.is_finite() && (0.0..0.5).contains(&poisson)) {
            return Err(SpecimenError::Poisson(poisson));
        }
        if !(prebulge_height_m.is_finite() && prebulge_height_m >= 0.0) {
            return Err(SpecimenError::Prebulge(prebulge_height_m));
        }
        Ok(())
    }
}

/// A whole experiment file. Stages read the tables they need and ignore the
/// rest; `[simulate]` and `[report]` hold settings for `bulge run`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    /// The specimen (required).
    #[serde(deserialize_with = "specimen_of_file")]
    pub specimen: Specimen,
    /// Photos (needed by `track`).
    #[serde(default)]
    pub photos: Option<PhotosConfig>,
    /// Measured heights, in place of `[photos]` (`bulge run`, `bulge study`).
    #[serde(default)]
    pub heights: Option<HeightsConfig>,
    /// Calibration (needed by `track`).
    #[serde(default)]
    pub calibration: Option<CalibrationConfig>,
    /// Pressure log (needed by `track`).
    #[serde(default)]
    pub pressure: Option<PressureConfig>,
    /// The camera (default: an 8-bit camera with the sRGB tone curve).
    #[serde(default)]
    pub camera: Option<CameraConfig>,
    /// The clamped opening (default the circle of the specimen's radius).
    #[serde(default)]
    pub window: Window,
    /// Other tables (settings of later stages), kept as TOML.
    #[serde(flatten)]
    pub other: toml::Table,
    /// Folder of the experiment file; relative paths resolve against it.
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// The file it was read from.
    #[serde(skip)]
    pub path: PathBuf,
    /// `prebulge_height_m = "fit"`: the stress-free dome height is to be
    /// estimated from the heights (the specimen then holds 0 until it is).
    #[serde(skip)]
    pub prebulge_fit: bool,
    /// The standard deviations of the specimen's dimensions.
    #[serde(skip)]
    pub specimen_std: SpecimenStd,
}

impl Experiment {
    /// Reads and validates an experiment file.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, InputError> {
        let path = path.as_ref();
        // One read of the file: the whole, then its `[specimen]` as written
        // (the dome height's "fit", the standard deviations).
        let text = crate::io::read_text(path)?;
        let mut e: Experiment = crate::io::parse_toml(path, &text)?;
        let table = specimen_table(path, &text)?;
        e.prebulge_fit = table.prebulge_height_m == PrebulgeHeight::Fit;
        e.specimen
            .validate()
            .map_err(|m| specimen_refused(path, &text, m))?;
        e.window
            .validate()
            .map_err(|m| InputError::from_value(path, m))?;
        if e.heights.is_some() && e.photos.is_some() {
            return Err(InputError::file(
                path,
                "[heights] and [photos] are both given: the heights come from one of them; remove [photos] to use the measured heights, or [heights] to track the photos",
            ));
        }
        if e.heights.is_some() {
            for (table, given) in [
                ("pressure", e.pressure.is_some()),
                ("calibration", e.calibration.is_some()),
                ("camera", e.camera.is_some()),
            ] {
                if given {
                    return Err(InputError::file(
                        path,
                        format!(
                            "[{table}] describes photos and [heights] gives the heights: remove [{table}] (the pressures are the heights file's pressure_pa column)"
                        ),
                    ));
                }
            }
        }
        e.specimen_std = table
            .std()
            .map_err(|m| InputError::file(path, format!("[specimen] {m}")))?;
        let positive = |table: &str, key: &str, v: Option<f64>, example: &str| match v {
            Some(v) if !(v.is_finite() && v >= 0.0) => Err(InputError::file(
                path,
                format!(
                    "[{table}] {key} = {v} must be a standard deviation, zero or positive (e.g. {example})"
                ),
            )),
            _ => Ok(()),
        };
        if let Some(p) = &e.pressure {
            positive("pressure", "std_pa", p.std_pa, "5.0")?;
            positive("pressure", "relative_std", p.relative_std, "0.0025")?;
        }
        if let Some(c) = &e.calibration {
            positive(
                "calibration",
                "metres_per_pixel_std",
                c.metres_per_pixel_std,
                "2e-7",
            )?;
            positive("calibration", "clamp_row_std_px", c.clamp_row_std_px, "0.5")?;
            if let Some(k) = c.scale_per_clamp_row.filter(|k| !k.is_finite()) {
                return Err(InputError::file(
                    path,
                    format!(
                        "[calibration] scale_per_clamp_row = {k} must be a finite number, 1/px (e.g. -0.004), or left out"
                    ),
                ));
            }
        }
        e.base_dir = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        e.path = path.to_path_buf();
        Ok(e)
    }

    /// Only the `[specimen]` of an experiment file (the other tables are
    /// not read, so a file for a simulation or a fit needs no photos).
    pub fn read_specimen(path: impl AsRef<Path>) -> Result<Specimen, InputError> {
        let path = path.as_ref();
        let text = crate::io::read_text(path)?;
        let table = specimen_table(path, &text)?;
        let spec = table.specimen();
        let checked = match table.prebulge_height_m {
            PrebulgeHeight::Fit => Err(SpecimenError::PrebulgeToFit),
            PrebulgeHeight::Metres(_) => spec.validate(),
        };
        checked.map_err(|e| specimen_refused(path, &text, e))?;
        Ok(spec)
    }

    /// Only the `[window]` of an experiment file (the circle when there is
    /// none).
    pub fn read_window(path: impl AsRef<Path>) -> Result<Window, InputError> {
        #[derive(Deserialize)]
        struct Only {
            #[serde(default)]
            window: Window,
        }
        let path = path.as_ref();
        let only: Only = crate::io::read_toml(path)?;
        only.window
            .validate()
            .map_err(|m| InputError::from_value(path, m))?;
        Ok(only.window)
    }

    /// The files this experiment reads, resolved: the experiment file, the
    /// pressure log, the template image and the video (the photos are listed
    /// by the tracker, which knows their pattern), and the photo folder.
    pub fn input_files(&self) -> (Vec<PathBuf>, Option<PathBuf>) {
        let mut files = vec![self.path.clone()];
        if let Some(p) = &self.pressure {
            files.push(self.resolve(&p.csv));
        }
        if let Some(h) = &self.heights {
            files.push(self.resolve(&h.csv));
        }
        let mut folder = None;
        if let Some(ph) = &self.photos {
            if let Some(t) = &ph.template {
                files.push(self.resolve(t));
            }
            if let Some(v) = &ph.video {
                files.push(self.resolve(v));
            }
            folder = ph.dir.as_ref().map(|d| self.resolve(d));
        }
        (files, folder)
    }

    /// The uncertainty of the inputs besides the heights' own: the
    /// specimen's dimensions, the pressure reading and gauge, the scale and
    /// the clamp row (converted to metres with the scale).
    pub fn uncertainty(&self) -> crate::fit::uncertainty::Sources {
        let (scale, cal) = match &self.calibration {
            Some(c) => (c.scale(), Some(c)),
            None => (None, None),
        };
        let scale_relative_std = match (scale, cal.and_then(|c| c.metres_per_pixel_std)) {
            (Some(s), Some(sd)) if s > 0.0 => sd / s,
            _ => 0.0,
        };
        let height_offset_std_m = match (scale, cal.and_then(|c| c.clamp_row_std_px)) {
            (Some(s), Some(px)) => s * px,
            _ => 0.0,
        };
        // per px of clamp row, `d ln(mpp) / d c`; per metre of offset, over the scale
        let offset_scale_per_m = match (scale, cal.and_then(|c| c.scale_per_clamp_row)) {
            (Some(s), Some(k)) if s > 0.0 => k / s,
            _ => 0.0,
        };
        crate::fit::uncertainty::Sources {
            pressure_std_pa: self.pressure.as_ref().and_then(|p| p.std_pa).unwrap_or(0.0),
            pressure_relative_std: self
                .pressure
                .as_ref()
                .and_then(|p| p.relative_std)
                .unwrap_or(0.0),
            thickness_std_m: self.specimen_std.thickness_std_m,
            radius_std_m: self.specimen_std.radius_std_m,
            scale_relative_std,
            height_offset_std_m,
            offset_scale_per_m,
            // found with the dome height, when it is (`bulge run`)
            prebulge_std_m: 0.0,
            prebulge_in_heights: false,
        }
    }

    /// Resolves a path written in the file against the file's folder.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }
}

/// A `[specimen]` value refused, located to its line in the file's `text`.
fn specimen_refused(path: &Path, text: &str, e: SpecimenError) -> InputError {
    let line = crate::io::key_line(text, "specimen", e.field());
    InputError {
        line,
        ..InputError::file(path, format!("[specimen] {e}"))
    }
}

/// The `[specimen]` table of an experiment file's `text`, its other tables
/// not read.
fn specimen_table(path: &Path, text: &str) -> Result<SpecimenTable, InputError> {
    #[derive(Deserialize)]
    struct Only {
        specimen: Option<SpecimenTable>,
    }
    let only: Only = crate::io::parse_toml(path, text)?;
    only.specimen.ok_or_else(|| {
        InputError::file(
            path,
            "no [specimen] table: give radius_m, thickness_m and poisson under [specimen]",
        )
    })
}
