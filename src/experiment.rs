//! The experiment file (`experiment.toml`): the specimen, and for later stages
//! the photos, the calibration and the pressure log.
//!
//! ```toml
//! [specimen]
//! radius_m = 0.0375          # free radius a of the clamped disc
//! thickness_m = 0.00035      # initial thickness t
//! poisson = 0.45             # Poisson ratio nu, in [0, 0.5)
//! prebulge_height_m = 0.0    # apex height h0 at p = 0+ (default 0)
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
//! Names may grow, never change. Paths inside the file are relative to the
//! file's own folder.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::io::{InputError, read_toml};

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
    /// spherical cap of this height). In an experiment file `"fit"` asks
    /// `bulge run` to estimate it from the heights (read as NaN here until
    /// [`Experiment::read`] takes it out).
    #[serde(default, deserialize_with = "height_or_fit")]
    pub prebulge_height_m: f64,
}

/// A height in metres, or the word `fit` (as NaN).
fn height_or_fit<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum HeightOrFit {
        Number(f64),
        Word(String),
    }
    match HeightOrFit::deserialize(d)? {
        HeightOrFit::Number(v) => Ok(v),
        HeightOrFit::Word(w) if w == "fit" => Ok(f64::NAN),
        HeightOrFit::Word(w) => Err(serde::de::Error::custom(format!(
            "prebulge_height_m = \"{w}\": give a height in metres (e.g. 0.0035) or \"fit\" (estimated from the heights by bulge run)"
        ))),
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
    pub fn validate(&self) -> Result<(), String> {
        let bad =
            |key: &str, v: f64| format!("[window] {key} = {v} must be a positive length in metres");
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
        "prebulge_height_m = \"fit\" is estimated from the heights by `bulge run`; this command needs it as a number (the value bulge run reports in material.toml, [fit.refined] prebulge_height_m)"
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
        if prebulge_height_m.is_nan() {
            return Err(SpecimenError::PrebulgeToFit);
        }
        if !(prebulge_height_m.is_finite() && prebulge_height_m >= 0.0) {
            return Err(SpecimenError::Prebulge(prebulge_height_m));
        }
        Ok(())
    }
}

/// `[photos]`: where the photos are and what to look for in them: a folder
/// of photos (`dir`, `glob`) or a video (`video`, with `every` or `times_s`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhotosConfig {
    /// Folder of the photos, relative to the experiment file.
    #[serde(default)]
    pub dir: Option<PathBuf>,
    /// File-name pattern, e.g. `*.png` (default `*`); files are taken in
    /// natural sort order.
    #[serde(default)]
    pub glob: Option<String>,
    /// Or a video file, relative to the experiment file (read with OpenCV's
    /// video module).
    #[serde(default)]
    pub video: Option<PathBuf>,
    /// Video only: take every N-th frame (frames 0, N, 2N, ...; default 1).
    #[serde(default)]
    pub every: Option<usize>,
    /// Video only: take the frame nearest each of these times, s.
    #[serde(default)]
    pub times_s: Option<Vec<f64>>,
    /// Photo folder only: time between consecutive photos (in file-name
    /// order), s; gives each photo a time for a pressure log by time.
    #[serde(default)]
    pub interval_s: Option<f64>,
    /// Photo folder only: time of the first photo, s (default 0; with
    /// `interval_s`).
    #[serde(default)]
    pub start_s: Option<f64>,
    /// Region where the apex can move: `[x, y, width, height]` in pixels.
    pub roi_px: [i32; 4],
    /// Template image file, relative to the experiment file.
    #[serde(default)]
    pub template: Option<PathBuf>,
    /// Or the template cut from the reference frame: `[x, y, width, height]`.
    #[serde(default)]
    pub template_rect_px: Option<[i32; 4]>,
    /// Index of the reference frame (default 0).
    #[serde(default)]
    pub reference_frame: usize,
    /// Apex position inside the template, `[dx, dy]` px (default: its centre).
    #[serde(default)]
    pub apex_in_template_px: Option<[f64; 2]>,
}

impl PhotosConfig {
    /// The file-name pattern of a photo folder (`*` when not given).
    pub fn glob(&self) -> &str {
        self.glob.as_deref().unwrap_or("*")
    }
}

/// `[calibration]`: pixels to metres and the clamp plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct CalibrationConfig {
    /// Scale, m per pixel.
    #[serde(default)]
    pub metres_per_pixel: Option<f64>,
    /// Or two image points a known distance apart.
    #[serde(default)]
    pub points_px: Option<[[f64; 2]; 2]>,
    /// Distance between `points_px`, m.
    #[serde(default)]
    pub distance_m: Option<f64>,
    /// Image row of the clamp plane, px, when known.
    #[serde(default)]
    pub clamp_row_px: Option<f64>,
}

/// `[pressure]`: the pressure log, joined per photo (columns
/// `file,pressure_pa`) or by time (columns `time_s,pressure_pa`, interpolated
/// linearly at each frame's time).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureConfig {
    /// The CSV, relative to the experiment file.
    pub csv: PathBuf,
    /// Clock offset of a log by time, s: logger time = frame time +
    /// `offset_s` (the logger's clock reads `offset_s` when the camera's
    /// reads 0). Default 0.
    #[serde(default)]
    pub offset_s: Option<f64>,
}

/// A whole experiment file. Stages read the tables they need and ignore the
/// rest; `[simulate]` and `[report]` hold settings for `bulge run`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    /// The specimen (required).
    pub specimen: Specimen,
    /// Photos (needed by `track`).
    #[serde(default)]
    pub photos: Option<PhotosConfig>,
    /// Calibration (needed by `track`).
    #[serde(default)]
    pub calibration: Option<CalibrationConfig>,
    /// Pressure log (needed by `track`).
    #[serde(default)]
    pub pressure: Option<PressureConfig>,
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
}

impl Experiment {
    /// Reads and validates an experiment file.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, InputError> {
        let path = path.as_ref();
        let mut e: Experiment = read_toml(path)?;
        if e.specimen.prebulge_height_m.is_nan() {
            e.prebulge_fit = true;
            e.specimen.prebulge_height_m = 0.0;
        }
        e.specimen
            .validate()
            .map_err(|m| InputError::file(path, format!("[specimen] {m}")))?;
        e.window.validate().map_err(|m| InputError::file(path, m))?;
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
        #[derive(Deserialize)]
        struct Only {
            specimen: Option<Specimen>,
        }
        let path = path.as_ref();
        let only: Only = crate::io::read_toml(path)?;
        let spec = only.specimen.ok_or_else(|| {
            InputError::file(
                path,
                "no [specimen] table: give radius_m, thickness_m and poisson under [specimen]",
            )
        })?;
        spec.validate()
            .map_err(|e| InputError::file(path, format!("[specimen] {e}")))?;
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
            .map_err(|m| InputError::file(path, m))?;
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

    /// Resolves a path written in the file against the file's folder.
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[window]` reads as a circle by default, an ellipse or a rectangle
    /// by `shape`; unknown keys and non-positive sizes are refused.
    #[test]
    fn window_table() {
        let base = "[specimen]\nradius_m = 0.01875\nthickness_m = 0.00035\npoisson = 0.45\n";
        let dir = tempfile::tempdir().unwrap();
        let read = |extra: &str| {
            let p = dir.path().join("e.toml");
            std::fs::write(&p, format!("{base}{extra}")).unwrap();
            Experiment::read(&p).map(|e| e.window)
        };
        assert_eq!(read("").unwrap(), Window::Circle);
        assert_eq!(
            read("[window]\nshape = \"ellipse\"\nsemi_axes_m = [0.0375, 0.01875]\n").unwrap(),
            Window::Ellipse {
                semi_axes_m: [0.0375, 0.01875]
            }
        );
        assert_eq!(
            read("[window]\nshape = \"rectangle\"\nlength_m = 0.08\nwidth_m = 0.02\n").unwrap(),
            Window::Rectangle {
                length_m: 0.08,
                width_m: 0.02
            }
        );
        for (extra, needle) in [
            (
                "[window]\nshape = \"ellipse\"\nsemi_axes_m = [0.0375, 0.0]\n",
                "semi_axes_m = 0",
            ),
            (
                "[window]\nshape = \"rectangle\"\nlength_m = 0.08\nwidth = 0.02\n",
                "width",
            ),
            ("[window]\nshape = \"hexagon\"\n", "hexagon"),
        ] {
            let e = read(extra).unwrap_err().to_string();
            assert!(e.contains(needle), "`{needle}` not in: {e}");
        }
    }

    #[test]
    fn specimen_defaults_and_validation() {
        let s: Specimen =
            toml::from_str("radius_m = 0.0375\nthickness_m = 0.00035\npoisson = 0.45").unwrap();
        assert_eq!(s.prebulge_height_m, 0.0);
        assert!(s.validate().is_ok());
        let bad = Specimen { poisson: 0.5, ..s };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("poisson = 0.5")
        );
        let bad = Specimen { radius_m: 0.0, ..s };
        assert!(bad.validate().unwrap_err().to_string().contains("radius_m"));
        let bad = Specimen {
            thickness_m: -1.0,
            ..s
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("thickness_m")
        );
    }
}
