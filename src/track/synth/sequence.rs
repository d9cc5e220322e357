//! A synthetic sequence's description: the camera and specimen
//! ([`SequenceSpec`], drawn at random by [`random_camera`]), its frames
//! (axisymmetric solutions or given silhouettes), the truth of each photo,
//! where the bubble sits in the picture ([`Layout`]) and the experiment file
//! that describes it.

use super::*;

/// A synthetic sequence: the camera, the specimen and the degradations.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceSpec {
    /// Image width, px.
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// Seed of the scene placement, texture and noise.
    pub seed: u64,
    /// Gaussian blur, px.
    pub blur_px: f64,
    /// Sensor noise, grey levels.
    pub noise_grey: f64,
    /// Exposure drift: the gain goes linearly from `1 - drift` to `1 + drift`.
    pub drift: f64,
    /// File format.
    pub encoding: Encoding,
    /// The specimen written into `experiment.toml`.
    pub specimen: Specimen,
    /// The window written into `experiment.toml` (a `[window]` table when
    /// it is not the circle).
    pub window: crate::experiment::Window,
    /// Where the specimen is in the picture.
    pub framing: Framing,
    /// What the photos show besides the plain side view.
    pub look: Look,
}

impl SequenceSpec {
    /// A `width` x `height` sequence of the latex disc of the paper
    /// (a = 37.5 mm, t = 0.35 mm, nu = 0.45, flat) with the default
    /// framing, the plain look, the circular window and an exposure drift
    /// of 3 %: the camera of the tests and benchmarks.
    pub fn plain(
        width: usize,
        height: usize,
        seed: u64,
        blur_px: f64,
        noise_grey: f64,
        encoding: Encoding,
    ) -> SequenceSpec {
        SequenceSpec {
            width,
            height,
            seed,
            blur_px,
            noise_grey,
            drift: 0.03,
            encoding,
            specimen: Specimen {
                radius_m: 0.0375,
                thickness_m: 0.00035,
                poisson: 0.45,
                prebulge_height_m: 0.0,
            },
            window: Default::default(),
            framing: Default::default(),
            look: Default::default(),
        }
    }

    /// The scene of this sequence drawing `frames` (see [`Scene::framed`]).
    pub fn scene(&self, frames: &[SynthFrame]) -> Result<Scene, FramingError> {
        let s: Vec<&Silhouette> = frames.iter().map(|f| &f.silhouette).collect();
        let mut scene = Scene::for_frames(
            self.width,
            self.height,
            self.specimen.radius_m,
            self.seed,
            &self.framing,
            self.look,
            &s,
        )?;
        // One camera: a lens on a pinhole camera has the pinhole's focal
        // length and principal point (the ones that give the scene's scale
        // at the ring's centre from its distance).
        if let (Some(p), Some(l)) = (scene.pinhole(), scene.look.lens.as_mut()) {
            (l.fx, l.fy) = (p.focal_px, p.focal_px);
            (l.cx, l.cy) = (p.principal_px[0], p.principal_px[1]);
        }
        Ok(scene)
    }
}

/// A random camera for `seed`: a size of `sizes`, scale 0.05-0.12 mm/px,
/// the disc 35-65 % of the width (its radius follows, the thickness in
/// proportion), blur 0.8-2 px, noise 1-4 grey levels, JPEG quality 80-95,
/// the framing random ([`Framing::random`]) and the look given.
pub fn random_camera(seed: u64, sizes: &[(usize, usize)], look: Look) -> SequenceSpec {
    let mut rng = Rng::new(seed ^ 0x1A17);
    let (w, h) = sizes[(rng.next_u64() % sizes.len() as u64) as usize];
    let mpp = 5e-5 + 7e-5 * rng.uniform();
    let f = 0.35 + 0.3 * rng.uniform();
    let a = f * w as f64 * mpp / 2.0;
    let q = 80 + (rng.next_u64() % 16) as u8;
    SequenceSpec {
        width: w,
        height: h,
        seed,
        blur_px: 0.8 + 1.2 * rng.uniform(),
        noise_grey: 1.0 + 3.0 * rng.uniform(),
        drift: 0.03,
        encoding: Encoding::Jpeg(q),
        specimen: Specimen {
            radius_m: a,
            thickness_m: 0.00035 * a / 0.0375,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        },
        window: Default::default(),
        framing: Framing {
            metres_per_pixel: Some(mpp),
            random: true,
            ..Framing::default()
        },
        look,
    }
}

/// One frame to draw: the pressure and the bubble's profile at it.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthFrame {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Meridian profile (pole first).
    pub silhouette: Silhouette,
}

/// The exact neo-Hookean bubble (C1 = 0.2 MPa, Poisson 0.45) of `specimen`
/// at `n` pressures evenly up to 3.7 kPa (an apex height of about 0.53 a on
/// the default disc and its scaled copies).
pub fn neo_hookean_bubble(
    specimen: &Specimen,
    n: usize,
) -> Result<Vec<SynthFrame>, crate::axisym::AxisymError> {
    let material = crate::material::Material {
        model: crate::material::Model::NeoHookean { c1_pa: 0.2e6 },
        poisson: 0.45,
        fit: None,
    };
    (1..=n)
        .map(|k| {
            let p = 3700.0 * k as f64 / n as f64;
            axisym_frame(&material, specimen, p, p)
        })
        .collect()
}

/// The frame of the exact axisymmetric bubble of `material` on `specimen` at
/// `pressure_pa` (default [`crate::axisym::Options`]), labelled `label_pa`
/// in `pressure.csv` (the pressure itself, or a gauge's reading of it).
pub fn axisym_frame(
    material: &crate::material::Material,
    specimen: &Specimen,
    pressure_pa: f64,
    label_pa: f64,
) -> Result<SynthFrame, crate::axisym::AxisymError> {
    let sol = crate::axisym::solve_pressure(
        material,
        specimen,
        pressure_pa,
        &crate::axisym::Options::default(),
    )?;
    Ok(SynthFrame {
        pressure_pa: label_pa,
        silhouette: Silhouette {
            rho_m: sol.profile.rho_m,
            z_m: sol.profile.z_m,
        },
    })
}

/// The truth of one written frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// File name inside `photos/`.
    pub file: String,
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height above the clamp plane, m.
    pub height_m: f64,
    /// Apex column, px.
    pub apex_x_px: f64,
    /// Apex row, px.
    pub apex_y_px: f64,
}

/// What [`write_sequence`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// The truth per frame.
    pub truth: Vec<Truth>,
    /// Total bytes of the photos.
    pub photo_bytes: usize,
    /// The scene.
    pub scene: Scene,
    /// The region and template written into `experiment.toml`.
    pub layout: Layout,
}

/// Template size for an image width: 10 % by 5 % of the width (even).
pub fn template_size(width: usize) -> (usize, usize) {
    let tw = ((0.1 * width as f64 / 2.0).round() as usize * 2).max(16);
    (tw, (tw / 2).max(8))
}

/// Photo `i` of a sequence of `n` (the same pixels as the file
/// [`write_sequence`] writes, before encoding).
pub fn render_frame(
    scene: &Scene,
    spec: &SequenceSpec,
    n: usize,
    i: usize,
    f: &SynthFrame,
) -> Gray {
    let t = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        0.5
    };
    let d = Degradation {
        blur_px: spec.blur_px,
        noise_grey: spec.noise_grey,
        gain: 1.0 + spec.drift * (2.0 * t - 1.0),
    };
    render(
        scene,
        &f.silhouette,
        &d,
        spec.seed.wrapping_mul(1_000_003).wrapping_add(i as u64 + 1),
    )
}

/// Where tracking looks, as `experiment.toml` says: the region, the template
/// rectangle (around the first frame's apex) and the apex inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// `roi_px`: `[x, y, w, h]`.
    pub roi_px: [i64; 4],
    /// `template_rect_px`: `[x, y, w, h]`.
    pub template_rect_px: [i64; 4],
    /// `apex_in_template_px`.
    pub apex_in_template_px: [f64; 2],
}

impl Layout {
    /// Sets `[photos]`'s region, template and reference frame to this
    /// layout's.
    pub fn apply(&self, photos: &mut crate::experiment::PhotosConfig, reference_frame: usize) {
        let px = |v: [i64; 4]| v.map(|x| i32::try_from(x).unwrap_or(i32::MAX));
        photos.roi_px = px(self.roi_px);
        photos.template_rect_px = Some(px(self.template_rect_px));
        photos.reference_frame = reference_frame;
        photos.apex_in_template_px = Some(self.apex_in_template_px);
    }

    /// The template (`size` = width, height px) centred on the apex of
    /// photo `reference` and a region three template widths wide covering
    /// every apex with a template's height above and below, inside a photo
    /// of `frame` = (width, height) px.
    pub fn around(
        apexes: &[[f64; 2]],
        reference: usize,
        size: (usize, usize),
        frame: (usize, usize),
    ) -> Layout {
        let (tw, th) = size;
        let [ax0, ay0] = apexes[reference];
        let tx = (ax0 - tw as f64 / 2.0).round() as i64;
        let ty = (ay0 - th as f64 / 2.0).round() as i64;
        let ymin = apexes.iter().map(|a| a[1]).fold(f64::INFINITY, f64::min);
        let ymax = apexes
            .iter()
            .map(|a| a[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let rx = (ax0 - 1.5 * tw as f64).round().max(0.0) as i64;
        let ry = (ymin - th as f64).floor().max(0.0) as i64;
        let rw = ((3 * tw) as i64).min(frame.0 as i64 - rx);
        let rh = ((ymax + th as f64).ceil() as i64 - ry).min(frame.1 as i64 - ry);
        Layout {
            roi_px: [rx, ry, rw, rh],
            template_rect_px: [tx, ty, tw as i64, th as i64],
            apex_in_template_px: [ax0 - tx as f64, ay0 - ty as f64],
        }
    }
}

/// The experiment file of a synthetic sequence: `photos` says where the
/// frames are (its region and template are set here, from `layout`),
/// `pressure` where the pressures are.
pub fn experiment_file(
    spec: &SequenceSpec,
    scene: &Scene,
    layout: &Layout,
    mut photos: crate::experiment::PhotosConfig,
    pressure: crate::experiment::PressureConfig,
) -> crate::experiment::Commented {
    use crate::experiment::{CalibrationConfig, Commented, Draft, Place, SpecimenTable};
    layout.apply(&mut photos, 0);
    let mut camera = scene
        .look
        .lens
        .map_or_else(Default::default, |l| l.to_config(None));
    camera.response = Some(spec.look.response);
    let elevated = spec.look.elevation_deg != 0.0;
    if spec.look.camera_distance_m > 0.0 {
        camera.distance_m = Some(spec.look.camera_distance_m);
    }
    let mut draft = Draft::new(SpecimenTable::of(&spec.specimen));
    draft.photos = Some(photos);
    draft.camera = Some(camera);
    draft.calibration = Some(CalibrationConfig {
        metres_per_pixel: Some(scene.metres_per_pixel),
        clamp_row_px: Some(scene.clamp_row_px),
        elevation_deg: elevated.then_some(spec.look.elevation_deg),
        ..CalibrationConfig::default()
    });
    draft.pressure = Some(pressure);
    draft.window = spec.window;
    let mut file = Commented::new(draft);
    file.note(
        Place::Head,
        "A synthetic experiment written by `bulge synth` (truth in truth.csv).\n\
         Image coordinates: the centre of the top-left pixel is (0, 0), y down.",
    );
    if elevated {
        file.note(
            Place::Key("calibration", "elevation_deg"),
            format!(
                "The camera is {:?} degrees above the clamp plane: clamp_row_px is the row of the\n\
                 clamp ring's centre, and elevation_deg corrects the heights for it.",
                spec.look.elevation_deg
            ),
        );
    }
    file.note(
        Place::Key("camera", "focal_px"),
        "the lens the photos were drawn through (as `bulge calibrate` writes it)",
    )
    .note(
        Place::Key("camera", "distance_m"),
        "a pinhole camera this far from the axis, m (elevation_deg: the angle it looks down at the ring's centre)",
    );
    file
}
