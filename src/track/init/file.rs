//! The experiment file `bulge init` writes: each found value with its
//! standard deviation, commented.

use super::*;

/// Where the experiment file written by `bulge init` points.
#[derive(Debug, Clone, PartialEq)]
pub struct Sources {
    /// The photo folder, as the experiment file will name it (relative to
    /// it), or with `video` the video file.
    pub dir: String,
    /// The frames are a video's, every N-th (`dir` names the video).
    pub video_every: Option<usize>,
    /// The glob of the photos.
    pub glob: String,
    /// The number of photos.
    pub count: usize,
    /// The pressure CSV, relative to the experiment file.
    pub pressure_csv: Option<String>,
    /// Two points and their distance, when the scale is given that way.
    pub points: Option<([[f64; 2]; 2], f64)>,
}

/// `x` rounded to `decimals` decimals (written as its shortest form).
fn decimals(x: f64, decimals: i32) -> f64 {
    let k = 10f64.powi(decimals);
    (x * k).round() / k
}

/// `x` rounded to `digits` significant digits.
fn significant(x: f64, digits: usize) -> f64 {
    format!("{:.*e}", digits.saturating_sub(1), x)
        .parse()
        .unwrap_or(x)
}

/// The elevation above which a camera with no distance is not read as
/// orthographic, degrees. From a pinhole raised by `e` the ring's centre
/// row read orthographically is off by about `e` pixels per degree at
/// 0.45 m and 1280x960 (3 px at 3 degrees); at half a degree that is about
/// the level camera's own orthographic error (the grazing ray's 0.27 px at
/// the apex), which is only noted; above it the raised camera's error
/// dominates and grows with the elevation.
pub const RAISED_DEG: f64 = 0.5;

/// The largest elevation init's search of the clamp ring is measured on,
/// degrees: the camera grid's and the init sweep's highest cameras
/// (docs/track.md). Not a limit: a set-up found from higher (by 2 of the
/// elevation's deviations) is noted.
pub const MEASURED_ELEVATION_DEG: f64 = 5.0;

impl Found {
    /// Why this set-up cannot be read as an orthographic camera's: the
    /// camera looks down on the clamp plane from more than [`RAISED_DEG`]
    /// and neither its distance nor a lens that gives it is known. `None`
    /// when the camera is level or its distance is known. A front end
    /// refuses the set-up with this sentence unless the user says the lens
    /// is telecentric.
    pub fn raised_without_distance(&self) -> Option<String> {
        let e = self.elevation_deg?;
        (self.camera_distance_m.is_none() && e.value > RAISED_DEG).then(|| {
            format!(
                "the camera looks down on the clamp plane from {:.2} +- {:.2} degrees and its distance is not known: read as orthographic, a camera D from the bubble's axis puts the ring's centre row a few pixels off (3 px at 0.45 m and 3 degrees, 1280x960), and the heights off by up to a few per cent (+2.5 % on the first photo at 0.3 m and 3 degrees)",
                e.value, e.std
            )
        })
    }

    /// The text of a commented experiment file: the specimen as given, the
    /// set-up as found, each found value with its standard deviation.
    pub fn experiment_toml(&self, specimen: &crate::experiment::Specimen, src: &Sources) -> String {
        self.experiment_file(specimen, src).render()
    }

    /// The experiment file's tables and their comments.
    pub fn experiment_file(
        &self,
        specimen: &crate::experiment::Specimen,
        src: &Sources,
    ) -> crate::experiment::Commented {
        use crate::experiment::{
            CalibrationConfig, CameraConfig, Commented, Draft, PhotosConfig, Place, PressureConfig,
            SpecimenTable,
        };
        let l = &self.layout;
        let mut photos = match src.video_every {
            None => PhotosConfig::folder(&src.dir, &src.glob),
            Some(k) => PhotosConfig::video(&src.dir, (k != 1).then_some(k)),
        };
        l.apply(&mut photos, self.reference_frame);
        photos.apex_in_template_px = photos
            .apex_in_template_px
            .map(|a| a.map(|v| decimals(v, 3)));
        let mut camera = self
            .lens
            .as_ref()
            .map_or_else(CameraConfig::default, |lens| lens.to_config(None));
        camera.response = Some(self.response);
        camera.distance_m = self.camera_distance_m;
        let mut calibration = CalibrationConfig {
            clamp_row_px: Some(decimals(self.clamp_row_px.value, 4)),
            clamp_row_std_px: Some(significant(self.clamp_row_px.std.max(1e-4), 3)),
            ..CalibrationConfig::default()
        };
        let mut draft = Draft::new(SpecimenTable::of(specimen));
        let mut notes: Vec<(Place, String)> = vec![(
            Place::Head,
            format!(
                "Written by `bulge init` from {} photos ({}x{} px). Check init.png: every value below\n\
                 found in the photos is drawn there. A value followed by `_std` is its standard deviation.\n\
                 Image coordinates: the centre of the top-left pixel is (0, 0), y down.",
                src.count, self.width, self.height
            ),
        )];
        let (ymin, ymax) = self
            .apexes_px
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
                (lo.min(a[1]), hi.max(a[1]))
            });
        notes.push((
            Place::Key("photos", "roi_px"),
            format!(
                "where the apex moves: {} apexes found on the axis (column {:.2} +- {:.2}), rows {ymin:.0} to {ymax:.0}, with a template's margin",
                self.apexes_px.len(),
                self.axis_x_px.value,
                self.axis_x_px.std,
            ),
        ));
        notes.push((
            Place::Key("photos", "template_rect_px"),
            "cut from reference_frame (the first photo whose template stays clear of the clamp, or the\n\
             second where no edge lies at the first's top as the photos' difference places it), around its apex"
                .into(),
        ));
        notes.push((
            Place::Key("camera", "response"),
            "the tone curve from light to grey levels: edges are located in light\n\
             (\"srgb\" for ordinary 8-bit photos, \"linear\" for raw ones, or a gamma)"
                .into(),
        ));
        if self.lens.is_some() {
            notes.push((
                Place::Key("camera", "focal_px"),
                "the lens (bulge calibrate): the tracker undistorts the apex, and clamp_row_px and the\n\
                 scale below are in the undistorted image's pixels (roi_px and the template in the photo's)"
                    .into(),
            ));
        }
        notes.push((
            Place::Key("camera", "distance_m"),
            format!(
                "a pinhole camera this far from the bubble's axis, m ({}): clamp_row_px is the image of\n\
                 the ring's centre and the scale is the one at it, both found through this camera",
                if self.camera_distance_from_focal {
                    "found: the lens's focal length times the scale at the ring's centre"
                } else {
                    "given"
                }
            ),
        ));
        match (&src.points, self.scale_from) {
            (Some((p, d)), _) => {
                calibration.points_px = Some(*p);
                calibration.distance_m = Some(*d);
                notes.push((
                    Place::Key("calibration", "points_px"),
                    "the scale, given: two points and their distance".into(),
                ));
            }
            (None, ScaleSource::Given) => {
                calibration.metres_per_pixel = Some(self.metres_per_pixel.value);
                notes.push((
                    Place::Key("calibration", "metres_per_pixel"),
                    "the scale, given".into(),
                ));
            }
            (None, ScaleSource::ClampOpening) => {
                let a = self.radius_px.expect("measured radius");
                calibration.metres_per_pixel = Some(significant(self.metres_per_pixel.value, 7));
                calibration.metres_per_pixel_std = Some(significant(self.metres_per_pixel.std, 3));
                notes.push((
                    Place::Key("calibration", "metres_per_pixel"),
                    format!(
                        "the scale from the clamp opening: the silhouette is 2a = {:.3} +- {:.3} px wide at the clamp plane\n\
                         ({} points on its sides); radius_m / a. It shares the radius's own error (radius_std_m).",
                        2.0 * a.value,
                        2.0 * a.std,
                        self.side_points_px.len(),
                    ),
                ));
                calibration.scale_per_clamp_row = Some(significant(self.scale_per_clamp_row, 3));
                notes.push((
                    Place::Key("calibration", "scale_per_clamp_row"),
                    format!(
                        "the opening is read at the clamp row: a row 1 px lower changes the scale by {:+.4} %,\n\
                         one error with the row's (metres_per_pixel_std is the scale's error besides it)",
                        100.0 * self.scale_per_clamp_row
                    ),
                ));
            }
        }
        let face = match self.clamp_half_width_px {
            Some(a) => format!(", the clamp {:.1} px wide", 2.0 * a),
            None => String::new(),
        };
        let (clamp_note, roll_note) = if self.clamp_row_given {
            (
                "the clamp plane's row at the bubble's axis, given (from a raised camera the ring's centre)".to_string(),
                "the camera's roll about its view axis: taken as none (the clamp row was given, not found)".to_string(),
            )
        } else {
            (
                format!(
                    "the clamp plane: the clamp's top edge beside the bubble, {} columns{face}",
                    self.clamp_points_px.len(),
                ),
                format!(
                    "the camera's roll about its view axis: the clamp's edge slopes by {:.2} +- {:.2} degrees (at most {MAX_ROLL_DEG} is taken)",
                    self.roll_deg.value, self.roll_deg.std
                ),
            )
        };
        notes.push((Place::Key("calibration", "clamp_row_px"), clamp_note));
        let mut after = vec![roll_note];
        match self.elevation_deg {
            Some(e) if e.std == 0.0 => {
                calibration.elevation_deg = Some(e.value);
                notes.push((
                    Place::Key("calibration", "elevation_deg"),
                    "the camera's elevation above the clamp plane, given".into(),
                ));
            }
            Some(e) if e.value.abs() > 2.0 * e.std && e.value > 0.05 => {
                calibration.elevation_deg = Some(decimals(e.value, 3));
                notes.push((
                    Place::Key("calibration", "elevation_deg"),
                    format!(
                        "the camera is {:.2} +- {:.2} degrees above the clamp plane (from the clamp's ellipse): clamp_row_px is\n\
                         the row of the clamp ring's centre, and the heights are corrected for the elevation",
                        e.value, e.std
                    ),
                ));
            }
            Some(e) => after.push(format!(
                "the camera is level with the clamp plane: elevation {:.2} +- {:.2} degrees from the clamp's ellipse",
                e.value, e.std
            )),
            None if self.clamp_row_given => {
                after.push("the camera is taken as level: no elevation was given".into())
            }
            None => after.push(
                "the camera is taken as level: the clamp's edge is straight and its ends are outside the picture".into(),
            ),
        }
        match &src.pressure_csv {
            Some(p) => {
                draft.pressure = Some(PressureConfig {
                    csv: p.into(),
                    offset_s: None,
                    std_pa: None,
                    relative_std: None,
                })
            }
            None => notes.push((
                Place::Tail,
                "No pressure log was given: add one (columns file,pressure_pa, or a log by time)\n\
                 [pressure]\ncsv = \"pressure.csv\""
                    .into(),
            )),
        }
        draft.photos = Some(photos);
        draft.camera = Some(camera);
        draft.calibration = Some(calibration);
        let mut file = Commented::new(draft);
        for (place, text) in notes {
            if !text.is_empty() {
                file.note(place, text);
            }
        }
        // The roll, and a level camera, set no key: said over the table.
        file.note(Place::Table("calibration"), after.join("\n"));
        file
    }
}
