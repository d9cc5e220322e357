//! The checks of `bulge synth`'s flags, each refused with the flag, the
//! value and what to give instead, before anything is drawn.

use anyhow::anyhow;

use super::super::Failure;
use super::Args;
use bulge::track::image::Encoding;

/// Checks the flags that need no solve; the photos' encoding.
pub(super) fn check(args: &Args) -> Result<Encoding, Failure> {
    let bad = |m: String| Failure::BadInput(anyhow!(m));
    if args.frames == 0 {
        return Err(bad("--frames 0: give at least one photo".into()));
    }
    if args.width < 64 || args.height < 48 {
        return Err(bad(format!(
            "--width {} --height {}: the picture must be at least 64x48 px",
            args.width, args.height
        )));
    }
    // drawn in double precision with a blurred copy and the encoded image
    let bytes = (args.width as f64) * (args.height as f64) * 25.0;
    if bytes > args.max_memory_gb * 1e9 {
        return Err(bad(format!(
            "--width {} --height {}: drawing one photo takes about {:.1} GB, above --max-memory-gb {}; make it smaller or raise the limit",
            args.width,
            args.height,
            bytes / 1e9,
            args.max_memory_gb
        )));
    }
    if args.frames > 100_000 {
        return Err(bad(format!(
            "--frames {}: at most 100000 photos (a test is a few to a few hundred)",
            args.frames
        )));
    }
    let blur_cap = 0.1 * args.width.min(args.height) as f64;
    if args.blur_px > blur_cap {
        return Err(bad(format!(
            "--blur-px {}: a blur wider than a tenth of the picture ({blur_cap} px) erases the bubble's edge and its kernel grows with it; use a few px",
            args.blur_px
        )));
    }
    for (name, v) in [
        ("--blur-px", args.blur_px),
        ("--noise", args.noise),
        ("--drift", args.drift),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(bad(format!("{name} {v} must be zero or positive")));
        }
    }
    if let Some(d) = args.look.camera_distance_m
        && !(d.is_finite() && d > 2.0 * args.radius_m)
    {
        return Err(bad(format!(
            "--camera-distance-m {d}: give the distance from the bubble's axis to the camera, m, more than the opening's diameter {}",
            2.0 * args.radius_m
        )));
    }
    if let (Some(d), Some(f)) = (args.look.camera_distance_m, args.look.focal_px) {
        return Err(bad(format!(
            "--focal-px {f} with --camera-distance-m {d}: a pinhole camera's focal length follows from its distance and the scale at the ring's centre (the lens gets that focal length); leave out --focal-px, or set the scale with --metres-per-pixel"
        )));
    }
    if !(args.look.elevation_deg.is_finite() && (0.0..=30.0).contains(&args.look.elevation_deg)) {
        return Err(bad(format!(
            "--elevation-deg {}: give the camera's elevation above the clamp plane, 0 to 30 degrees",
            args.look.elevation_deg
        )));
    }
    if !(args.look.uneven_light.is_finite() && (0.0..=0.8).contains(&args.look.uneven_light)) {
        return Err(bad(format!(
            "--uneven-light {}: give a relative change of the light from 0 to 0.8",
            args.look.uneven_light
        )));
    }
    if !(args.look.highlight_grey.is_finite() && (0.0..=255.0).contains(&args.look.highlight_grey))
    {
        return Err(bad(format!(
            "--highlight-grey {}: give the highlight's peak, 0 to 255 grey levels",
            args.look.highlight_grey
        )));
    }
    for (name, v, what) in [
        (
            "--ring-face-grey",
            args.look.ring_face_grey,
            "the ring face's grey level",
        ),
        (
            "--bubble-grey",
            args.look.bubble_grey,
            "the bubble's grey level",
        ),
        (
            "--background-grey",
            args.look.background_grey,
            "the background's grey level",
        ),
    ] {
        if !(v.is_finite() && (0.0..=255.0).contains(&v)) {
            return Err(bad(format!(
                "{name} {v}: give {what}, 1 to 255 (0 keeps the default)"
            )));
        }
    }
    if !(args.look.side_light.is_finite() && args.look.side_light.abs() <= 0.9) {
        return Err(bad(format!(
            "--side-light {}: give the relative change of the light across the disc, -0.9 to 0.9",
            args.look.side_light
        )));
    }
    for (name, v) in [
        ("--defocus-px", args.look.defocus_px),
        ("--motion-px", args.look.motion_px),
    ] {
        if !(v.is_finite() && v >= 0.0 && v <= blur_cap) {
            return Err(bad(format!(
                "{name} {v}: give a spread of 0 to a tenth of the picture ({blur_cap} px); a few px is a strong blur"
            )));
        }
    }
    if !args.look.motion_deg.is_finite() {
        return Err(bad(format!(
            "--motion-deg {}: give the motion's direction in degrees",
            args.look.motion_deg
        )));
    }
    if !(args.look.vignetting.is_finite() && (0.0..=0.9).contains(&args.look.vignetting)) {
        return Err(bad(format!(
            "--vignetting {}: give the share of the light the corners lose, 0 to 0.9",
            args.look.vignetting
        )));
    }
    if let Some(m) = args.metres_per_pixel
        && !(m.is_finite() && m > 0.0)
    {
        return Err(bad(format!(
            "--metres-per-pixel {m}: give a positive scale, m per px (e.g. 1e-4)"
        )));
    }
    for (name, v) in [
        ("--axis-x-px", args.axis_x_px),
        ("--clamp-row-px", args.clamp_row_px),
    ] {
        if let Some(v) = v
            && !v.is_finite()
        {
            return Err(bad(format!("{name} {v} must be a finite pixel position")));
        }
    }
    if args.drift >= 1.0 {
        return Err(bad(format!(
            "--drift {} must be below 1 (a relative gain change)",
            args.drift
        )));
    }
    if args.fps == 0 || args.fps > 1000 {
        return Err(bad(format!(
            "--fps {}: give 1 to 1000 photos per second",
            args.fps
        )));
    }
    if let Some(r) = args.log_rate_hz
        && !(r.is_finite() && r > 0.0 && r <= 1e4)
    {
        return Err(bad(format!(
            "--log-rate-hz {r}: give a sampling rate in Hz above 0 and at most 10000"
        )));
    }
    if let Some(o) = args.log_offset_s {
        if !o.is_finite() {
            return Err(bad(format!(
                "--log-offset-s {o} must be a finite time in seconds"
            )));
        }
        if args.log_rate_hz.is_none() {
            return Err(bad(
                "--log-offset-s is the clock offset of the pressure log: give --log-rate-hz too"
                    .into(),
            ));
        }
    }
    if let Some(v) = &args.video {
        if args.log_rate_hz.is_none() {
            return Err(bad(format!(
                "--video {}: a video's frames are joined to the pressures by time; give --log-rate-hz (e.g. 7) for the pressure log",
                v.display()
            )));
        }
        let plain = v.file_name().is_some_and(|n| n == v.as_os_str());
        let ext = v
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !plain || !matches!(ext.as_deref(), Some("avi" | "mp4")) {
            return Err(bad(format!(
                "--video {}: give a file name (no folder; it is written in OUT_DIR) ending in .avi (Motion JPEG) or .mp4",
                v.display()
            )));
        }
    }
    Ok(match args.jpeg_quality {
        None => Encoding::Png,
        Some(q) if (1..=100).contains(&q) => Encoding::Jpeg(q),
        Some(q) => return Err(bad(format!("--jpeg-quality {q} must be in 1..=100"))),
    })
}
