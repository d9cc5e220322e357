//! The tracking of every frame: photos decoded in parallel and matched in
//! order, each match refined to sub-pixel precision (`track`).

use rayon::prelude::*;

use super::decode::{decode_frame, match_frames, reference_box};
use super::guards::SIGMAS;
use super::image::{Decoded, Gray};
use super::matcher::{EdgeFit, EdgeSettings, Extremes, Match};
use super::*;

/// Systematic error of the edge fit that its residuals do not show, px, for
/// a fit over [`FLOOR_COLUMNS`] columns, on photos stored without block
/// compression (PNG, TIFF) or where no block boundary of a JPEG lies within
/// [`BLOCK_REACH_PX`] of the edge ([`edge_floor_px`]). Measured on the
/// tracker sweep's clean sequences (docs/track.md, *The sweep*): the floor
/// that brings a class of photos to RMS(error / std) 1 falls with the
/// photo's size, on PNG photos from 0.014 px at 640x480 to 0.007 px at
/// 1280x960, about as the inverse of the columns fitted (as a bias that
/// shrinks with the dome's size in px would; noise would fall as the square
/// root; the mechanism is not established). The value is the smallest, in
/// steps of 0.002 px, that leaves no clean photo of the sweep beyond 4
/// stated deviations.
pub const EDGE_BIAS_FLOOR_PX: f64 = 0.014;

/// The columns of the fit at which the floor is [`EDGE_BIAS_FLOOR_PX`]
/// (about a 640x480 photo's).
pub const FLOOR_COLUMNS: f64 = 60.0;

/// A JPEG codes the photo in 8x8 blocks, each quantised on its own: where a
/// block boundary runs through the blurred step of a nearly horizontal
/// edge, the two halves of its profile carry the quantisation errors of two
/// blocks, and the columns along that block row share the boundary, so no
/// residual shows it. Its size at [`FLOOR_COLUMNS`] columns, px, added in
/// quadrature to the floor within [`BLOCK_REACH_PX`] of a boundary: the
/// smallest, in steps of 0.004 px, that leaves no clean JPEG photo of the
/// sweep beyond 4 stated deviations (docs/track.md, *The sweep*).
pub const JPEG_BLOCK_PX: f64 = 0.024;

/// How far from a JPEG block boundary an edge's row feels it, px: on the
/// sweep's clean JPEG photos the apex error within 1.5 px of a boundary
/// needed a floor of 0.014-0.015 px, from 1.5 px on 0-0.004 px
/// (docs/track.md, *The sweep*).
pub const BLOCK_REACH_PX: f64 = 1.5;

/// How the photos were stored, for the edge fit's floor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blocks {
    /// Without block compression (PNG, TIFF, raw).
    None,
    /// JPEG: 8x8 blocks from the photo's top-left corner.
    Jpeg,
    /// A video, whose codec's blocks are not known: every edge is taken as
    /// near a boundary.
    Unknown,
}

impl Blocks {
    /// The storage of the photo at `path`, from its first bytes (a JPEG
    /// starts with `FF D8 FF`); `None` when it cannot be read (decoding
    /// reports that).
    pub fn of_photo(path: &std::path::Path) -> Blocks {
        use std::io::Read;
        let mut head = [0u8; 3];
        let jpeg = std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut head))
            .is_ok()
            && head == [0xFF, 0xD8, 0xFF];
        if jpeg { Blocks::Jpeg } else { Blocks::None }
    }
}

/// The edge fit's floor, px, for an edge at image row `row` (pixel centres
/// at whole numbers, so a JPEG's block boundaries lie at rows `8 k - 0.5`)
/// fitted over `columns` columns: [`EDGE_BIAS_FLOOR_PX`], with
/// [`JPEG_BLOCK_PX`] in quadrature within [`BLOCK_REACH_PX`] of a block
/// boundary (always for [`Blocks::Unknown`]), times [`FLOOR_COLUMNS`] over
/// the columns.
pub fn edge_floor_px(blocks: Blocks, row: f64, columns: usize) -> f64 {
    let near = match blocks {
        Blocks::None => false,
        Blocks::Unknown => true,
        Blocks::Jpeg => {
            let phase = (row + 0.5).rem_euclid(8.0);
            phase.min(8.0 - phase) < BLOCK_REACH_PX
        }
    };
    let floor = if near {
        EDGE_BIAS_FLOOR_PX.hypot(JPEG_BLOCK_PX)
    } else {
        EDGE_BIAS_FLOOR_PX
    };
    floor * FLOOR_COLUMNS / columns.max(1) as f64
}

/// Per-frame measurement in region coordinates, before calibration.
pub(super) struct Located {
    pub(super) m: Match,
    pub(super) edge: Option<EdgeFit>,
    /// Axis column from the edge's mirror symmetry and its standard error, px.
    pub(super) axis: Option<(f64, f64)>,
}

/// Tracks every frame of `setup`; `tick` is called once per frame done.
pub fn track(
    setup: &Setup,
    opts: &Options,
    tick: &(dyn Fn() + Sync),
) -> Result<Tracked, TrackError> {
    let n = setup.frames.len();
    let r = setup.roi;
    let roi_req = (r[0] >= 0 && r[1] >= 0 && r[2] > 0 && r[3] > 0)
        .then(|| [r[0] as usize, r[1] as usize, r[2] as usize, r[3] as usize]);
    // The pipeline: the rayon pool decodes the photos roughly in order
    // (`par_bridge`), the reference photo first (its region and the
    // template's rectangle), and sends them through a bounded channel; this thread takes
    // them back in frame order and tracks them one by one (each search
    // starts from the previous frame's position). No barrier stops the
    // decoders, and memory holds only a few regions at a time.
    // A deep queue (up to 128 MB of regions) keeps the decoders running
    // when the matching thread waits for a core on a busy machine.
    let crop_bytes = roi_req.map_or(1 << 20, |r| (r[2] * r[3]).max(1));
    let depth =
        ((128usize << 20) / crop_bytes).clamp(2 * rayon::current_num_threads().max(1) + 2, 1024);
    let (tx, rx) = std::sync::mpsc::sync_channel::<(usize, Result<Decoded, TrackError>)>(depth);
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let reference = &setup.frames[setup.reference_frame];
    std::thread::scope(|scope| {
        let cancel = &cancel;
        if let Some(video) = &setup.video {
            // A video is read in order by one thread (its frames are decoded
            // one after the other anyway); the reference frame is cropped to
            // the region and the template's rectangle like a photo.
            scope.spawn(move || {
                let r = setup.reference_frame;
                let mut wanted: Vec<video::Wanted> = setup
                    .frames
                    .iter()
                    .enumerate()
                    .map(|(i, f)| video::Wanted {
                        seq: i,
                        index: f.video_frame.unwrap_or(i),
                        crop: if i == r {
                            reference_box(setup)
                        } else {
                            roi_req
                        },
                        lenient: i != r,
                    })
                    .collect();
                wanted.sort_by_key(|w| w.index);
                video::read_frames(video, &wanted, |i, d| {
                    !cancel.load(std::sync::atomic::Ordering::Relaxed) && tx.send((i, d)).is_ok()
                });
            });
            let result = match_frames(setup, opts, tick, reference, rx);
            if result.is_err() {
                cancel.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            return result;
        }
        scope.spawn(move || {
            // The reference photo first, cropped to the region and the
            // template's rectangle, then the others' regions.
            let r = setup.reference_frame;
            let order = std::iter::once(r).chain((0..n).filter(|&i| i != r));
            order.par_bridge().for_each(|i| {
                if cancel.load(std::sync::atomic::Ordering::Relaxed) {
                    return;
                }
                let path = &setup.frames[i].path;
                let decoded = match (i == r, reference_box(setup)) {
                    (true, Some(b)) => decode_frame(path, Some(b)),
                    (true, None) => image::read_gray(path, None),
                    (false, _) => decode_frame(path, roi_req),
                };
                // A closed channel means the matching stopped on an error.
                let _ = tx.send((i, decoded));
            });
        });
        let result = match_frames(setup, opts, tick, reference, rx);
        if result.is_err() {
            cancel.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        result
    })
}

pub(super) struct Tracker<'a> {
    pub(super) templ: &'a Gray,
    pub(super) opts: &'a Options,
    pub(super) edge_settings: EdgeSettings,
    /// Apex position inside the template, px.
    pub(super) apex_in_t: [f64; 2],
    /// Reduction factor and reduced template for the coarse search, when the
    /// template is wider than 128 px.
    pub(super) reduced: Option<(usize, Gray)>,
    /// Template position (region coordinates) in the last two tracked frames.
    pub(super) last: Option<[f64; 2]>,
    pub(super) prev: Option<[f64; 2]>,
    /// Edge curvature of the last tracked frame, 1/px (0: none yet).
    pub(super) curvature: f64,
    /// How the photos were stored, and the image row of the region's top
    /// (for the edge fit's floor, [`edge_floor_px`]).
    pub(super) blocks: Blocks,
    pub(super) origin_row_px: f64,
}

impl Tracker<'_> {
    /// Template search in `img` (full or reduced resolution): around the
    /// position predicted from the last two frames, widened (four times the
    /// margin, then the whole image) on a poor score or a peak on the
    /// window's border.
    pub(super) fn search(
        &self,
        img: &Gray,
        templ: &Gray,
        last: Option<[f64; 2]>,
        prev: Option<[f64; 2]>,
        margin_px: f64,
    ) -> Result<Match, TrackError> {
        let (tw, th) = (templ.width, templ.height);
        let (rw, rh) = (img.width, img.height);
        let whole = [0, 0, rw, rh];
        let Some(last) = last else {
            return matcher::match_in_window(img, templ, whole);
        };
        let vel = prev.map_or([0.0, 0.0], |p| [last[0] - p[0], last[1] - p[1]]);
        let pred = [last[0] + vel[0], last[1] + vel[1]];
        let margin = margin_px + 0.5 * vel[0].abs().max(vel[1].abs());
        // The window of positions within `margin` of the prediction.
        let window = |margin: f64| {
            let x0 = (pred[0] - margin).floor().clamp(0.0, (rw - tw) as f64) as usize;
            let y0 = (pred[1] - margin).floor().clamp(0.0, (rh - th) as f64) as usize;
            let x1 = ((pred[0] + margin).ceil().max(0.0) as usize + tw).clamp(x0 + tw, rw);
            let y1 = ((pred[1] + margin).ceil().max(0.0) as usize + th).clamp(y0 + th, rh);
            [x0, y0, x1 - x0, y1 - y0]
        };
        // A good match: a high score, and a peak off the window's top and
        // bottom borders (where the apex could have moved past). A peak on
        // a side border with a high score is the template sliding along a
        // flat top, which the edge fit resolves; widening would only let it
        // slide further.
        let good = |m: &Match, win: [usize; 4]| {
            let (lo, hi) = (win[1], win[1] + win[3] - th);
            let y = m.integer[1];
            let on_border = (y <= lo as f64 && lo > 0) || (y >= hi as f64 && hi < rh - th);
            m.score >= self.opts.min_score.max(0.8) && !on_border
        };
        // Widened in two steps on a poor match: four times the margin, then
        // the whole region.
        let wins = [window(margin), window(4.0 * margin), whole];
        for (k, &win) in wins.iter().enumerate() {
            if k > 0 && win == wins[k - 1] {
                continue;
            }
            let m = matcher::match_in_window(img, templ, win)?;
            if win == whole || good(&m, win) {
                return Ok(m);
            }
        }
        unreachable!("the last window is the whole region")
    }

    /// The apex of a located frame in region coordinates and its
    /// statistical uncertainty, px, as `opts.refine` asks.
    /// The standard error of the apex column of a located frame, px
    /// (infinite without an edge fit).
    pub(super) fn apex_x_std(&self, l: &Located) -> f64 {
        let edge = match (l.edge, l.axis) {
            (Some(e), Some((_, s))) => s.min(e.x_std),
            (Some(e), None) => e.x_std,
            (None, _) => return f64::INFINITY,
        };
        // With the template's column as the apex's (`--refine integer` or
        // `quadratic`), its own bias is the gap to the edge's column, as
        // for the row in `apex`: along a flat top the match slides.
        let t = self.apex_in_t[0];
        let col = l
            .axis
            .map_or(l.edge.map_or(f64::NAN, |e| e.x_vertex), |a| a.0);
        match self.opts.refine {
            Refine::Edge => edge,
            Refine::Quadratic => edge.hypot(l.m.quadratic[0] + t - col),
            Refine::Integer => edge.hypot(l.m.integer[0] + t - col),
        }
    }

    pub(super) fn apex(&self, l: &Located) -> ([f64; 2], f64) {
        let t = self.apex_in_t;
        let int = [l.m.integer[0] + t[0], l.m.integer[1] + t[1]];
        let quad = [l.m.quadratic[0] + t[0], l.m.quadratic[1] + t[1]];
        // Without an edge fit, the error bound of a peak on the pixel grid.
        let grid = 0.5;
        // The edge fit's statistical error plus its bias floor.
        let edge_std = |e: &EdgeFit| {
            e.y_std.hypot(edge_floor_px(
                self.blocks,
                e.y + self.origin_row_px,
                e.columns,
            ))
        };
        match (self.opts.refine, l.edge) {
            // The column from the edge's symmetry, else the parabola's
            // vertex when the edge's curvature pins it down at all: the
            // template sees mostly a horizontal edge, so its column follows
            // the background texture (errors of several px measured).
            (Refine::Edge, Some(e)) if l.axis.is_some_and(|(_, s)| s < e.x_std) => {
                ([l.axis.map_or(e.x_vertex, |a| a.0), e.y], edge_std(&e))
            }
            (Refine::Edge, Some(e)) if e.x_std < 0.5 * self.edge_settings.half_span_px as f64 => {
                ([e.x_vertex, e.y], edge_std(&e))
            }
            (Refine::Edge, Some(e)) => ([quad[0], e.y], edge_std(&e)),
            (Refine::Edge, None) | (Refine::Quadratic, None) => (quad, grid),
            (Refine::Integer, None) => (int, grid),
            // The template's own bias is the gap to the edge fit.
            (Refine::Quadratic, Some(e)) => (quad, edge_std(&e).hypot(quad[1] - e.y)),
            (Refine::Integer, Some(e)) => (int, edge_std(&e).hypot(int[1] - e.y)),
        }
    }

    pub(super) fn locate(&self, crop: &Gray, extremes: Extremes) -> Result<Located, TrackError> {
        let margin = self.opts.search_margin_px as f64;
        let m = match &self.reduced {
            None => self.search(crop, self.templ, self.last, self.prev, margin)?,
            Some((f, small_t)) => {
                // Coarse search at 1/f resolution, then the full-resolution
                // match in a window of +-(f + 2) px around it.
                let f = *f;
                let fl = f as f64;
                let small = matcher::reduce(crop, f)?;
                let down = |p: [f64; 2]| [p[0] / fl, p[1] / fl];
                let mc = self.search(
                    &small,
                    small_t,
                    self.last.map(down),
                    self.prev.map(down),
                    (margin / fl).max(2.0),
                )?;
                if self.opts.refine == Refine::Edge {
                    // The edge fit needs a seed within a few px, not the
                    // full-resolution match: report the coarse one scaled up.
                    let up = |p: [f64; 2]| [p[0] * fl, p[1] * fl];
                    Match {
                        integer: up(mc.integer),
                        quadratic: up(mc.quadratic),
                        score: mc.score,
                    }
                } else {
                    let (tw, th) = (self.templ.width, self.templ.height);
                    let r = f + 2;
                    let cx = (mc.quadratic[0] * fl).round() as i64;
                    let cy = (mc.quadratic[1] * fl).round() as i64;
                    let x0 = (cx - r as i64).clamp(0, (crop.width - tw) as i64) as usize;
                    let y0 = (cy - r as i64).clamp(0, (crop.height - th) as i64) as usize;
                    let x1 = (x0 + tw + 2 * r).min(crop.width);
                    let y1 = (y0 + th + 2 * r).min(crop.height);
                    matcher::match_in_window(crop, self.templ, [x0, y0, x1 - x0, y1 - y0])?
                }
            }
        };
        // The edge fit runs in every mode: in the integer and quadratic modes
        // it only serves to state their uncertainty.
        // The bubble's axis does not move: the edge fit is centred on the
        // last frame's apex column (the template's own column follows the
        // background and slides along a flat top), on the template's row.
        let apex = [
            self.last.map_or(m.quadratic[0], |l| l[0]) + self.apex_in_t[0],
            m.quadratic[1] + self.apex_in_t[1],
        ];
        let mut cols =
            matcher::Columns::with_extremes(crop, self.edge_settings.half_window_px, extremes);
        let (edge, axis) = self.edge_near_or_wall(&mut cols, apex);
        Ok(Located { m, edge, axis })
    }

    /// The apex searched again by the edge fit alone, seeded at `pred`
    /// (the apex predicted by the frames before, region coordinates) with
    /// the last frame's curvature, and the template's score at the
    /// position it gives. `None` when no edge is found there.
    pub(super) fn locate_at(
        &self,
        crop: &Gray,
        extremes: Extremes,
        pred: [f64; 2],
    ) -> Result<Option<Located>, TrackError> {
        let mut cols =
            matcher::Columns::with_extremes(crop, self.edge_settings.half_window_px, extremes);
        let (edge, axis) = self.edge_near_or_wall(&mut cols, pred);
        let Some(edge) = edge else {
            return Ok(None);
        };
        // The template's score near the edge's apex (its top-left corner
        // within 2 px of where the apex puts it).
        let (tw, th) = (self.templ.width, self.templ.height);
        let tx = (edge.x_vertex - self.apex_in_t[0]).round() as i64;
        let ty = (edge.y - self.apex_in_t[1]).round() as i64;
        let x0 = (tx - 2).clamp(0, (crop.width - tw) as i64) as usize;
        let y0 = (ty - 2).clamp(0, (crop.height - th) as i64) as usize;
        let x1 = (x0 + tw + 4).min(crop.width);
        let y1 = (y0 + th + 4).min(crop.height);
        let m = matcher::match_in_window(crop, self.templ, [x0, y0, x1 - x0, y1 - y0])?;
        Ok(Some(Located {
            m,
            edge: Some(edge),
            axis,
        }))
    }

    /// The edge fit ([`matcher::edge_fit_in`], then on the axis) seeded at
    /// `seed` (region coordinates), else at rows stepping away from it, by
    /// the window's half-height plus one (each column's search finds an
    /// edge within about that of its start), alternately below and above,
    /// out to half the template's height: the nearest edge found whose top
    /// is clean ([`Tracker::clean`]; the seed's own need not be). The
    /// template's match places the apex only within the template: a template
    /// cut from a small dome matched on a flatter, larger one lines up its
    /// steep flanks with the larger dome's and puts the apex above the top
    /// (9 px on a 1280x960 photo at 0.25 m, where the columns' search from
    /// there found no edge), and a prediction from the frames before misses
    /// a step that grows near the limit pressure (12 px below on the same
    /// photo). Where the seed's own fit finds the edge, nothing else is
    /// tried.
    fn edge_near(
        &self,
        cols: &mut matcher::Columns,
        seed: [f64; 2],
    ) -> (Option<EdgeFit>, Option<(f64, f64)>) {
        let step = self.edge_settings.half_window_px as f64 + 1.0;
        let reach = (0.5 * self.templ.height as f64 / step).floor() as i32;
        let mut first = (None, None);
        for (k, y) in matcher::seed_rows(seed[1], step, reach).enumerate() {
            let Some(e) =
                matcher::edge_fit_in(cols, seed[0], y, self.curvature, self.edge_settings)
            else {
                continue;
            };
            let found = self.on_axis(cols, e);
            if found.0.is_some_and(|e| k == 0 || self.clean(&e)) {
                return found;
            }
            if k == 0 {
                first = found;
            }
        }
        first
    }

    /// [`Tracker::edge_near`], and on the emptiest frame where it finds no
    /// edge, again with the rows under an edge passing also where they
    /// stand off the wall above it ([`matcher::Columns::wall_below`]), an
    /// edge then taken only where it curves as a dome's top does, upwards
    /// by [`SIGMAS`] standard errors. The rows under a line behind the
    /// bubble that lies along the first photo's top (a cable the top has
    /// grown into) stand off the wall too, and on a flat top nothing else
    /// on that photo tells the line's upper border from the top: on the
    /// init sweep a first top at h = 0.1 a under a cable was written 4.5 px
    /// high at 4.9 stated deviations, its curvature -0.7 standard errors
    /// from 0. The path-traced glossy domes' first tops curve upwards by 6
    /// and 12. The bar is the guards' for a bound that holds exactly (a
    /// membrane's pole is convex upwards), not one fitted between those
    /// cases.
    fn edge_near_or_wall(
        &self,
        cols: &mut matcher::Columns,
        seed: [f64; 2],
    ) -> (Option<EdgeFit>, Option<(f64, f64)>) {
        let found = self.edge_near(cols, seed);
        if found.0.is_some() || !cols.is_emptiest() {
            return found;
        }
        match self.edge_near(&mut cols.wall_below(), seed) {
            (Some(e), axis) if e.curvature > SIGMAS * e.curvature_std => (Some(e), axis),
            (_, axis) => (None, axis),
        }
    }

    /// Whether the edge fit `e` saw a clean top: its step model not taken
    /// and at most a tenth of the columns its span samples left out (the
    /// share beyond which the fit counts something on the edge and tests
    /// the step model). A seed away from the match is taken only then: where
    /// something crosses the top (a cable, a shelf's edge, a highlight), a
    /// match that found no edge may have matched on that, and an edge found
    /// near it may be that (on the sweep's dirty photos: edges 0.9-1.5 px
    /// off, written where they had been refused).
    fn clean(&self, e: &EdgeFit) -> bool {
        let sampled = matcher::sampled_columns(self.edge_settings.half_span_px);
        !e.two_sided && 10 * e.columns >= 9 * sampled
    }

    /// The bubble's axis over the whole region's width (less the slope
    /// margin) from the free edge fit `edge`, searched near the axis of the
    /// frames before when known, and the apex refitted on it
    /// ([`matcher::edge_fit_about`]). Without a known axis, the free fit
    /// stays when the axis is not found; with one, an edge that is not
    /// mirror-symmetric about a column near it (or too few of whose columns
    /// are left about that column) is not the bubble's top (a cable or a
    /// shelf edge across it), and no edge is returned.
    fn on_axis(
        &self,
        cols: &mut matcher::Columns,
        edge: EdgeFit,
    ) -> (Option<EdgeFit>, Option<(f64, f64)>) {
        let half = (cols.width() / 2).saturating_sub(1);
        let near = self.last.map(|l| l[0] + self.apex_in_t[0]);
        let axis = matcher::axis_fit_in(cols, &edge, near, half);
        let on_axis =
            axis.and_then(|a| matcher::edge_fit_about(cols, a, &edge, self.edge_settings));
        match (on_axis, near) {
            (Some(e), _) => (Some(e), axis),
            (None, None) => (Some(edge), axis),
            (None, Some(_)) => (None, axis),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A JPEG's block boundaries lie between rows `8 k - 1` and `8 k`
    /// (at `8 k - 0.5`): an edge within `BLOCK_REACH_PX` of one gets the
    /// block term in quadrature, one mid-block and a PNG's the floor alone,
    /// a video's always the block term; all fall as the columns grow.
    #[test]
    fn the_block_term_joins_the_floor_near_a_jpeg_block_boundary() {
        let both = EDGE_BIAS_FLOOR_PX.hypot(JPEG_BLOCK_PX);
        let n = FLOOR_COLUMNS as usize;
        // 383.72 is 0.22 px below the boundary at 383.5; 387.5 is mid-block
        for (row, want) in [
            (383.72, both),
            (382.9, both),
            (381.1, EDGE_BIAS_FLOOR_PX),
            (387.5, EDGE_BIAS_FLOOR_PX),
            (-0.4, both),
        ] {
            let got = edge_floor_px(Blocks::Jpeg, row, n);
            assert!(
                (got - want).abs() < 1e-15,
                "row {row}: {got} against {want}"
            );
        }
        assert_eq!(edge_floor_px(Blocks::None, 383.72, n), EDGE_BIAS_FLOOR_PX);
        assert_eq!(edge_floor_px(Blocks::Unknown, 387.5, n), both);
        // twice the columns, half the floor
        let half = edge_floor_px(Blocks::None, 387.5, 2 * n);
        assert!((half - 0.5 * EDGE_BIAS_FLOOR_PX).abs() < 1e-15, "{half}");
    }

    /// A file is taken for a JPEG by its first bytes, not its name.
    #[test]
    fn a_jpeg_is_known_by_its_first_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let jpeg = dir.path().join("photo.png");
        std::fs::write(&jpeg, [0xFF, 0xD8, 0xFF, 0xE0, 0, 16]).unwrap();
        let png = dir.path().join("photo.jpg");
        std::fs::write(&png, [0x89, b'P', b'N', b'G', 0x0D, 0x0A]).unwrap();
        assert_eq!(Blocks::of_photo(&jpeg), Blocks::Jpeg);
        assert_eq!(Blocks::of_photo(&png), Blocks::None);
        assert_eq!(
            Blocks::of_photo(&dir.path().join("missing.jpg")),
            Blocks::None
        );
    }
}
