//! The flags of `bulge synth` that say how the photos look: the camera's
//! placement and lens, the light, and the colours of the scene.

/// How the camera sees the scene and how it is lit.
#[derive(Debug, clap::Args)]
pub struct LookFlags {
    /// The camera's elevation above the clamp plane, degrees (default 0, a
    /// level side view; at most 30): the clamp ring is seen as an ellipse
    /// and the silhouette is the union of the dome's latitude circles.
    /// truth.csv's apex_y_px is the pole's projection, clamp_row_px the
    /// ring's centre.
    #[arg(long, default_value_t = 0.0)]
    pub elevation_deg: f64,

    /// A pinhole camera this far from the bubble's axis, m (default: an
    /// orthographic camera), looking down at the clamp ring's centre at
    /// --elevation-deg, its focal length the one that gives the scale there:
    /// the silhouette's top is the grazing ray (truth.csv's apex_y_px), the
    /// ring's top face an ellipse-like conic; the experiment file gets
    /// `[camera] distance_m`.
    #[arg(long)]
    pub camera_distance_m: Option<f64>,

    /// Uneven light: the relative change of the illumination across the
    /// frame (default 0; e.g. 0.3), a tilted plane and a fall-off.
    #[arg(long, default_value_t = 0.0)]
    pub uneven_light: f64,

    /// A specular highlight on the dome of this peak, grey levels (default
    /// 0: none; e.g. 90): a small light above the camera reflected 12
    /// degrees from the pole, nearer the apex as the bubble inflates.
    #[arg(long, default_value_t = 0.0)]
    pub highlight_grey: f64,

    /// Clutter behind the bubble: a dark shelf edge and a cable crossing
    /// the apex's path (placed from the seed).
    #[arg(long)]
    pub clutter: bool,

    /// The camera's tone curve: the scene's light is blurred by the lens,
    /// scaled by the exposure and the uneven light, then encoded by this
    /// curve (`srgb`, the default, as an ordinary camera; `linear`, pixel
    /// values proportional to light; or a gamma such as 2.2). The
    /// experiment file says it in `[camera] response`.
    #[arg(long, default_value = "srgb", value_parser = super::super::parse_response)]
    pub response: bulge::camera::Response,

    /// Grey level of the clamp ring's visible top face (default: 58, a
    /// dull face a little lighter than the ring's side at 38): e.g. 230
    /// for a machined metal ring lit from above, 20 for a face darker than
    /// its side. Drawn as light before the tone curve.
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub ring_face_grey: f64,

    /// Grey level of the bubble at its centre (default: 72, a dark
    /// membrane before a light wall): e.g. 215 with --background-grey 50
    /// for translucent latex lit in front of a dark wall.
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub bubble_grey: f64,

    /// Mean grey level of the background wall (default: 190, light).
    #[arg(long, default_value_t = 0.0, hide_default_value = true)]
    pub background_grey: f64,

    /// Light from one side: the light is multiplied by 1 + S x, with x
    /// going from -1 to 1 across the disc's columns (held beyond it), so
    /// the dome and the background behind it are brighter on one side of
    /// the apex (default 0; e.g. 0.3; negative: lit from the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub side_light: f64,

    /// Defocus: the light is spread over a uniform disc of this radius, px
    /// (the pillbox point-spread function of a defocused lens), after the
    /// Gaussian blur (default 0: in focus).
    #[arg(long, default_value_t = 0.0)]
    pub defocus_px: f64,

    /// Motion blur: the light is spread along a line of this length, px
    /// (the camera or the specimen moving steadily during the exposure)
    /// (default 0: none).
    #[arg(long, default_value_t = 0.0)]
    pub motion_px: f64,

    /// Direction of the motion blur, degrees from the image's x axis
    /// towards its y axis, down (default 0: horizontal).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub motion_deg: f64,

    /// Vignetting: the lens's cos^4 fall-off of the light away from the
    /// picture's centre, given as the share of the light the corners lose
    /// (default 0: none; e.g. 0.3, corners at 70 % of the centre's light).
    #[arg(long, default_value_t = 0.0)]
    pub vignetting: f64,

    /// Radial distortion of the lens, k1 (OpenCV's model; e.g. -0.1 for a
    /// barrel distortion of about 1 % at the photo's edge with the default
    /// focal length): the photos are drawn through it, and experiment.toml
    /// gives the lens in `[camera]`. Off by default (a pinhole camera).
    #[arg(long, allow_hyphen_values = true)]
    pub lens_k1: Option<f64>,

    /// Radial distortion of the lens, k2 (with --lens-k1).
    #[arg(
        long,
        allow_hyphen_values = true,
        default_value_t = 0.0,
        requires = "lens_k1"
    )]
    pub lens_k2: f64,

    /// Focal length of the lens with --lens-k1, px (default: the photo's
    /// width; the principal point is the photo's centre). With
    /// --camera-distance-m the lens is the pinhole camera's: its focal
    /// length and principal point are the camera's (this flag is refused).
    #[arg(long, requires = "lens_k1")]
    pub focal_px: Option<f64>,
}
