//! The cheap closed loop: a synthetic experiment with known truth through the
//! whole pipeline, the simulated heights against the true ones.

mod support;

mod tests {
    use super::support::closed_loop::*;
    use bulge::experiment::Specimen;
    use bulge::material::{Material, Model};
    use bulge::pipeline::Settings;

    /// The cheap closed loop: one material the demo does not use
    /// (Mooney-Rivlin), 8 noisy 320x240 photos. The full study is
    /// `examples/closed_loop.rs` (docs/run.md). Bounds: the tracked heights
    /// within 0.5 % of the truth; TP MSS within 2 % of the true heights at
    /// every pressure (the target) and closer to the truth than Van
    /// Gelder; without the correction of the law to the heights, the
    /// spherical-cap method's own bias puts TP MSS more than 1 % off.
    #[test]
    fn closed_loop_mooney_rivlin() {
        let case = Case {
            name: "mooney-rivlin".into(),
            material: Material {
                model: Model::MooneyRivlin {
                    c1_pa: 0.12e6,
                    c2_pa: 0.03e6,
                },
                poisson: 0.45,
                fit: None,
            },
            specimen: Specimen {
                radius_m: 0.0375,
                thickness_m: 0.00035,
                poisson: 0.45,
                prebulge_height_m: 0.0,
            },
            frames: 8,
            top_fraction: 0.9,
            p_max_pa: 6000.0,
            size: [320, 240],
            noise: (2.0, 1.0, None),
            seed: 301,
        };
        // the paper's chain: the quartic E(eps), corrected to the heights
        let settings = Settings {
            fit: bulge::fit::FitModel::Quartic { degree: 4 },
            ..Settings::default()
        };
        let dir = tempfile::tempdir().unwrap();
        let d = draw(&case, dir.path(), &settings).unwrap();
        assert_eq!(d.truth.len(), 8);
        let o = evaluate(&d, &settings).unwrap();
        let track_max = o
            .tracking_errors
            .iter()
            .map(|e| e.abs())
            .fold(0.0, f64::max);
        assert!(track_max < 0.005, "tracking error {track_max}");
        let tp = o.max_abs(TP);
        let vg = o.max_abs(VAN_GELDER);
        assert!(tp < 0.02, "TP MSS worst error {tp}");
        assert!(tp < vg, "TP {tp} vs Van Gelder {vg}");
        let cap_only = Settings {
            refine: false,
            ..settings.clone()
        };
        let o_cap = evaluate(&d, &cap_only).unwrap();
        let tp_cap = o_cap.max_abs(TP);
        assert!(
            tp_cap > 0.01 && tp_cap > 2.0 * tp,
            "TP without the correction {tp_cap}, with {tp}"
        );
        assert_eq!(
            o.errors.len(),
            3,
            "tp, van-gelder and the axisymmetric reference"
        );
    }
}
