//! Sub-pixel accuracy on clean photos (noise, blur, JPEG, sizes) and
//! experiments tracked at once.

use super::*;

// Seeds 101.. are used by tests only; the benchmarks use seeds 1..=3.
#[test]
fn sub_pixel_apex_without_noise() {
    let a = accuracy(&spec(101, 0.0, 0.0, image::Encoding::Png), 10, Refine::Edge);
    assert_row_rms(&a, 0.05);
}

/// A 1280x960 sequence: the 128 px template is searched at a quarter of
/// the resolution for the edge fit's seed; the integer mode searches at
/// half resolution first, then matches at full resolution near the
/// coarse peak.
#[test]
fn coarse_to_fine_search_on_larger_photos() {
    let s = synth::SequenceSpec {
        width: 1280,
        height: 960,
        ..spec(103, 1.5, 3.0, image::Encoding::Jpeg(85))
    };
    let a = accuracy(&s, 6, Refine::Edge);
    assert_row_rms(&a, 0.1);
    // The full-resolution integer match (after the coarse search at
    // half resolution) is right to a pixel.
    let i = accuracy(&s, 6, Refine::Integer);
    assert!(
        i.integer[1] <= 1.0,
        "integer match row error {} px",
        i.integer[1]
    );
}

/// 4000x3000 photos (the 400 px template searched at 1/8 of the
/// resolution for the edge fit's seed). Slow in a debug build (drawing
/// the photos): `cargo test --lib -- --ignored large_photos`.
#[test]
#[ignore]
fn sub_pixel_apex_on_large_photos() {
    let s = synth::SequenceSpec {
        width: 4000,
        height: 3000,
        ..spec(104, 1.0, 2.0, image::Encoding::Jpeg(90))
    };
    let a = accuracy(&s, 6, Refine::Edge);
    assert_row_rms(&a, 0.1);
}

#[test]
fn sub_pixel_apex_with_noise_blur_and_jpeg() {
    let a = accuracy(
        &spec(102, 1.5, 3.0, image::Encoding::Jpeg(85)),
        10,
        Refine::Edge,
    );
    assert_row_rms(&a, 0.1);
}

/// Several experiments tracked at once, each on threads of its own (as a
/// program tracking several folders does): every run gives exactly what
/// the experiment gives alone. OpenCV's thread count is a process-wide
/// setting, made once; made by every run, two runs setting it at the same
/// moment crashed the process.
#[test]
fn experiments_tracked_at_once_give_what_each_gives_alone() {
    let dirs: Vec<_> = [121u64, 122]
        .iter()
        .map(|&seed| {
            let dir = tempfile::tempdir().unwrap();
            let s = spec(seed, 1.0, 2.0, image::Encoding::Png);
            let frames = synth::cap_frames(s.specimen.radius_m, 0.5 * s.specimen.radius_m, 6);
            synth::write_sequence(dir.path(), &s, &frames).unwrap();
            dir
        })
        .collect();
    let run = |dir: &Path| tracked_in(dir, &Options::default()).unwrap();
    let alone: Vec<Tracked> = dirs.iter().map(|d| run(d.path())).collect();
    assert!(alone.iter().all(|t| t.rows.len() == 6));
    std::thread::scope(|scope| {
        let runs: Vec<_> = (0..4)
            .map(|k| {
                let dir = dirs[k % 2].path();
                scope.spawn(move || (k % 2, (0..3).map(|_| run(dir)).collect::<Vec<_>>()))
            })
            .collect();
        for r in runs {
            let (i, tracked) = r.join().unwrap();
            for t in tracked {
                assert_eq!(
                    t.rows, alone[i].rows,
                    "experiment {i} tracked beside others"
                );
                assert_eq!(t.skipped, alone[i].skipped, "experiment {i}");
            }
        }
    });
}
