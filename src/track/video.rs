//! Video input (OpenCV's video module): the frames of a video file as a
//! sequence of photos named `frame NNNNNN` (the 0-based frame index), with
//! their times from the container.
//!
//! A video is read twice, each time from its start: once by [`probe`] (every
//! frame grabbed, not converted, for the count and the times) and once by
//! the tracker (the chosen frames converted to grayscale and cropped).
//! Frames are always read in order: seeking is exact in some back-ends and
//! not in others.

use std::path::{Path, PathBuf};

use opencv::core::{Mat, MatTraitConst};
use opencv::imgproc;
use opencv::videoio::{self, VideoCapture, VideoCaptureTrait, VideoCaptureTraitConst};

use super::TrackError;
use super::image::{Decoded, crop_lenient, crop_mat};
use crate::io::fmt_short;

/// The name of video frame `index` in messages and in `heights.csv`.
pub fn frame_name(index: usize) -> String {
    format!("frame {index:06}")
}

/// What [`probe`] found in a video.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoInfo {
    /// The video file.
    pub path: PathBuf,
    /// Number of frames that could be read.
    pub frames: usize,
    /// Frame rate the container states, frames/s (`None`: none stated).
    pub fps: Option<f64>,
    /// Time of every frame, s: the container's time stamps
    /// (`CAP_PROP_POS_MSEC`) when they increase strictly, else frame index /
    /// frame rate; `None` when neither is known.
    pub times_s: Option<Vec<f64>>,
    /// The OpenCV back-end that read it (e.g. `FFMPEG`).
    pub backend: String,
}

fn cv(e: opencv::Error) -> TrackError {
    TrackError::OpenCv(e.to_string())
}

/// Opens a video for reading, or says why it cannot be read.
fn open(path: &Path) -> Result<VideoCapture, TrackError> {
    let unreadable = |reason: String| TrackError::Video {
        path: path.to_path_buf(),
        reason,
    };
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => return Err(unreadable("it is not a file".into())),
        Err(e) => return Err(unreadable(e.to_string())),
    }
    super::image::opencv_serial().map_err(cv)?;
    let name = path.to_str().ok_or_else(|| {
        unreadable("the path is not valid UTF-8, which OpenCV's video module needs".into())
    })?;
    // The back-ends that fail to open a file log their own exceptions; what
    // a user needs is the one message below. The log level is OpenCV's, for
    // the whole process: one open at a time silences it and puts it back.
    static QUIET: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let cap = {
        let _one = QUIET.lock().unwrap_or_else(|e| e.into_inner());
        let level = opencv::core::set_log_level(opencv::core::LogLevel::LOG_LEVEL_SILENT);
        let cap = VideoCapture::from_file(name, videoio::CAP_ANY);
        if let Ok(l) = level {
            let _ = opencv::core::set_log_level(l);
        }
        cap
    };
    let cap = cap.map_err(cv)?;
    if !cap.is_opened().map_err(cv)? {
        return Err(unreadable(
            "OpenCV cannot open it as a video (not a video, a damaged file, or a codec none of its video back-ends here reads; MJPG in AVI is always readable)".into(),
        ));
    }
    Ok(cap)
}

/// Reads a video through once: its frame count, frame rate and frame times.
pub fn probe(path: &Path) -> Result<VideoInfo, TrackError> {
    let mut cap = open(path)?;
    let backend = cap.get_backend_name().unwrap_or_default();
    let fps = cap
        .get(videoio::CAP_PROP_FPS)
        .ok()
        .filter(|f| f.is_finite() && *f > 0.0);
    let mut msec = Vec::new();
    while cap.grab().map_err(cv)? {
        msec.push(cap.get(videoio::CAP_PROP_POS_MSEC).unwrap_or(f64::NAN));
    }
    if msec.is_empty() {
        return Err(TrackError::Video {
            path: path.to_path_buf(),
            reason: format!(
                "no frame could be read from it (OpenCV's {backend} back-end opened it): an empty video, or a codec it lacks"
            ),
        });
    }
    let stamped = msec.len() > 1
        && msec.iter().all(|m| m.is_finite())
        && msec.windows(2).all(|w| w[1] > w[0]);
    // A frame that cannot be decoded is skipped by the back-end: every
    // later frame would take the index, and so the time and the pressure,
    // of the one before it. The container's time stamps show the hole (an
    // interval of more than one and a half frames), and its header the
    // count of frames it holds.
    if stamped && msec.len() > 2 {
        let mut gaps: Vec<f64> = msec.windows(2).map(|w| w[1] - w[0]).collect();
        gaps.sort_by(f64::total_cmp);
        let typical = gaps[gaps.len() / 2];
        if let Some(k) = msec.windows(2).position(|w| w[1] - w[0] > 1.5 * typical) {
            return Err(TrackError::Video {
                path: path.to_path_buf(),
                reason: format!(
                    "a frame cannot be decoded after {} (at {} s): the next frame readable is at {} s, {:.1} frame intervals later; every later frame would take the time of the frame before it. Repair or re-encode the video (e.g. with ffmpeg), or cut it before the damage",
                    frame_name(k),
                    fmt_short(msec[k] / 1e3),
                    fmt_short(msec[k + 1] / 1e3),
                    (msec[k + 1] - msec[k]) / typical
                ),
            });
        }
    }
    let stated = cap
        .get(videoio::CAP_PROP_FRAME_COUNT)
        .ok()
        .filter(|c| c.is_finite() && *c >= 1.0)
        .map(|c| c.round() as usize);
    if let Some(n) = stated.filter(|&n| n > msec.len()) {
        return Err(TrackError::Video {
            path: path.to_path_buf(),
            reason: format!(
                "its header says {n} frames, but only {} can be read: the file is cut short or a frame is damaged; copy it again, or re-encode it (e.g. with ffmpeg) to keep the frames that can be read",
                msec.len()
            ),
        });
    }
    let times_s = if stamped {
        Some(msec.iter().map(|m| m / 1e3).collect())
    } else {
        fps.map(|f| (0..msec.len()).map(|k| k as f64 / f).collect())
    };
    Ok(VideoInfo {
        path: path.to_path_buf(),
        frames: msec.len(),
        fps,
        times_s,
        backend,
    })
}

impl VideoInfo {
    /// The video's span for messages: `0..9.5 s (20 frames at 2 frames/s)`.
    pub fn describe(&self) -> String {
        let rate = self
            .fps
            .map_or(String::new(), |f| format!(" at {} frames/s", fmt_short(f)));
        match &self.times_s {
            Some(t) => format!(
                "{}..{} s ({} frames{rate})",
                fmt_short(t[0]),
                fmt_short(t[t.len() - 1]),
                self.frames
            ),
            None => format!("{} frames, no frame times", self.frames),
        }
    }

    /// The frames `[photos] every` or `times_s` choose, in time order. The
    /// error is the message (what is wrong and the fix), without the file.
    pub fn select(
        &self,
        every: Option<usize>,
        times: Option<&[f64]>,
    ) -> Result<Vec<usize>, String> {
        match (every, times) {
            (Some(_), Some(_)) => {
                Err("[photos] gives both `every` and `times_s`: keep one way to choose the video's frames".into())
            }
            (Some(0), None) => Err(
                "[photos] every = 0: give a positive step (every = 1 takes every frame, 10 every tenth)"
                    .into(),
            ),
            (every, None) => Ok((0..self.frames).step_by(every.unwrap_or(1)).collect()),
            (None, Some(times)) => self.nearest_frames(times),
        }
    }

    fn nearest_frames(&self, times: &[f64]) -> Result<Vec<usize>, String> {
        let Some(ft) = &self.times_s else {
            return Err(format!(
                "[photos] times_s needs the frames' times, but {} states neither time stamps nor a frame rate; choose frames with `every` instead",
                self.path.display()
            ));
        };
        if times.is_empty() {
            return Err("[photos] times_s = []: give at least one time, s".into());
        }
        let (first, last) = (ft[0], ft[ft.len() - 1]);
        let mut out: Vec<usize> = Vec::with_capacity(times.len());
        for (k, &t) in times.iter().enumerate() {
            if !(t.is_finite() && t >= first && t <= last) {
                return Err(format!(
                    "[photos] times_s[{k}] = {} s lies outside the video's span {}; give times within it",
                    fmt_short(t),
                    self.describe()
                ));
            }
            if k > 0 && t <= times[k - 1] {
                return Err(format!(
                    "[photos] times_s[{k}] = {} s is not after times_s[{}] = {} s: list the times in increasing order",
                    fmt_short(t),
                    k - 1,
                    fmt_short(times[k - 1])
                ));
            }
            let after = ft.partition_point(|&x| x < t).min(ft.len() - 1);
            let i = if after > 0 && (t - ft[after - 1]) <= (ft[after] - t) {
                after - 1
            } else {
                after
            };
            if let Some(&prev) = out.last()
                && prev == i
            {
                return Err(format!(
                    "[photos] times_s[{}] = {} s and times_s[{k}] = {} s both choose {} (at {} s): the frames are {} s apart; remove one of the times",
                    k - 1,
                    fmt_short(times[k - 1]),
                    fmt_short(t),
                    frame_name(i),
                    fmt_short(ft[i]),
                    fmt_short((last - first) / (ft.len() - 1).max(1) as f64)
                ));
            }
            out.push(i);
        }
        Ok(out)
    }
}

/// One frame to read: its position in the sequence, its index in the video,
/// and the crop (`None`: the whole frame).
#[derive(Debug, Clone, Copy)]
pub(super) struct Wanted {
    pub(super) seq: usize,
    pub(super) index: usize,
    pub(super) crop: Option<[usize; 4]>,
    /// A crop that does not fit gives an empty crop (the size check names
    /// the frame) instead of an error.
    pub(super) lenient: bool,
}

/// Reads the `wanted` frames (in increasing video index), converts them to
/// grayscale, crops them and hands each to `send` with its sequence
/// position; stops early when `send` returns false.
pub(super) fn read_frames(
    path: &Path,
    wanted: &[Wanted],
    mut send: impl FnMut(usize, Result<Decoded, TrackError>) -> bool,
) {
    let mut cap = match open(path) {
        Ok(c) => c,
        Err(e) => {
            if let Some(w) = wanted.first() {
                send(w.seq, Err(e));
            }
            return;
        }
    };
    let mut next = 0usize;
    let mut frame = Mat::default();
    for w in wanted {
        let got = (|| -> Result<Decoded, TrackError> {
            while next <= w.index {
                if !cap.grab().map_err(cv)? {
                    return Err(TrackError::Video {
                        path: path.to_path_buf(),
                        reason: format!(
                            "{} cannot be read: the video ends after {next} frames",
                            frame_name(w.index)
                        ),
                    });
                }
                next += 1;
            }
            if !cap.retrieve(&mut frame, 0).map_err(cv)? || frame.empty() {
                return Err(TrackError::Video {
                    path: path.to_path_buf(),
                    reason: format!("{} cannot be decoded", frame_name(w.index)),
                });
            }
            let gray = to_gray(&frame)?;
            let whole = [0, 0, gray.cols() as usize, gray.rows() as usize];
            if w.lenient {
                crop_lenient(path, &gray, w.crop)
            } else {
                crop_mat(path, &gray, w.crop.unwrap_or(whole))
            }
        })();
        let failed = got.is_err();
        if !send(w.seq, got) || failed {
            return;
        }
    }
}

/// An 8-bit frame of 1, 3 (BGR) or 4 (BGRA) channels as 8-bit grayscale.
fn to_gray(frame: &Mat) -> Result<Mat, TrackError> {
    let code = match frame.channels() {
        1 => return frame.try_clone().map_err(cv),
        3 => imgproc::COLOR_BGR2GRAY,
        4 => imgproc::COLOR_BGRA2GRAY,
        c => return Err(TrackError::OpenCv(format!("a video frame of {c} channels"))),
    };
    let mut gray = Mat::default();
    imgproc::cvt_color_def(frame, &mut gray, code).map_err(cv)?;
    Ok(gray)
}

/// Video frame `index` in colour (BGR), for drawing on it.
pub fn read_frame_bgr(path: &Path, index: usize) -> Result<Mat, TrackError> {
    let mut cap = open(path)?;
    for _ in 0..=index {
        if !cap.grab().map_err(cv)? {
            return Err(TrackError::Video {
                path: path.to_path_buf(),
                reason: format!(
                    "{} cannot be read: the video ends before it",
                    frame_name(index)
                ),
            });
        }
    }
    let mut frame = Mat::default();
    if !cap.retrieve(&mut frame, 0).map_err(cv)? || frame.empty() {
        return Err(TrackError::Video {
            path: path.to_path_buf(),
            reason: format!("{} cannot be decoded", frame_name(index)),
        });
    }
    if frame.channels() == 3 {
        return Ok(frame);
    }
    let code = if frame.channels() == 1 {
        imgproc::COLOR_GRAY2BGR
    } else {
        imgproc::COLOR_BGRA2BGR
    };
    let mut bgr = Mat::default();
    imgproc::cvt_color_def(&frame, &mut bgr, code).map_err(cv)?;
    Ok(bgr)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(times: Option<Vec<f64>>) -> VideoInfo {
        VideoInfo {
            path: PathBuf::from("test.avi"),
            frames: 10,
            fps: Some(2.0),
            times_s: times,
            backend: "TEST".into(),
        }
    }

    #[test]
    fn every_and_times_choose_frames() {
        let v = info(Some((0..10).map(|k| k as f64 / 2.0).collect()));
        assert_eq!(v.select(None, None).unwrap(), (0..10).collect::<Vec<_>>());
        assert_eq!(v.select(Some(4), None).unwrap(), [0, 4, 8]);
        assert!(v.select(Some(0), None).unwrap_err().contains("every = 0"));
        // nearest frame; a tie goes to the earlier one
        assert_eq!(
            v.select(None, Some(&[0.0, 0.74, 1.25, 4.5])).unwrap(),
            [0, 1, 2, 9]
        );
        let e = v.select(None, Some(&[1.0, 4.6])).unwrap_err();
        assert!(
            e.contains("times_s[1] = 4.6 s") && e.contains("0..4.5 s (10 frames at 2 frames/s)"),
            "{e}"
        );
        let e = v.select(None, Some(&[-0.1])).unwrap_err();
        assert!(e.contains("outside the video's span"), "{e}");
        let e = v.select(None, Some(&[1.0, 1.1])).unwrap_err();
        assert!(e.contains("both choose frame 000002"), "{e}");
        let e = v.select(None, Some(&[2.0, 1.0])).unwrap_err();
        assert!(e.contains("increasing order"), "{e}");
        let e = v.select(Some(2), Some(&[1.0])).unwrap_err();
        assert!(e.contains("both `every` and `times_s`"), "{e}");
        let e = info(None).select(None, Some(&[1.0])).unwrap_err();
        assert!(e.contains("choose frames with `every`"), "{e}");
    }

    #[test]
    fn a_missing_or_broken_video_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing.avi");
        let e = probe(&p).unwrap_err().to_string();
        assert!(e.contains("missing.avi"), "{e}");
        let p = dir.path().join("text.avi");
        std::fs::write(&p, b"not a video at all").unwrap();
        let e = probe(&p).unwrap_err().to_string();
        assert!(
            e.contains("text.avi") && e.contains("cannot read the video"),
            "{e}"
        );
    }
}
