//! The plausibility guards on their own.

/// The guards on their own: an apex below the clamp plane, one that moves
/// against the pressure, one far from the prediction, and an edge whose
/// curvature or columns do not follow the dome's are refused with the
/// reason; a plausible next apex is accepted.
#[test]
fn the_plausibility_guards_refuse_what_a_dome_cannot_do() {
    use crate::track::decode::Guard;
    use crate::track::matcher::EdgeFit;
    let edge = |curvature: f64, rms: f64, columns: usize| EdgeFit {
        y: 0.0,
        y_std: 0.02,
        x_vertex: 100.0,
        x_std: 0.5,
        curvature,
        curvature_std: 1e-5,
        y_curvature_cov: 0.0,
        columns,
        rms,
        two_sided: false,
        clutter_on_top: false,
    };
    // Clamp plane at row 200; apexes at heights 40, 50 px (curvature per px
    // of height 2e-5).
    let mut g = Guard::new(Some(200.0), None, 64, false);
    g.accept(
        100.0,
        [100.0, 160.0],
        [0.5, 0.02],
        Some(&edge(8e-4, 0.1, 120)),
    );
    g.accept(
        200.0,
        [100.0, 150.0],
        [0.5, 0.02],
        Some(&edge(1e-3, 0.1, 120)),
    );
    let ok = g.check(
        300.0,
        [100.2, 141.0],
        [0.5, 0.02],
        Some(&edge(1.18e-3, 0.1, 120)),
    );
    assert!(ok.is_ok(), "{ok:?}");
    let err = |apex: [f64; 2], e: EdgeFit| g.check(300.0, apex, [0.5, 0.02], Some(&e)).unwrap_err();
    let why = |apex: [f64; 2], e: EdgeFit| err(apex, e).to_string();
    assert!(why([100.0, 201.0], edge(1e-3, 0.1, 120)).contains("clamp plane"));
    assert!(why([100.0, 152.0], edge(1e-3, 0.1, 120)).contains("against the pressure"));
    assert!(
        why([100.0, 120.0], edge(1.6e-3, 0.1, 120))
            .contains("from where the frames before predict")
    );
    assert!(why([100.0, 141.0], edge(1e-5, 0.1, 120)).contains("curvature"));
    assert!(why([100.0, 141.0], edge(1.18e-3, 1.5, 120)).contains("columns disagree"));
    // The residual rule alone is no physical bound: it says how to keep
    // the frame; a physical rule does not.
    let residual = err([100.0, 141.0], edge(1.18e-3, 1.5, 120));
    assert!(
        g.kept_warning(&residual, 300.0, 141.0, 0.02)
            .is_some_and(|w| w.contains("kept, since every physical rule holds"))
    );
    let below = err([100.0, 201.0], edge(1e-3, 0.1, 120));
    assert!(
        g.kept_warning(&below, 300.0, 201.0, 0.02).is_none(),
        "{below}"
    );
    assert!(why([100.0, 141.0], edge(1.18e-3, 0.1, 40)).contains("columns against"));
    assert!(why([130.0, 141.0], edge(1.18e-3, 0.1, 120)).contains("apex column moved"));
}
