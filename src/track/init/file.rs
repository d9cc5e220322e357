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

/// A TOML string literal.
pub(super) fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

impl Found {
    /// The text of a commented experiment file: the specimen as given, the
    /// set-up as found, each found value with its standard deviation.
    pub fn experiment_toml(&self, specimen: &crate::experiment::Specimen, src: &Sources) -> String {
        let mut t = String::new();
        let l = &self.layout;
        t.push_str(&format!(
            "# Written by `bulge init` from {} photos ({}x{} px). Check init.png: every value below\n\
             # found in the photos is drawn there. A value followed by `_std` is its standard deviation.\n\
             # Image coordinates: the centre of the top-left pixel is (0, 0), y down.\n\n",
            src.count, self.width, self.height
        ));
        t.push_str(&format!(
            "[specimen]\nradius_m = {:?}\nthickness_m = {:?}\npoisson = {:?}\nprebulge_height_m = {:?}\n\n",
            specimen.radius_m, specimen.thickness_m, specimen.poisson, specimen.prebulge_height_m
        ));
        let [rx, ry, rw, rh] = l.roi_px;
        let [tx, ty, tw, th] = l.template_rect_px;
        let ymin = self
            .apexes_px
            .iter()
            .map(|a| a[1])
            .fold(f64::INFINITY, f64::min);
        let ymax = self
            .apexes_px
            .iter()
            .map(|a| a[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let source = match src.video_every {
            None => format!("dir = {}\nglob = {}\n", quoted(&src.dir), quoted(&src.glob)),
            Some(1) => format!("video = {}\n", quoted(&src.dir)),
            Some(k) => format!("video = {}\nevery = {k}\n", quoted(&src.dir)),
        };
        t.push_str(&format!(
            "[photos]\n{source}\
             # where the apex moves: {} apexes found on the axis (column {:.2} +- {:.2}), rows {:.0} to {:.0}, with a template's margin\n\
             roi_px = [{rx}, {ry}, {rw}, {rh}]\n\
             # cut from reference_frame (the first photo whose template stays clear of the clamp), around its apex\n\
             template_rect_px = [{tx}, {ty}, {tw}, {th}]\nreference_frame = {}\n\
             apex_in_template_px = [{:.3}, {:.3}]\n\n",
            self.apexes_px.len(),
            self.axis_x_px.value,
            self.axis_x_px.std,
            ymin,
            ymax,
            self.reference_frame,
            l.apex_in_template_px[0],
            l.apex_in_template_px[1],
        ));
        t.push_str(&format!(
            "[camera]\n# the tone curve from light to grey levels: edges are located in light\n\
             # (\"srgb\" for ordinary 8-bit photos, \"linear\" for raw ones, or a gamma)\n\
             response = {}\n{}{}\n",
            toml::Value::try_from(self.response).map_or_else(|_| quoted("srgb"), |v| v.to_string()),
            self.camera_distance_m.map_or_else(String::new, |d| format!(
                "# a pinhole camera this far from the bubble's axis, m ({}): clamp_row_px is the image of\n\
                 # the ring's centre and the scale is the one at it, both found through this camera\n\
                 distance_m = {d:?}\n",
                if self.camera_distance_from_focal {
                    "found: the lens's focal length times the scale at the ring's centre"
                } else {
                    "given"
                }
            )),
            super::super::lens::lens_keys_toml(self.lens.as_ref()),
        ));
        t.push_str("[calibration]\n");
        match (&src.points, self.scale_from) {
            (Some((p, d)), _) => t.push_str(&format!(
                "# the scale, given: two points and their distance\npoints_px = [[{:?}, {:?}], [{:?}, {:?}]]\ndistance_m = {d:?}\n",
                p[0][0], p[0][1], p[1][0], p[1][1]
            )),
            (None, ScaleSource::Given) => t.push_str(&format!(
                "# the scale, given\nmetres_per_pixel = {:?}\n",
                self.metres_per_pixel.value
            )),
            (None, ScaleSource::ClampOpening) => {
                let a = self.radius_px.expect("measured radius");
                t.push_str(&format!(
                    "# the scale from the clamp opening: the silhouette is 2a = {:.3} +- {:.3} px wide at the clamp plane\n\
                     # ({} points on its sides); radius_m / a. It shares the radius's own error (radius_std_m).\n\
                     metres_per_pixel = {:.6e}\nmetres_per_pixel_std = {:.2e}\n",
                    2.0 * a.value,
                    2.0 * a.std,
                    self.side_points_px.len(),
                    self.metres_per_pixel.value,
                    self.metres_per_pixel.std
                ));
            }
        }
        let face = match self.clamp_half_width_px {
            Some(a) => format!(", the clamp {:.1} px wide", 2.0 * a),
            None => String::new(),
        };
        t.push_str(&format!(
            "# the clamp plane: the clamp's top edge beside the bubble, {} columns{face}\n\
             clamp_row_px = {:.4}\nclamp_row_std_px = {:.2e}\n",
            self.clamp_points_px.len(),
            self.clamp_row_px.value,
            self.clamp_row_px.std.max(1e-4),
        ));
        t.push_str(&format!(
            "# the camera's roll about its view axis: the clamp's edge slopes by {:.2} +- {:.2} degrees (at most {MAX_ROLL_DEG} is taken)\n",
            self.roll_deg.value, self.roll_deg.std
        ));
        match self.elevation_deg {
            Some(e) if e.std == 0.0 => t.push_str(&format!(
                "# the camera's elevation above the clamp plane, given\nelevation_deg = {:?}\n",
                e.value
            )),
            Some(e) if e.value.abs() > 2.0 * e.std && e.value > 0.05 => t.push_str(&format!(
                "# the camera is {:.2} +- {:.2} degrees above the clamp plane (from the clamp's ellipse): clamp_row_px is\n\
                 # the row of the clamp ring's centre, and the heights are corrected for the elevation\n\
                 elevation_deg = {:.3}\n",
                e.value, e.std, e.value
            )),
            Some(e) => t.push_str(&format!(
                "# the camera is level with the clamp plane: elevation {:.2} +- {:.2} degrees from the clamp's ellipse\n",
                e.value, e.std
            )),
            None => t.push_str(
                "# the camera is taken as level: the clamp's edge is straight and its ends are outside the picture\n",
            ),
        }
        t.push('\n');
        match &src.pressure_csv {
            Some(p) => t.push_str(&format!("[pressure]\ncsv = {}\n", quoted(p))),
            None => t.push_str(
                "# No pressure log was given: add one (columns file,pressure_pa, or a log by time)\n# [pressure]\n# csv = \"pressure.csv\"\n",
            ),
        }
        t
    }
}
