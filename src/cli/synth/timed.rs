//! The outputs joined by time: the pressure log of --log-rate-hz and the video
//! of --video, each with its experiment file.

use super::super::Failure;
use anyhow::anyhow;
use bulge::experiment::{PhotosConfig, Place, PressureConfig};
use bulge::track::synth::{self, SequenceSpec, SynthFrame};

use super::*;

/// The outputs of --log-rate-hz and --video: pressure_log.csv,
/// experiment_log.toml, the video and experiment_video.toml. Returns their
/// part of the summary line (empty without those flags).
pub(super) fn write_timed(
    args: &Args,
    spec: &SequenceSpec,
    w: &synth::Written,
    frames: &[SynthFrame],
    pressures: &[f64],
) -> Result<String, Failure> {
    let Some(rate) = args.log_rate_hz else {
        return Ok(String::new());
    };
    let failed = Failure::of::<bulge::track::TrackError>;
    let write = |name: &str, bytes: &[u8]| -> Result<(), Failure> {
        let p = args.out_dir.join(name);
        bulge::io::write_atomic(&p, bytes)
            .map_err(|e| Failure::Failed(anyhow!("cannot write {}: {e}", p.display())))
    };
    let interval = 1.0 / f64::from(args.fps);
    let offset = args.log_offset_s.unwrap_or(0.0);
    let log = synth::pressure_log_csv(pressures, interval, rate, offset);
    let bytes = log.into_bytes();
    let rows = bytes.iter().filter(|&&b| b == b'\n').count() - 1;
    write("pressure_log.csv", &bytes)?;
    let pressure = PressureConfig {
        offset_s: Some(offset),
        ..PressureConfig::file("pressure_log.csv")
    };
    let with_log = |photos: PhotosConfig| {
        let mut file = synth::experiment_file(spec, &w.scene, &w.layout, photos, pressure.clone());
        file.note(Place::Key("pressure", "csv"), "columns time_s,pressure_pa")
            .note(
                Place::Key("pressure", "offset_s"),
                "logger time = frame time + offset_s",
            );
        file.render()
    };
    let ext = spec.encoding.extension();
    let mut photos = PhotosConfig::folder("photos", &format!("*.{ext}"));
    photos.interval_s = Some(interval);
    let toml = with_log(photos);
    write("experiment_log.toml", toml.as_bytes())?;
    let mut extra = format!(
        ", pressure_log.csv ({rows} rows at {rate} Hz, logger time = camera time + {offset} s), experiment_log.toml"
    );
    if let Some(v) = &args.video {
        let quality = args.jpeg_quality.unwrap_or(95);
        let bytes = synth::write_video(&args.out_dir.join(v), spec, frames, args.fps, quality)
            .map_err(failed)?;
        let name = v.to_string_lossy();
        let toml = with_log(PhotosConfig::video(v, Some(1)));
        write("experiment_video.toml", toml.as_bytes())?;
        extra += &format!(
            ", {name} ({:.2} MB, {} frames at {} frames/s), experiment_video.toml",
            bytes as f64 / 1e6,
            frames.len(),
            args.fps
        );
    }
    Ok(extra)
}
