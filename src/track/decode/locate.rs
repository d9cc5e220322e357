//! Every frame located in order: the template match and the edge fit
//! (`Tracker::locate`), the score, the plausibility guards, a second search
//! near the position the frames before predict, and what a refused frame
//! leaves (an error naming the photo and why, or with `skip_bad_frames` a
//! skipped row and a search that starts afresh).

use super::super::tracker::{Located, Tracker};
use super::*;

/// What every frame's search shares.
pub(super) struct Shared<'a> {
    /// The reference photo.
    pub reference: &'a Frame,
    /// Its region, in light.
    pub ref_crop: &'a Gray,
    /// The photos' size, px.
    pub size: (usize, usize),
    /// The camera's tone curve.
    pub tone: image::Tone,
    /// The frame where the bubble is largest, and its region (none for a
    /// video).
    pub fullest: (usize, Option<&'a Gray>),
    /// The frame where it is smallest, and its region.
    pub emptiest: (usize, Option<&'a Gray>),
    /// The apex's place in the template, px.
    pub apex_in_t: [f64; 2],
}

/// The frames located (`None`: skipped), the skipped ones with why, the
/// warnings, and the seconds spent locating.
pub(super) struct Outcome {
    pub located: Vec<Option<Located>>,
    pub skipped: Vec<Skipped>,
    pub warnings: Vec<String>,
    pub seconds: f64,
}

/// Locates every frame of `setup` in order, the decoded photos taken from
/// `arrivals`; `tick` after each.
pub(super) fn every_frame(
    setup: &Setup,
    opts: &Options,
    tick: &(dyn Fn() + Sync),
    shared: &Shared,
    arrivals: &mut InOrder,
    state: &mut Tracker,
    guard: &mut Guard,
) -> Result<Outcome, TrackError> {
    let n = setup.frames.len();
    let (width, height) = shared.size;
    let apex_in_t = shared.apex_in_t;
    let mut located: Vec<Option<Located>> = Vec::with_capacity(n);
    let mut skipped = Vec::new();
    let mut warnings = Vec::new();
    let mut locate_time = 0.0;
    while located.len() < n {
        let i = located.len();
        let f = &setup.frames[i];
        let crop_owned;
        let crop: &Gray = if i == setup.reference_frame {
            shared.ref_crop
        } else {
            let dec = arrivals.take(i)?;
            if (dec.width, dec.height) != (width, height) {
                return Err(TrackError::MixedSizes {
                    path: f.path.clone(),
                    width: dec.width,
                    height: dec.height,
                    reference: shared.reference.path.clone(),
                    ref_width: width,
                    ref_height: height,
                });
            }
            crop_owned = dec.crop.with_tone(shared.tone);
            &crop_owned
        };
        let t0 = std::time::Instant::now();
        let extremes = Extremes {
            fullest: shared.fullest.1.filter(|_| i != shared.fullest.0),
            emptiest: shared.emptiest.1.filter(|_| i != shared.emptiest.0),
            is_emptiest: i == shared.emptiest.0,
        };
        let loc = state.locate(crop, extremes)?;
        let low = loc.m.score < opts.min_score || !loc.m.score.is_finite();
        let score = loc.m.score;
        // A good score, then the plausibility guards; an implausible apex is
        // searched again near the position the frames before predict.
        let verdict = if low {
            Err(format!(
                "score {:.3} < {} {}",
                loc.m.score,
                crate::setting::Setting::MinScore,
                opts.min_score
            ))
        } else {
            let (apex, std) = state.apex(&loc);
            let x_std = state.apex_x_std(&loc);
            match guard.check(f.pressure_pa, apex, [x_std, std], loc.edge.as_ref()) {
                Ok(()) => Ok(loc),
                Err(why) => {
                    // Only a rule no physics bounds broken (the trend, or
                    // the residual with the trend holding): kept with a
                    // warning when the search near the prediction finds
                    // nothing better.
                    let kept = guard.kept_warning(&why, f.pressure_pa, apex[1], std);
                    let again = guard
                        .predict(f.pressure_pa)
                        .and_then(|pred| state.locate_at(crop, extremes, pred).transpose())
                        .transpose()?
                        .filter(|l| {
                            let (a, s) = state.apex(l);
                            if l.m.score < opts.min_score {
                                return false;
                            }
                            let xs = state.apex_x_std(l);
                            guard
                                .check(f.pressure_pa, a, [xs, s], l.edge.as_ref())
                                .is_ok()
                        });
                    match again {
                        Some(l) => Ok(l),
                        None => match kept {
                            Some(w) => {
                                warnings.push(format!("frame {i} ({}): {w}", f.file));
                                Ok(loc)
                            }
                            None => Err(why.to_string()),
                        },
                    }
                }
            }
        };
        locate_time += t0.elapsed().as_secs_f64();
        match verdict {
            Err(why) => {
                if !opts.skip_bad_frames {
                    // a video names the frame in it too
                    let path = match f.video_frame {
                        Some(_) => format!("{} ({})", f.path.display(), f.file).into(),
                        None => f.path.clone(),
                    };
                    return Err(if low {
                        TrackError::LowScore {
                            path,
                            frame: i,
                            score,
                            min: opts.min_score,
                        }
                    } else {
                        TrackError::Implausible {
                            path,
                            frame: i,
                            why,
                        }
                    });
                }
                skipped.push(Skipped {
                    frame: i,
                    file: f.file.clone(),
                    score,
                    reason: why,
                });
                if low {
                    state.last = None;
                    state.prev = None;
                    state.curvature = 0.0;
                } else if let Some(pred) = guard.predict(f.pressure_pa) {
                    // The next search starts from where this apex should be.
                    state.prev = state.last;
                    state.last = Some([pred[0] - apex_in_t[0], pred[1] - apex_in_t[1]]);
                }
                located.push(None);
            }
            Ok(loc) => {
                // The next search starts from this frame's refined apex (the
                // template alone slides along a flat top).
                let (apex, std) = state.apex(&loc);
                let x_std = state.apex_x_std(&loc);
                guard.accept(f.pressure_pa, apex, [x_std, std], loc.edge.as_ref());
                state.prev = state.last;
                state.last = Some([apex[0] - apex_in_t[0], apex[1] - apex_in_t[1]]);
                state.curvature = loc.edge.map_or(0.0, |e| e.curvature);
                located.push(Some(loc));
            }
        }
        tick();
    }
    Ok(Outcome {
        located,
        skipped,
        warnings,
        seconds: locate_time,
    })
}
