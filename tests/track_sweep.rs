//! A small, deterministic slice of the tracker's sweep over the synthetic
//! world (`cargo run --release --example track_sweep`; table in
//! docs/track.md). The full sweep measures, per level of every factor
//! (size, noise, blur, encoding, ring face, light bubble, side light,
//! defocus, motion blur, vignetting, highlight, law, photo count, top
//! pressure), how many clean photos are refused, how many are written
//! silently wrong and whether the stated uncertainty is honest. This test
//! runs thirty clean sequences at 480x360 and asserts only what holds now
//! and must keep holding: every sequence is tracked, no photo is written
//! more than 4 of its stated standard deviations off (the tracker refuses a
//! photo rather than write it silently wrong), and RMS(error / stated std)
//! lies within the sweep's goal of 0.8-1.2.

use bulge::track::synth::{HighlightShape, sweep};

/// The dirty case of `seed` at `size` with the highlight the sweep drew
/// before its place, size and lobe varied ([`HighlightShape::default`]):
/// the photos the tests below were written about.
fn dirty_as_first_drawn(seed: u64, size: (usize, usize)) -> sweep::Case {
    let mut case = sweep::draw(seed, true, &[size]).expect("the law's bubble is solved");
    case.spec.look.highlight = HighlightShape::default();
    case
}

#[test]
fn no_clean_photo_of_the_sweep_is_written_silently_wrong() {
    let mut written = 0;
    let mut z2 = 0.0;
    let mut refused = Vec::new();
    for seed in 1..=30u64 {
        let case = sweep::draw(seed, false, &[(480, 360)]).expect("the law's bubble is solved");
        let dir = tempfile::tempdir().unwrap();
        let photos = sweep::run(&case, dir.path());
        assert_eq!(photos.len(), case.frames.len());
        for p in &photos {
            match (p.written, &p.refused) {
                (Some((e, s)), _) => {
                    written += 1;
                    z2 += (e / s).powi(2);
                    assert!(
                        (e / s).abs() <= 4.0,
                        "seed {seed}, frame {}: apex row {e:+.3} px off, stated std {s:.3} px ({:?})",
                        p.frame,
                        case.levels
                    );
                }
                (None, Some(why)) => {
                    assert!(
                        !why.starts_with("not written") && !why.starts_with("tracking failed"),
                        "seed {seed}: {why}"
                    );
                    refused.push((seed, p.frame, why.clone()));
                }
                (None, None) => unreachable!("a photo is written or refused"),
            }
        }
    }
    let rms = (z2 / written.max(1) as f64).sqrt();
    eprintln!("{written} photos written, RMS(error/std) {rms:.2}; refused: {refused:#?}");
    assert!(written > 0);
    // The stated error is the size of the error: RMS(error / stated std)
    // within the sweep's goal of 0.8-1.2.
    assert!((0.8..=1.2).contains(&rms), "RMS(error/std) {rms:.2}");
}

/// Seed 11 of the sweep (640x480, Mooney-Rivlin, 12 photos to 0.97 of the
/// limit pressure): near the limit its last step of the height is more
/// than twice the one extrapolated from the two photos before, which no
/// membrane law forbids (`dh/dp` grows without bound at a limit point). The
/// photo is written, within 4 of its stated standard deviations, not
/// refused.
#[test]
fn a_coarse_step_near_the_limit_pressure_is_not_refused() {
    let case = sweep::draw(11, false, &[(640, 480)]).expect("the law's bubble is solved");
    let dir = tempfile::tempdir().unwrap();
    for p in sweep::run(&case, dir.path()) {
        let (e, s) = p
            .written
            .unwrap_or_else(|| panic!("frame {} refused: {:?}", p.frame, p.refused));
        assert!(
            (e / s).abs() <= 4.0,
            "frame {}: {e:+.3} px off, std {s:.3} px",
            p.frame
        );
    }
}

/// Three dirty sequences of the sweep with a light dome before a dark wall
/// whose highlight's flank rises through the edge's window and peaks
/// beyond it (seeds 1000225 and 1000215 at 800x600, 1000111 at 640x480):
/// the centroids are pulled 0.1-0.6 px into the dome. Every photo written
/// is within 4 of its stated standard deviations.
#[test]
fn a_light_domes_highlight_peaking_under_the_window_is_stated() {
    for (seed, size) in [
        (1_000_225, (800, 600)),
        (1_000_215, (800, 600)),
        (1_000_111, (640, 480)),
    ] {
        let case = dirty_as_first_drawn(seed, size);
        let dir = tempfile::tempdir().unwrap();
        let photos = sweep::run(&case, dir.path());
        let written = written_within_4_sd(seed, &photos);
        // (none of them refused when measured: the test is not passed by
        // refusing them)
        assert!(
            2 * written >= photos.len(),
            "seed {seed}: {written} of {} photos written",
            photos.len()
        );
    }
}

/// Two dirty sequences of the sweep with a highlight against the top of a
/// dark dome, beside the apex (seed 1000113 at 640x480, frame 4; seed
/// 1000105 at 800x600, frame 2): columns under it are left out, and its
/// halo, lighter towards the outline, lifts the kept ones; the apex was
/// written 0.17-0.23 px towards the wall at 4.2-4.5 stated deviations
/// before the glossy rim's bound was taken there too. Every photo written
/// is within 4 of its stated standard deviations.
#[test]
fn a_highlight_against_a_dark_domes_top_is_stated() {
    for (seed, size, frame) in [(1_000_113, (640, 480), 4), (1_000_105, (800, 600), 2)] {
        let case = dirty_as_first_drawn(seed, size);
        let dir = tempfile::tempdir().unwrap();
        let photos = sweep::run(&case, dir.path());
        let (e, s) = photos[frame]
            .written
            .unwrap_or_else(|| panic!("seed {seed}, frame {frame} refused"));
        // the photo that was 4.2-4.5 deviations off, still as far off
        assert!(e.abs() > 0.1, "seed {seed}, frame {frame}: {e:+.3} px off");
        written_within_4_sd(seed, &photos);
        eprintln!("seed {seed}, frame {frame}: {e:+.3} px off, std {s:.3} px");
    }
}

/// Two dirty sequences of the sweep (640x480) whose dark dome's top grows
/// into a blurred cable behind it, a trough 25-35 grey levels deep whose
/// neighbouring rows differ by less than the line limit: seed 1000346's
/// third photo, whose top runs along the cable's lower flank, was written
/// 2.7 px high at a stated 0.096 px (28 deviations); seed 1000438's first
/// photo, with the cable 6 rows above its top and no emptier photo to
/// tell the two apart, 0.90 px off at 11 deviations. Both are now left out
/// by name, and every photo written is within 4 of its stated standard
/// deviations.
#[test]
fn a_top_grown_into_a_blurred_cable_is_left_out_by_name() {
    for (seed, frame, why) in [
        (1_000_346, 2, "no edge of the bubble's top"),
        (1_000_438, 0, "lowest pressure"),
    ] {
        let case = dirty_as_first_drawn(seed, (640, 480));
        let dir = tempfile::tempdir().unwrap();
        let photos = sweep::run(&case, dir.path());
        let refused = photos[frame].refused.as_deref().unwrap_or_else(|| {
            panic!(
                "seed {seed}, frame {frame} written: {:?}",
                photos[frame].written
            )
        });
        assert!(
            refused.contains(why),
            "seed {seed}, frame {frame}: {refused}"
        );
        let written = written_within_4_sd(seed, &photos);
        assert!(
            2 * written >= photos.len(),
            "seed {seed}: {written} of {} photos written",
            photos.len()
        );
    }
}

/// The photos of seed `seed` written, each asserted within 4 of its stated
/// standard deviations.
fn written_within_4_sd(seed: u64, photos: &[sweep::Photo]) -> usize {
    let mut written = 0;
    for p in photos {
        if let Some((e, s)) = p.written {
            written += 1;
            assert!(
                (e / s).abs() <= 4.0,
                "seed {seed}, frame {}: {e:+.3} px off, std {s:.3} px",
                p.frame
            );
        }
    }
    written
}
