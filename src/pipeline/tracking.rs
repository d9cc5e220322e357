//! The track stage: photos -> apex heights, with the set-up it used.

#[cfg(feature = "opencv")]
use std::path::PathBuf;

#[cfg(feature = "opencv")]
use crate::experiment::Experiment;
use crate::io::CsvOut;
use crate::mechanics::Point;
#[cfg(feature = "opencv")]
use crate::track::{self, Setup, TemplateSource, Tracked};

use super::*;

/// Output of the tracking stage.
#[cfg(feature = "opencv")]
#[derive(Debug, Clone)]
pub struct Tracking {
    /// What was tracked.
    pub setup: Setup,
    /// The result per frame.
    pub tracked: Tracked,
    /// Template size `[w, h]`, px.
    pub template_size: [usize; 2],
    /// Apex position inside the template, px.
    pub apex_in_template: [f64; 2],
}

#[cfg(feature = "opencv")]
impl Tracking {
    /// `heights.csv` as `bulge track` writes it.
    pub fn csv(&self) -> CsvOut {
        self.tracked.heights_csv()
    }

    /// The measured points.
    pub fn points(&self) -> Vec<Point> {
        self.tracked
            .rows
            .iter()
            .map(|r| Point {
                pressure_pa: r.pressure_pa,
                height_m: r.height_m,
                height_std_m: Some(r.height_std_m),
            })
            .collect()
    }

    /// What to draw on frame `i` of the tracked rows.
    pub fn marks(&self, i: usize) -> track::annotate::Marks {
        let r = &self.tracked.rows[i];
        let q = r.apex_quadratic_px;
        let [tw, th] = self.template_size;
        let roi = self.setup.roi;
        track::annotate::Marks {
            roi_px: [roi[0] as f64, roi[1] as f64, roi[2] as f64, roi[3] as f64],
            template_px: [
                q[0] - self.apex_in_template[0],
                q[1] - self.apex_in_template[1],
                tw as f64,
                th as f64,
            ],
            // The apex is the undistorted image's: drawn where the photo shows it.
            apex_px: self.setup.lens.map_or([r.apex_x_px, r.apex_y_px], |l| {
                l.distort([r.apex_x_px, r.apex_y_px])
            }),
        }
    }

    /// Path of the photo of tracked row `i` (of the video, for a video frame).
    pub fn photo(&self, i: usize) -> PathBuf {
        self.setup.frames[self.tracked.rows[i].frame].path.clone()
    }

    /// The frame of tracked row `i` (a photo or a video frame).
    pub fn frame(&self, i: usize) -> &track::Frame {
        &self.setup.frames[self.tracked.rows[i].frame]
    }
}

#[cfg(feature = "opencv")]
/// Stage 1: the photos of `exp` -> heights. `tick` is called per frame.
pub fn track_stage(
    exp: &Experiment,
    settings: &Settings,
    tick: &(dyn Fn() + Sync),
) -> Result<Tracking, PipelineError> {
    struct Tick<'a>(&'a (dyn Fn() + Sync));
    impl Observer for Tick<'_> {
        fn tick(&self) {
            (self.0)()
        }
    }
    track_stage_observed(exp, settings, &Tick(tick))
}

/// Stage 1, telling `obs` of the number of frames and each frame done.
#[cfg(feature = "opencv")]
pub(super) fn track_stage_observed(
    exp: &Experiment,
    settings: &Settings,
    obs: &dyn Observer,
) -> Result<Tracking, PipelineError> {
    let setup = track::setup_from_experiment(exp)?;
    obs.start(Stage::Track, setup.frames.len() as u64);
    let tracked = track::track(&setup, &settings.track, &|| obs.tick())?;
    if tracked.rows.is_empty() {
        return Err(PipelineError::Input(format!(
            "every one of the {} frames scored below the minimum score {}: nothing to measure; check the template and the region",
            setup.frames.len(),
            settings.track.min_score
        )));
    }
    let template_size = match &setup.template {
        TemplateSource::Rect(r) => [r[2] as usize, r[3] as usize],
        TemplateSource::File(p) => {
            let t = track::image::read_gray(p, None)?;
            [t.width, t.height]
        }
    };
    let apex_in_template = setup.apex_in_template.unwrap_or([
        (template_size[0] as f64 - 1.0) / 2.0,
        (template_size[1] as f64 - 1.0) / 2.0,
    ]);
    Ok(Tracking {
        setup,
        tracked,
        template_size,
        apex_in_template,
    })
}
