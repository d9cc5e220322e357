//! Steps 1 and 2 of `bulge init`: what moves between the first and the last
//! photo (the band the bubble's top swept), the axis from the last photo's
//! sides, the sides followed down to the clamp, and the refusal of a
//! shrinking series.

use super::*;

/// The region the top of the bubble swept between two photos.
pub(super) struct Swept {
    /// The band with its thin gaps closed, row-major.
    pub(super) joined: Vec<bool>,
    /// Per row: the leftmost and rightmost column of the region.
    pub(super) rows: Vec<Option<(usize, usize)>>,
    /// Per column: the top and bottom row of the region.
    pub(super) cols: Vec<Option<(usize, usize)>>,
    /// +1 where the bubble is lighter than what it covers, -1 where darker.
    pub(super) sign: f64,
}

/// The largest 8-connected region of `mask` (row-major `w x h`).
fn largest_region(mask: &[bool], w: usize, h: usize) -> Vec<usize> {
    let mut seen = vec![false; mask.len()];
    let mut best: Vec<usize> = Vec::new();
    let mut stack = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] || seen[start] {
            continue;
        }
        let mut region = Vec::new();
        seen[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            region.push(i);
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if mask[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        if region.len() > best.len() {
            best = region;
        }
    }
    best
}

/// The mask dilated by a square of half-side `r` (two running sums).
fn dilate(mask: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    let mut rows = vec![false; w * h];
    let mut sums = vec![0u32; w.max(h) + 1];
    for y in 0..h {
        for x in 0..w {
            sums[x + 1] = sums[x] + u32::from(mask[y * w + x]);
        }
        for x in 0..w {
            let (a, b) = (x.saturating_sub(r), (x + r + 1).min(w));
            rows[y * w + x] = sums[b] > sums[a];
        }
    }
    let mut out = vec![false; w * h];
    for x in 0..w {
        for y in 0..h {
            sums[y + 1] = sums[y] + u32::from(rows[y * w + x]);
        }
        for y in 0..h {
            let (a, b) = (y.saturating_sub(r), (y + r + 1).min(h));
            out[y * w + x] = sums[b] > sums[a];
        }
    }
    out
}

/// Step 1: what moved between the first and the last photo.
pub(super) fn swept(first: &Plane, last: &Plane, names: [&Path; 2]) -> Result<Swept, TrackError> {
    let (w, h) = (first.w, first.h);
    let (f, l) = (first.box3(), last.box3());
    let stride = (w * h / 200_000).max(1);
    let mut ratios: Vec<f64> =
        f.v.iter()
            .zip(&l.v)
            .step_by(stride)
            .filter(|(a, _)| **a > 10.0)
            .map(|(a, b)| f64::from(*b / *a))
            .collect();
    let gain = quantile(&mut ratios, 0.5) as f32;
    let d: Vec<f32> = l.v.iter().zip(&f.v).map(|(b, a)| b - gain * a).collect();
    let mut s = sample(&d, stride);
    let sigma = robust_sd(&mut s);
    let mut mags: Vec<f64> = s.iter().map(|v| v.abs()).collect();
    let contrast = quantile(&mut mags, 0.995);
    let thr = (6.0 * sigma).max(0.35 * contrast).max(3.0);
    let sum: f64 = d
        .iter()
        .filter(|v| f64::from(v.abs()) > thr)
        .map(|&v| f64::from(v))
        .sum();
    let sign = sum.signum() as f32;
    let mask: Vec<bool> = d.iter().map(|&v| f64::from(v * sign) > thr).collect();
    // A cable or a shelf edge in front of the band's background cuts it
    // into pieces: the pieces a thin line apart are joined (the regions of
    // the mask dilated by a few px), and the band is the mask's pixels in
    // the largest of them.
    let reach = (0.006 * w.max(h) as f64).max(3.0).round() as usize;
    let joined = largest_region(&dilate(&mask, w, h, reach), w, h);
    let mut in_joined = vec![false; w * h];
    for &i in &joined {
        in_joined[i] = true;
    }
    let region: Vec<usize> = joined.iter().copied().filter(|&i| mask[i]).collect();
    let min_area = ((w * h) as f64 * 2e-4).max(30.0) as usize;
    if sum == 0.0 || region.len() < min_area {
        return Err(TrackError::NotFound {
            what: "the bubble".into(),
            detail: format!(
                "the first photo ({}) and the last ({}) do not differ beyond their noise ({:.1} grey levels) over more than {} px: the bubble does not grow in these photos",
                names[0].display(),
                names[1].display(),
                sigma,
                region.len()
            ),
            keys: "roi_px, template_rect_px, apex_in_template_px, clamp_row_px and metres_per_pixel",
            clamp_plane: false,
        });
    }
    let mut rows = vec![None; h];
    let mut cols = vec![None; w];
    for &i in &region {
        let (x, y) = (i % w, i / w);
        let r: &mut Option<(usize, usize)> = &mut rows[y];
        *r = Some(r.map_or((x, x), |(a, b)| (a.min(x), b.max(x))));
        let c: &mut Option<(usize, usize)> = &mut cols[x];
        *c = Some(c.map_or((y, y), |(a, b)| (a.min(y), b.max(y))));
    }
    Ok(Swept {
        joined: in_joined,
        rows,
        cols,
        sign: f64::from(sign),
    })
}

/// A photo's top on the axis where it lies below the swept band's first
/// run there, or `None` where the photo's profile `p` (rows, on the axis)
/// steps at that run's lowest row `from` as a top does (the step 2 guess
/// stands). The band stops where the largest bubble's side matches what
/// it covers: a mid-grey dome whose lower part is lit to the wall's grey
/// (a path-traced 1024x768 scene seen 10 degrees from above: the band's
/// run on the axis ended at row 341, the first photo's top at 415). Below
/// it the top is the first row where the profile steps by the bubble's
/// sign (`sign`, +1 for a bubble lighter than the wall) and stays there,
/// down to row `to` (the clamp): the mean of the 3 rows below against the
/// 3 above, and of the 5 rows from 4 below (a line across the wall
/// returns to the background there). A step counts beyond 6 standard
/// deviations of the same step over the rows `bg` (the wall above the
/// largest top, in every photo): the swept band's own noise criterion
/// ([`swept`]), here on the profile. The row counts (3 either side, 5
/// from 4 below) are chosen, not derived (3 is about the widest blur the
/// sweep draws, 2.8 px, [`super::clamp::CORNER_PX`]'s reckoning). On
/// the init sweep (250 clean and 100 dirty sequences) and the camera grid
/// the search below was never entered; it is measured on the one
/// path-traced scene above and the tests below only.
pub(super) fn top_below_band(
    p: &[f64],
    bg: std::ops::Range<usize>,
    from: usize,
    to: usize,
    sign: f64,
) -> Option<f64> {
    let mean = |a: usize, b: usize| p[a..=b].iter().sum::<f64>() / (b + 1 - a) as f64;
    let step = |r: usize| sign * (mean(r + 1, r + 3) - mean(r - 3, r - 1));
    let stays = |r: usize| sign * (mean(r + 4, r + 8) - mean(r - 3, r - 1));
    let to = to.min(p.len().saturating_sub(9));
    if bg.end < bg.start + 16 || from < 6 || from + 4 > to {
        return None;
    }
    let mut steps: Vec<f64> = (bg.start + 3..bg.end - 9).map(step).collect();
    let thr = 6.0 * robust_sd(&mut steps);
    if (from - 3..=from + 3).any(|r| step(r) > thr) {
        return None;
    }
    let mut r = from + 4;
    while r <= to {
        if step(r) > thr {
            // the steepest of the step's rows, where it must stay
            let best = (r..=(r + 3).min(to)).max_by(|&a, &b| step(a).total_cmp(&step(b)))?;
            if stays(best) > thr {
                return Some(best as f64);
            }
            r = best;
        }
        r += 1;
    }
    None
}

/// The axis from the last photo's silhouette: the median midpoint of its
/// two sides, located to sub-pixel precision in the rows of the middle of
/// the swept band (where a side is steep), with its standard error.
pub(super) fn refine_axis(
    last: &Plane,
    sw: &Swept,
    x0: f64,
    top: usize,
    bottom: usize,
) -> Option<(f64, f64)> {
    let w = last.w as i64;
    let span = (bottom - top) as f64;
    let rows = (top as f64 + 0.2 * span) as usize..=(top as f64 + 0.6 * span) as usize;
    let mut mids = Vec::new();
    for r in rows {
        let Some((l, rt)) = sw.rows[r] else { continue };
        let p = |x: i64| last.at(x.clamp(0, w - 1) as usize, r);
        let edge = |start: usize| profile_edge(p, w, start as f64, 3.0).map(|e| e.0);
        if let (Some(a), Some(b)) = (edge(l), edge(rt))
            && (a - l as f64).abs() < 3.0
            && (b - rt as f64).abs() < 3.0
        {
            mids.push(0.5 * (a + b));
        }
    }
    if mids.len() < 5 {
        return None;
    }
    let mut m = mids.clone();
    let med = quantile(&mut m, 0.5);
    if (med - x0).abs() > 3.0 {
        return None;
    }
    let mut dev: Vec<f64> = mids.iter().map(|v| (v - med).abs()).collect();
    let sd = 1.4826 * quantile(&mut dev, 0.5);
    Some((med, 1.2533 * sd.max(0.02) / (mids.len() as f64).sqrt()))
}

/// Follows a side of the silhouette from row `r0` (column `x`) down, row
/// by row, while it stays a strong step moving outward (`dir` -1 left, +1
/// right) or straight down, over gaps of up to 6 rows (a cable crossing
/// it); returns where it ends: about the clamp plane and the opening's edge.
pub(super) fn follow_side(img: &Plane, x: f64, r0: usize, dir: f64) -> Option<(f64, f64)> {
    let (w, h) = (img.w as i64, img.h);
    let mut x = x;
    let mut slope = 0.0;
    let mut last = None;
    let mut steps: Vec<f64> = Vec::new();
    let mut gap = 0;
    for r in r0..h.saturating_sub(8) {
        let p = |c: i64| img.at(c.clamp(0, w - 1) as usize, r);
        let pred = x + slope;
        let found = profile_edge(p, w, pred, 3.0).filter(|(e, st)| {
            let reference = if steps.len() >= 3 {
                let mut v = steps.clone();
                quantile(&mut v, 0.5)
            } else {
                st.abs()
            };
            (e - pred).abs() < 2.5 && (e - x) * dir > -1.0 && st.abs() > 0.5 * reference
        });
        // Beside the side, a step down the column that stays (not a thin
        // line crossing it) is the clamp's top edge: the side ends there.
        if let Some((e, _)) = found
            && steps.len() >= 3
        {
            let q = (e + dir * 5.0).round() as i64;
            let col = |y: usize| img.at(q.clamp(0, w - 1) as usize, y.min(h - 1));
            let reach = 12usize;
            let below = (r + 3..r + 3 + reach).map(col).sum::<f64>() / reach as f64;
            let above = (r.saturating_sub(4)..r.saturating_sub(1))
                .map(col)
                .sum::<f64>()
                / 3.0;
            let mut v = steps.clone();
            if (below - above).abs() > 0.5 * quantile(&mut v, 0.5) {
                last = Some((e, r as f64));
                break;
            }
        }
        match found {
            Some((e, st)) => {
                if steps.len() < 40 {
                    steps.push(st.abs());
                }
                slope = 0.7 * slope + 0.3 * (e - x);
                x = e;
                last = Some((e, r as f64));
                gap = 0;
            }
            None => {
                gap += 1;
                if gap > 6 {
                    break;
                }
                x = pred;
            }
        }
    }
    last
}

/// Refuses a series in which the bubble shrinks. On the axis, the rows
/// between the two photos' apexes show the wall in the photo with the
/// smaller bubble and the bubble in the other: if the first photo's light
/// there is the wall's (the rows above both apexes) the bubble grew; if the
/// last photo's is, it shrank (a deflation, or photos in reverse order),
/// and every apex init would place is the wrong photo's.
pub(super) fn shrinking_check(
    first: &[f64],
    last: &[f64],
    wall_rows: &std::ops::Range<usize>,
    band: std::ops::RangeInclusive<usize>,
    names: [&Path; 2],
) -> Result<(), TrackError> {
    let median = |v: &mut Vec<f64>| quantile(v, 0.5);
    let wall = median(&mut first[wall_rows.clone()].to_vec());
    let off = |p: &[f64]| median(&mut band.clone().map(|r| (p[r] - wall).abs()).collect());
    let (off_first, off_last) = (off(first), off(last));
    // the wall's own spread above the apexes: the noise of this comparison
    let spread = median(&mut wall_rows.clone().map(|r| (first[r] - wall).abs()).collect());
    if off_first > 3.0 * off_last && off_first - off_last > 6.0 * spread.max(1e-3 * wall) {
        return Err(TrackError::Config {
            path: names[1].to_path_buf(),
            message: format!(
                "above the bubble's top this last photo shows the wall where the first ({}) shows the bubble: the bubble shrinks in this series (a deflation, or photos in reverse order); give the photos in the order of rising pressure (name them so, or use a glob that sorts them so)",
                names[0].display()
            ),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::top_below_band;

    /// A profile down the axis: a wall at 200 grey levels with a slow
    /// gradient and a deterministic ripple of +-1.5 (noise), and from row
    /// `top` a dome `step` lighter (negative: darker).
    fn profile(top: usize, step: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|r| {
                let ripple = 1.5 * ((r as f64 * 2.399).sin() + (r as f64 * 0.731).cos()) / 2.0;
                let wall = 200.0 - 0.02 * r as f64 + ripple;
                wall + if r >= top { step } else { 0.0 }
            })
            .collect()
    }

    #[test]
    fn a_top_below_the_band_is_found_where_the_profile_steps_and_stays() {
        // a dark dome's top 74 rows below the band's lowest row, as on the
        // scene seen 10 degrees from above
        let p = profile(415, -40.0, 600);
        let top = top_below_band(&p, 0..260, 341, 520, -1.0).expect("a top below the band");
        assert!((top - 415.0).abs() <= 1.0, "top at {top}, drawn at 415");
        // a light dome on the same wall
        let p = profile(415, 40.0, 600);
        let top = top_below_band(&p, 0..260, 341, 520, 1.0).expect("a top below the band");
        assert!((top - 415.0).abs() <= 1.0, "top at {top}, drawn at 415");
    }

    #[test]
    fn a_top_at_the_band_s_lowest_row_stands_and_a_step_of_the_other_sign_is_no_top() {
        // the photo steps at the band's lowest row: step 2's guess stands
        let p = profile(341, -40.0, 600);
        assert_eq!(top_below_band(&p, 0..260, 341, 520, -1.0), None);
        // a dome lighter than the wall is not a dark bubble's top
        let p = profile(415, 40.0, 600);
        assert_eq!(top_below_band(&p, 0..260, 341, 520, -1.0), None);
    }

    #[test]
    fn a_line_across_the_wall_is_passed_over() {
        // a dark line 3 rows wide at rows 380-382 (a cable), then the top
        let mut p = profile(450, -40.0, 600);
        for v in &mut p[380..=382] {
            *v -= 60.0;
        }
        let top = top_below_band(&p, 0..260, 341, 520, -1.0).expect("a top below the band");
        assert!((top - 450.0).abs() <= 1.0, "top at {top}, drawn at 450");
    }
}
