//! Writing a synthetic experiment to disk: the photos (in parallel, each file
//! atomically), `pressure.csv`, `truth.csv` and `experiment.toml`, or a
//! video of the photos with a pressure logger's file on its own clock.

use super::*;

/// Renders and writes a whole synthetic experiment into `out`:
/// `photos/frame_NNN.{png,jpg}`, `pressure.csv`, `truth.csv`,
/// `experiment.toml`. Frames are rendered in parallel; every file is written
/// atomically. Fails when the tallest bubble does not fit in the picture.
pub fn write_sequence(
    out: &Path,
    spec: &SequenceSpec,
    frames: &[SynthFrame],
) -> Result<Written, TrackError> {
    use rayon::prelude::*;
    if frames.is_empty() {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: "no frames to draw: give at least one pressure".into(),
        });
    }
    let scene = spec.scene(frames).map_err(|e| TrackError::Config {
        path: out.to_path_buf(),
        message: e.to_string(),
    })?;
    let hmax = frames
        .iter()
        .map(|f| f.silhouette.height_m())
        .fold(0.0, f64::max);
    if spec.framing.is_default() && hmax > scene.max_height_m() {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: format!(
                "the tallest bubble ({:.4} m) does not fit in a {}x{} px picture framed for the {:.4} m disc (at most {:.4} m): lower the pressure or use a wider image height",
                hmax,
                spec.width,
                spec.height,
                2.0 * spec.specimen.radius_m,
                scene.max_height_m()
            ),
        });
    }
    // A bubble too small to measure is refused rather than drawn: the
    // tracker's template is at least 32 px wide (so the opening must be as
    // wide), and at its best the apex is found to about 0.03 px, so a
    // tallest bubble under 3 px could not give heights to 1 %.
    let (a_px, h_px) = (
        spec.specimen.radius_m / scene.metres_per_pixel,
        hmax / scene.metres_per_pixel,
    );
    if 2.0 * a_px < 32.0 || h_px < 3.0 {
        return Err(TrackError::Config {
            path: out.to_path_buf(),
            message: format!(
                "the opening is {:.1} px wide and the tallest bubble {h_px:.2} px tall at {:.3e} m per px: the tracker needs an opening of at least 32 px and a bubble of at least 3 px; give a finer {} or a higher {}",
                2.0 * a_px,
                scene.metres_per_pixel,
                crate::setting::Setting::MetresPerPixel,
                crate::setting::Setting::PressureMax
            ),
        });
    }
    let n = frames.len();
    let digits = n.to_string().len().max(3);
    let ext = spec.encoding.extension();
    let photos = out.join("photos");
    let write_err = |p: &Path, e: std::io::Error| TrackError::Write {
        path: p.to_path_buf(),
        reason: e.to_string(),
    };
    std::fs::create_dir_all(&photos).map_err(|e| write_err(&photos, e))?;
    let results: Vec<Result<(Truth, usize), TrackError>> = frames
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let img = render_frame(&scene, spec, n, i, f);
            let bytes = super::super::image::encode(&img, spec.encoding)?;
            let file = format!("frame_{:0digits$}.{ext}", i + 1);
            let path = photos.join(&file);
            crate::io::write_atomic(&path, &bytes).map_err(|e| write_err(&path, e))?;
            let [ax, ay] = scene.apex_px(&f.silhouette);
            Ok((
                Truth {
                    file,
                    pressure_pa: f.pressure_pa,
                    height_m: f.silhouette.height_m(),
                    apex_x_px: ax,
                    apex_y_px: ay,
                },
                bytes.len(),
            ))
        })
        .collect();
    let mut truth = Vec::with_capacity(n);
    let mut photo_bytes = 0;
    for r in results {
        let (t, b) = r?;
        truth.push(t);
        photo_bytes += b;
    }

    let mut pcsv = CsvOut::new(&["file", "pressure_pa"]);
    let mut tcsv = CsvOut::new(&["file", "pressure_pa", "height_m", "apex_x_px", "apex_y_px"]);
    for t in &truth {
        pcsv.row(&[t.file.clone(), fmt_num(Some(t.pressure_pa))]);
        tcsv.row(&[
            t.file.clone(),
            fmt_num(Some(t.pressure_pa)),
            fmt_num(Some(t.height_m)),
            fmt_num(Some(t.apex_x_px)),
            fmt_num(Some(t.apex_y_px)),
        ]);
    }
    let p = out.join("pressure.csv");
    pcsv.write(&p).map_err(|e| write_err(&p, e))?;
    let p = out.join("truth.csv");
    tcsv.write(&p).map_err(|e| write_err(&p, e))?;

    // The region and the template where the photos show the apex (through
    // the lens, when there is one).
    let apexes: Vec<[f64; 2]> = truth
        .iter()
        .map(|t| [t.apex_x_px, t.apex_y_px])
        .map(|p| scene.look.lens.map_or(p, |l| l.distort(p)))
        .collect();
    let layout = Layout::around(
        &apexes,
        0,
        template_size(spec.width),
        (spec.width, spec.height),
    );
    let toml = experiment_file(
        spec,
        &scene,
        &layout,
        crate::experiment::PhotosConfig::folder("photos", &format!("*.{ext}")),
        crate::experiment::PressureConfig::file("pressure.csv"),
    )
    .render();
    let p = out.join("experiment.toml");
    crate::io::write_atomic(&p, toml.as_bytes()).map_err(|e| write_err(&p, e))?;
    Ok(Written {
        truth,
        photo_bytes,
        scene,
        layout,
    })
}

/// Writes the photos of a sequence as a video at `fps` frames per second
/// (frame `i` at `i / fps` s), the same pixels as the photos before their
/// encoding: `.avi` as Motion JPEG (OpenCV's own writer, always available)
/// at JPEG quality `quality`, `.mp4` as MPEG-4 part 2 when OpenCV's FFmpeg
/// back-end can write it. Written whole or not at all. Returns its size, bytes.
pub fn write_video(
    path: &Path,
    spec: &SequenceSpec,
    frames: &[SynthFrame],
    fps: u32,
    quality: u8,
) -> Result<u64, TrackError> {
    use opencv::core::Size;
    use opencv::videoio::{self, VideoWriter, VideoWriterTrait, VideoWriterTraitConst};
    use rayon::prelude::*;
    let cv = |e: opencv::Error| TrackError::OpenCv(e.to_string());
    super::super::image::opencv_serial().map_err(cv)?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let (api, fourcc) = match ext.as_str() {
        "avi" => (videoio::CAP_OPENCV_MJPEG, ['M', 'J', 'P', 'G']),
        "mp4" => (videoio::CAP_FFMPEG, ['m', 'p', '4', 'v']),
        _ => {
            return Err(TrackError::Config {
                path: path.to_path_buf(),
                message: "a video file name must end in .avi (Motion JPEG, always written) or .mp4 (MPEG-4, when OpenCV's FFmpeg back-end is present)".into(),
            });
        }
    };
    let scene = spec.scene(frames).map_err(|e| TrackError::Config {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let n = frames.len();
    let write = |tmp: &Path| -> Result<(), TrackError> {
        let name = tmp.to_str().ok_or_else(|| TrackError::Write {
            path: path.to_path_buf(),
            reason: "the path is not valid UTF-8, which OpenCV's video module needs".into(),
        })?;
        let code = VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]).map_err(cv)?;
        let size = Size::new(spec.width as i32, spec.height as i32);
        let mut w = VideoWriter::new_with_backend(name, api, code, f64::from(fps), size, true)
            .map_err(cv)?;
        if !w.is_opened().map_err(cv)? {
            return Err(TrackError::Write {
                path: path.to_path_buf(),
                reason: format!(
                    "OpenCV cannot write a .{ext} video here (no back-end for it); write .avi (Motion JPEG) instead"
                ),
            });
        }
        if api == videoio::CAP_OPENCV_MJPEG {
            w.set(videoio::VIDEOWRITER_PROP_QUALITY, f64::from(quality))
                .map_err(cv)?;
        }
        // Rendered a few at a time in parallel, written in order.
        let chunk = 2 * rayon::current_num_threads().max(1);
        for start in (0..n).step_by(chunk) {
            let imgs: Vec<Gray> = (start..(start + chunk).min(n))
                .into_par_iter()
                .map(|i| render_frame(&scene, spec, n, i, &frames[i]))
                .collect();
            for img in &imgs {
                // Written in colour (grey, R = G = B): the usual 3-channel
                // Motion JPEG that every reader decodes.
                let mut bgr = opencv::core::Mat::default();
                opencv::imgproc::cvt_color_def(
                    &img.as_mat().map_err(cv)?,
                    &mut bgr,
                    opencv::imgproc::COLOR_GRAY2BGR,
                )
                .map_err(cv)?;
                w.write(&bgr).map_err(cv)?;
            }
        }
        w.release().map_err(cv)?;
        Ok(())
    };
    crate::io::write_atomic_with(path, write).map_err(|e| match e {
        crate::io::AtomicWriteError::Write(e) => e,
        crate::io::AtomicWriteError::Io(e) => TrackError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        },
    })?;
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|e| TrackError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
}

/// The pressure of a synthetic test at camera time `t`, s, when photo `k`
/// (pressure `pressures[k]`) is taken at `k * interval_s`: linear between
/// photos plus a quarter of the step times `sin^2(pi t / interval_s)` (zero,
/// with zero slope, at every photo; the pressure still rises), so that the
/// linear interpolation of a log sampled between photos is not exact; its
/// error is at most `h^2 / 8 * max|p''|` for samples `h` apart, with
/// `max|p''| = (step / 4) * 2 pi^2 / interval_s^2`. Beyond the photos the
/// first and last steps continue; never below 0.
pub fn pressure_ramp(pressures: &[f64], interval_s: f64, t: f64) -> f64 {
    let n = pressures.len();
    if n == 1 {
        return pressures[0];
    }
    let u = t / interval_s;
    let k = (u.floor().max(0.0) as usize).min(n - 2);
    let step = pressures[k + 1] - pressures[k];
    let lin = pressures[k] + step * (u - k as f64);
    let wiggle = 0.25 * step * (std::f64::consts::PI * u).sin().powi(2);
    (lin + wiggle).max(0.0)
}

/// `time_s,pressure_pa`: the pressure of [`pressure_ramp`] sampled by a
/// logger at `rate_hz` on its own clock, which reads `offset_s` when the
/// camera's reads 0 (logger time = camera time + offset_s). The logger
/// starts at 0 (earlier when `offset_s` < 0, to cover the first photo) and
/// stops one sample after the last photo.
pub fn pressure_log_csv(pressures: &[f64], interval_s: f64, rate_hz: f64, offset_s: f64) -> CsvOut {
    let last = (pressures.len().max(1) - 1) as f64 * interval_s + offset_s;
    let j0 = ((offset_s * rate_hz).floor() as i64 - 1).min(0);
    let j1 = (last * rate_hz).ceil() as i64 + 1;
    let mut csv = CsvOut::new(&["time_s", "pressure_pa"]);
    for j in j0..=j1 {
        let tau = j as f64 / rate_hz;
        let p = pressure_ramp(pressures, interval_s, tau - offset_s);
        csv.row(&[fmt_num(Some(tau)), fmt_num(Some(p))]);
    }
    csv
}
