//! The edge fit started away from the top: the template's match or the
//! frames' prediction can miss a grown dome's top by more than a column's
//! search reaches.

use super::super::matcher::tests::coverage;
use super::super::matcher::{EdgeSettings, Extremes};
use super::super::tracker::Tracker;
use super::*;

/// A dark dome on a light wall, its top `y = y0 + k (x - xa)^2` blurred by
/// a Gaussian of 1.2 px, drawn by coverage (8x8 samples a pixel).
fn dome(w: usize, h: usize, xa: f64, y0: f64, k: f64) -> image::Gray {
    let mut data = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let cov = coverage(x, y, (xa, y0, k), 1.2);
            data[y * w + x] = (200.0 - 140.0 * cov).round() as u8;
        }
    }
    image::Gray {
        width: w,
        height: h,
        data,
        tone: image::Tone::LINEAR,
    }
}

#[test]
fn the_top_is_found_from_a_seed_a_dozen_px_off() {
    let (w, h, xa, y0, k) = (240, 200, 120.3, 80.4, 0.004);
    let img = dome(w, h, xa, y0, k);
    // The template: 96x48 px around the top, the apex at its middle.
    let (tx, ty) = (72usize, 57usize);
    let templ = image::Gray {
        width: 96,
        height: 48,
        data: (ty..ty + 48)
            .flat_map(|y| img.data[y * w + tx..y * w + tx + 96].to_vec())
            .collect(),
        tone: image::Tone::LINEAR,
    };
    let opts = Options::default();
    let state = Tracker {
        templ: &templ,
        opts: &opts,
        edge_settings: EdgeSettings {
            half_span_px: 48,
            half_window_px: opts.edge_window_px,
        },
        apex_in_t: [xa - tx as f64, y0 - ty as f64],
        reduced: None,
        last: None,
        prev: None,
        curvature: 2.0 * k,
        blocks: crate::track::tracker::Blocks::None,
        origin_row_px: 0.0,
    };
    let none = Extremes {
        fullest: None,
        emptiest: None,
        is_emptiest: false,
    };
    // 12 px below the top (a prediction that missed a growing step) and
    // 9 px above it (a small dome's template on a flatter one): each
    // column's search from there sees no step within its window.
    for off in [12.0, -9.0] {
        let l = state
            .locate_at(&img, none, [xa, y0 + off])
            .unwrap()
            .unwrap_or_else(|| panic!("no edge found from {off:+} px"));
        let e = l.edge.unwrap();
        assert!(
            (e.y - y0).abs() < 0.05,
            "from {off:+} px: apex row {} against {y0}",
            e.y
        );
    }
}
