//! The flags of `bulge init` and their help.

use std::path::PathBuf;

/// Flags of `bulge init`.
///
/// Finds, in a folder of photos of a bubble test taken from the side while
/// the bubble grows, everything `bulge track` needs: the clamp plane (its
/// row, to a fraction of a pixel), the bubble's axis, the apex in every
/// photo, the region where it moves, a template around it, the scale from
/// the clamp opening (the silhouette is 2a wide at the clamp plane) and the
/// camera's elevation above the clamp plane (from the clamp's ellipse). It
/// writes a commented experiment file, each value found with its standard
/// deviation, and init.png: the last photo with everything found drawn on
/// it. What it cannot find (no bubble, a bubble cut by the border, the
/// clamp out of the picture, two candidate edges) is refused with exit
/// status 2, naming the key to set by hand.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder of photos, in the order taken (natural order of the names:
    /// img2 before img10), or a video; the bubble must grow from the first
    /// frame to the last.
    pub source: PathBuf,

    /// A video only: use every N-th frame (frames 0, N, 2N, ...; default 1),
    /// written into [photos] `every`.
    #[arg(long, value_name = "N")]
    pub every: Option<usize>,

    /// The experiment file to write (refused if it exists, unless --force).
    #[arg(short, long, default_value = "experiment.toml")]
    pub output: PathBuf,

    /// The specimen's free radius a (the clamp opening's radius), m.
    #[arg(long)]
    pub radius_m: f64,

    /// The specimen's initial thickness t, m.
    #[arg(long)]
    pub thickness_m: f64,

    /// Poisson ratio (default 0.45).
    #[arg(long, default_value_t = 0.45)]
    pub poisson: f64,

    /// The pressure log: columns file,pressure_pa (by photo), or a log by
    /// time (see docs/track.md). Written into [pressure] relative to the
    /// experiment file; without it, [pressure] is left for you to fill in.
    #[arg(long)]
    pub pressure: Option<PathBuf>,

    /// The photos to use in the folder (default: every file with the
    /// folder's most common image extension, e.g. "*.jpg").
    #[arg(long)]
    pub glob: Option<String>,

    /// The scale, m per px, when known (instead of the clamp opening).
    #[arg(long, conflicts_with = "points_px")]
    pub metres_per_pixel: Option<f64>,

    /// Two points in the photos (x1,y1,x2,y2 px) a known distance apart
    /// (--distance-m), for the scale instead of the clamp opening.
    #[arg(
        long,
        value_delimiter = ',',
        num_args = 4,
        requires = "distance_m",
        value_name = "X1,Y1,X2,Y2"
    )]
    pub points_px: Option<Vec<f64>>,

    /// The distance between --points-px, m.
    #[arg(long, requires = "points_px")]
    pub distance_m: Option<f64>,

    /// The camera's elevation above the clamp plane, degrees, when known
    /// (default: found from the clamp's ellipse when its ends are in the
    /// picture, else level).
    #[arg(long)]
    pub elevation_deg: Option<f64>,

    /// The clamp plane's row at the bubble's axis, px from the photo's top,
    /// when init does not find it (a lit floor or a table's edge beside the
    /// ring, a camera raised beyond 5 degrees): init then takes it instead
    /// of searching, the camera as not rolled, and the elevation from
    /// --elevation-deg (level without it). From a raised camera it is the
    /// row of the clamp ring's centre, which is no edge in the photo (nor
    /// halfway between the opening's near and far edges, through
    /// perspective): docs/track.md, "The clamp row given", places it
    /// through the lens from the opening's near edge on the axis.
    #[arg(long, value_name = "ROW")]
    pub clamp_row_px: Option<f64>,

    /// The standard deviation of --clamp-row-px, px: every height shares it
    /// (written into [calibration] clamp_row_std_px).
    #[arg(
        long,
        value_name = "PX",
        default_value_t = 0.0,
        requires = "clamp_row_px"
    )]
    pub clamp_row_std_px: f64,

    /// The horizontal distance from the bubble's axis to the camera's lens,
    /// m, for a pinhole camera at that distance (written into [camera]
    /// distance_m): the clamp ring's centre row and the elevation are fitted
    /// to the ring's far side seen from it, and the scale at the ring's
    /// centre from the opening's tangent points. Without it, a lens given
    /// by --camera gives it: its focal length times the scale found at the
    /// ring's centre. Without either a level camera is taken as
    /// orthographic (the scale then comes out about a^2 / (2 D^2) small),
    /// and a camera raised above the clamp plane is refused unless
    /// --orthographic says it is one.
    #[arg(long, value_name = "M")]
    pub camera_distance_m: Option<f64>,

    /// Take the camera as orthographic (a telecentric lens, or photos drawn
    /// by an orthographic renderer): no distance is found from a focal
    /// length that --camera gives, and a camera raised above the clamp
    /// plane is set up without a distance.
    #[arg(long, conflicts_with = "camera_distance_m")]
    pub orthographic: bool,

    /// The camera's tone curve from light to grey levels: `srgb` (ordinary
    /// 8-bit JPEG or PNG photos), `linear` (raw or linearised photos), or a
    /// gamma such as 2.2. Edges are located in light; the experiment file
    /// keeps it as `[camera] response`.
    #[arg(long, default_value = "srgb", value_parser = super::super::parse_response)]
    pub response: bulge::camera::Response,

    /// The lens, a `[camera]` table written by `bulge calibrate`: the
    /// clamp row, the axis and the scale are measured in the undistorted
    /// image, the camera's distance from the axis follows from its focal
    /// length (unless --camera-distance-m or --orthographic), and the table
    /// is copied into the experiment file.
    #[arg(long)]
    pub camera: Option<PathBuf>,

    /// Where to draw what was found (default: init.png beside the
    /// experiment file).
    #[arg(long)]
    pub png: Option<PathBuf>,

    /// Replace an existing experiment file (never one of the inputs).
    #[arg(long)]
    pub force: bool,
}
