//! `bulge synth`: a synthetic experiment with known truth.

use anyhow::anyhow;

use super::Failure;
use bulge::experiment::Specimen;
use bulge::material::{Material, Model};
use bulge::track::synth::{self, Framing, Look, SequenceSpec};

mod timed;
use timed::write_timed;

mod args;
mod checks;
mod look_args;
pub use args::*;
pub use look_args::LookFlags;

pub fn run(args: Args) -> Result<(), Failure> {
    super::output_folder(&args.out_dir, "OUT_DIR")?;
    let plan = bulge::io::OutputPlan::new().inputs(&args.material);
    super::guard(plan.output_as("OUT_DIR", &args.out_dir))?;
    let encoding = checks::check(&args)?;
    let bad = |m: String| Failure::BadInput(anyhow!(m));
    let window = match &args.window_semi_axes_m {
        None => bulge::experiment::Window::Circle,
        Some(v) => {
            if v.len() != 2 {
                return Err(bad(format!(
                    "--window-semi-axes-m {v:?}: give the two semi-axes in m, e.g. 0.0375,0.01875"
                )));
            }
            if args.prebulge_height_m != 0.0 {
                return Err(bad(
                    "--prebulge-height-m is for the disc; an elliptical window is flat".into(),
                ));
            }
            bulge::experiment::Window::Ellipse {
                semi_axes_m: [v[0], v[1]],
            }
        }
    };
    window
        .validate()
        .map_err(|m| bad(format!("--window-semi-axes-m: {m}")))?;
    let specimen = Specimen {
        radius_m: match window {
            bulge::experiment::Window::Ellipse { semi_axes_m } => semi_axes_m[0],
            _ => args.radius_m,
        },
        thickness_m: args.thickness_m,
        poisson: args.poisson,
        prebulge_height_m: args.prebulge_height_m,
    };
    specimen
        .validate()
        .map_err(|m| bad(format!("specimen: {m}")))?;
    let material = match &args.material {
        Some(p) => Material::read(p)?,
        None => Material {
            model: Model::NeoHookean { c1_pa: 0.2e6 },
            poisson: 0.45,
            fit: None,
        },
    };
    let p_max = args.pressure_max_pa;
    let p_min = args.pressure_min_pa.unwrap_or(p_max / args.frames as f64);
    if !(p_max.is_finite() && p_max > 0.0 && p_min.is_finite() && p_min > 0.0 && p_min <= p_max) {
        return Err(bad(format!(
            "pressures {p_min}..{p_max} Pa: need 0 < --pressure-min-pa <= --pressure-max-pa"
        )));
    }
    let n = args.frames;
    let pressures = synth::pressure_steps(p_min, p_max, n);
    let pb = super::progress(n as u64, "solve");
    let frames = synth::bubble_frames(&material, &specimen, &window, &pressures, &|| pb.inc(1))
        .map_err(Failure::of)?;
    pb.finish_and_clear();
    let spec = SequenceSpec {
        width: args.width,
        height: args.height,
        seed: args.seed,
        blur_px: args.blur_px,
        noise_grey: args.noise,
        drift: args.drift,
        encoding,
        specimen,
        framing: Framing {
            metres_per_pixel: args.metres_per_pixel,
            axis_x_px: args.axis_x_px,
            clamp_row_px: args.clamp_row_px,
            random: args.random_framing,
        },
        look: Look {
            elevation_deg: args.look.elevation_deg,
            uneven_light: args.look.uneven_light,
            highlight_grey: args.look.highlight_grey,
            highlight: Default::default(),
            clutter: args.look.clutter,
            response: args.look.response,
            ring_face_grey: args.look.ring_face_grey,
            bubble_grey: args.look.bubble_grey,
            background_grey: args.look.background_grey,
            side_light: args.look.side_light,
            defocus_px: args.look.defocus_px,
            motion_px: args.look.motion_px,
            motion_deg: args.look.motion_deg,
            vignetting: args.look.vignetting,
            camera_distance_m: args.look.camera_distance_m.unwrap_or(0.0),
            lens: args.look.lens_k1.map(|k1| {
                let f = args.look.focal_px.unwrap_or(args.width as f64);
                let (cx, cy) = (
                    (args.width as f64 - 1.0) / 2.0,
                    (args.height as f64 - 1.0) / 2.0,
                );
                bulge::track::lens::Lens {
                    k1,
                    k2: args.look.lens_k2,
                    image_size_px: Some([args.width, args.height]),
                    ..bulge::track::lens::Lens::pinhole(f, f, cx, cy)
                }
            }),
        },
        window,
    };
    let w = synth::write_sequence(&args.out_dir, &spec, &frames).map_err(Failure::of)?;
    let extra = write_timed(&args, &spec, &w, &frames, &pressures)?;
    let hmax = w.truth.iter().map(|t| t.height_m).fold(0.0, f64::max);
    println!(
        "wrote {n} {}x{} {} photos ({:.2} MB) of a {} bubble, {:.0}..{:.0} Pa, apex height up to {:.4e} m ({:.1} px), {:.4e} m/px, + pressure.csv, truth.csv, experiment.toml{extra} -> {}",
        args.width,
        args.height,
        encoding.extension().to_uppercase(),
        w.photo_bytes as f64 / 1e6,
        material.model.name(),
        p_min,
        p_max,
        hmax,
        hmax / w.scene.metres_per_pixel,
        w.scene.metres_per_pixel,
        args.out_dir.display()
    );
    Ok(())
}
