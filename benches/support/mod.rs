//! What the photo benchmarks share: the synthetic camera and specimen.

use bulge::experiment::Specimen;
use bulge::track::image::Encoding;
use bulge::track::synth::SequenceSpec;

/// A `w` x `h` sequence of the default specimen (a = 37.5 mm, t = 0.35
/// mm), default framing, plain look, exposure drift 3 %.
pub fn spec(w: usize, h: usize, seed: u64, blur: f64, noise: f64, enc: Encoding) -> SequenceSpec {
    SequenceSpec {
        width: w,
        height: h,
        seed,
        blur_px: blur,
        noise_grey: noise,
        drift: 0.03,
        encoding: enc,
        specimen: Specimen {
            radius_m: 0.0375,
            thickness_m: 0.00035,
            poisson: 0.45,
            prebulge_height_m: 0.0,
        },
        framing: Default::default(),
        look: Default::default(),
        window: Default::default(),
    }
}
