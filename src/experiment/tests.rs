use super::*;

/// `[window]` reads as a circle by default, an ellipse or a rectangle
/// by `shape`; unknown keys and non-positive sizes are refused.
#[test]
fn window_table() {
    let base = "[specimen]\nradius_m = 0.01875\nthickness_m = 0.00035\npoisson = 0.45\n";
    let dir = tempfile::tempdir().unwrap();
    let read = |extra: &str| {
        let p = dir.path().join("e.toml");
        std::fs::write(&p, format!("{base}{extra}")).unwrap();
        Experiment::read(&p).map(|e| e.window)
    };
    assert_eq!(read("").unwrap(), Window::Circle);
    assert_eq!(
        read("[window]\nshape = \"ellipse\"\nsemi_axes_m = [0.0375, 0.01875]\n").unwrap(),
        Window::Ellipse {
            semi_axes_m: [0.0375, 0.01875]
        }
    );
    assert_eq!(
        read("[window]\nshape = \"rectangle\"\nlength_m = 0.08\nwidth_m = 0.02\n").unwrap(),
        Window::Rectangle {
            length_m: 0.08,
            width_m: 0.02
        }
    );
    for (extra, needle) in [
        (
            "[window]\nshape = \"ellipse\"\nsemi_axes_m = [0.0375, 0.0]\n",
            "semi_axes_m = 0",
        ),
        (
            "[window]\nshape = \"rectangle\"\nlength_m = 0.08\nwidth = 0.02\n",
            "width",
        ),
        ("[window]\nshape = \"hexagon\"\n", "hexagon"),
    ] {
        let e = read(extra).unwrap_err().to_string();
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
}

/// The standard deviations of every table read, converted, and a bad
/// one refused with its table, key and value.
#[test]
fn uncertainty_inputs_read_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("e.toml");
    let base = "[specimen]\nradius_m = 0.04\nthickness_m = 0.0004\npoisson = 0.45\nthickness_std_m = 1.2e-5\nradius_std_m = 2e-4\n\
        [calibration]\npoints_px = [[0.0, 0.0], [300.0, 400.0]]\ndistance_m = 0.1\nmetres_per_pixel_std = 4e-7\nclamp_row_std_px = 0.5\n\
        [pressure]\ncsv = \"p.csv\"\nstd_pa = 3.0\nrelative_std = 0.0025\n";
    std::fs::write(&path, base).unwrap();
    let e = Experiment::read(&path).unwrap();
    let u = e.uncertainty();
    // scale 0.1 m / 500 px = 2e-4 m/px
    assert!((u.scale_relative_std - 2e-3).abs() < 1e-15);
    assert!((u.height_offset_std_m - 1e-4).abs() < 1e-15);
    assert_eq!(u.offset_scale_per_m, 0.0);
    // the scale read at the clamp row: -0.004 per px is -0.004 / 2e-4 m
    let shared = base.replace(
        "clamp_row_std_px = 0.5\n",
        "clamp_row_std_px = 0.5\nscale_per_clamp_row = -0.004\n",
    );
    std::fs::write(&path, &shared).unwrap();
    let k = Experiment::read(&path)
        .unwrap()
        .uncertainty()
        .offset_scale_per_m;
    assert!((k + 20.0).abs() < 1e-9, "{k}");
    std::fs::write(&path, shared.replace("-0.004", "nan")).unwrap();
    let err = Experiment::read(&path).unwrap_err().to_string();
    assert!(err.contains("scale_per_clamp_row = NaN"), "{err}");
    std::fs::write(&path, base).unwrap();
    assert_eq!(
        (u.thickness_std_m, u.radius_std_m, u.pressure_std_pa),
        (1.2e-5, 2e-4, 3.0)
    );
    assert_eq!(u.pressure_relative_std, 0.0025);
    assert_eq!(Experiment::read_specimen(&path).unwrap().thickness_m, 4e-4);
    std::fs::write(&path, base.replace("std_pa = 3.0", "std_pa = -3.0")).unwrap();
    let m = Experiment::read(&path).unwrap_err().to_string();
    assert!(m.contains("[pressure] std_pa = -3"), "{m}");
    std::fs::write(&path, base.replace("1.2e-5", "0.001")).unwrap();
    let m = Experiment::read(&path).unwrap_err().to_string();
    assert!(m.contains("thickness_std_m = 0.001"), "{m}");
}

#[test]
fn specimen_defaults_and_validation() {
    let s: Specimen =
        toml::from_str("radius_m = 0.0375\nthickness_m = 0.00035\npoisson = 0.45").unwrap();
    assert_eq!(s.prebulge_height_m, 0.0);
    assert!(s.validate().is_ok());
    let bad = Specimen { poisson: 0.5, ..s };
    assert!(
        bad.validate()
            .unwrap_err()
            .to_string()
            .contains("poisson = 0.5")
    );
    let bad = Specimen { radius_m: 0.0, ..s };
    assert!(bad.validate().unwrap_err().to_string().contains("radius_m"));
    let bad = Specimen {
        thickness_m: -1.0,
        ..s
    };
    assert!(
        bad.validate()
            .unwrap_err()
            .to_string()
            .contains("thickness_m")
    );
}
