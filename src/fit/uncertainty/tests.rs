use super::*;

/// Every point's change for each input's error against what the cap
/// formulas say without derivatives: every stress is `p` times a
/// function of the geometry over `t` (so the thickness and the gauge
/// move it in proportion and leave the strains), and the formulas are
/// homogeneous in lengths (a radius and height scaled together leave
/// the strains and scale the radius of curvature, the stresses and the
/// modulus in proportion).
#[test]
fn point_shifts_follow_the_scaling_of_the_cap_formulas() {
    let spec = crate::experiment::Specimen {
        radius_m: 0.0375,
        thickness_m: 0.0005,
        poisson: 0.45,
        prebulge_height_m: 0.002,
    };
    let sources = Sources {
        pressure_std_pa: 3.0,
        pressure_relative_std: 0.004,
        thickness_std_m: 1.5e-5,
        radius_std_m: 2e-4,
        scale_relative_std: 2e-4 / 0.0375,
        height_offset_std_m: 3e-5,
        ..Sources::default()
    };
    for opts in [
        mechanics::Options::default(),
        mechanics::Options {
            strain: mechanics::StrainMeasure::Log,
            true_stress: mechanics::TrueStress::Incompressible,
            modulus: mechanics::Modulus::Uniaxial,
            modulus_stress: mechanics::ModulusStress::True,
        },
    ] {
        for (p, h) in [(800.0, 0.009), (3000.0, 0.021), (6000.0, 0.05)] {
            let pt = mechanics::Point {
                pressure_pa: p,
                height_m: h,
                height_std_m: Some(1e-5),
            };
            let v = mechanics::stress_strain(&spec, &opts, &[pt]).unwrap()[0].value;
            let got = point_shifts(&spec, &opts, &pt, &sources).unwrap();
            let of = |k: SourceKind| got.iter().find(|(g, _)| *g == k).unwrap().1;
            let close = |a: Option<f64>, b: Option<f64>, tol: f64| {
                let (a, b) = (a.unwrap(), b.unwrap());
                assert!(
                    (a - b).abs() <= tol * b.abs().max(1e-300),
                    "{a} against {b}"
                );
            };
            let stresses = |d: Derived| [d.stress_pa, d.true_stress_pa, d.secant_modulus_pa];
            // The gauge and the thickness: the stresses in proportion,
            // exactly (the gauge) or to first order (the thickness).
            let (noise, gain, thick) = (
                of(SourceKind::PressureNoise),
                of(SourceKind::PressureGain),
                of(SourceKind::Thickness),
            );
            for (k, q) in stresses(v).into_iter().enumerate() {
                close(stresses(noise)[k], q.map(|q| q * 3.0 / p), 1e-12);
                close(stresses(gain)[k], q.map(|q| q * 0.004), 1e-12);
                close(stresses(thick)[k], q.map(|q| -q * 1.5e-5 / 0.0005), 1e-8);
            }
            for d in [noise, gain, thick] {
                assert_eq!((d.stretch, d.strain), (Some(0.0), Some(0.0)));
            }
            // Lengths: the radius's change plus the heights' (prebulge
            // included) in the same proportion is the value times its
            // degree in length (0 for strains, 1 for the radius of
            // curvature and the stresses, which are p R / t).
            let r = of(SourceKind::Radius);
            let f = 2e-4 / 0.0375;
            let with_heights = |h: f64, h0: f64| {
                let s = crate::experiment::Specimen {
                    prebulge_height_m: h0,
                    ..spec
                };
                let d = mechanics::height_derivatives(&s, &opts, p, h);
                // the derivative in h0 at fixed h by a central difference
                let e = 1e-7 * h0;
                let at = |h0: f64| {
                    let s = crate::experiment::Specimen {
                        prebulge_height_m: h0,
                        ..spec
                    };
                    mechanics::stress_strain(
                        &s,
                        &opts,
                        &[mechanics::Point {
                            height_std_m: None,
                            ..pt
                        }],
                    )
                    .unwrap()[0]
                        .value
                };
                (d, at(h0 + e), at(h0 - e), e)
            };
            let (dh, up, down, e) = with_heights(h, spec.prebulge_height_m);
            let total = |x: Option<f64>, dx: Option<f64>, u: Option<f64>, w: Option<f64>| {
                Some(x? + dx? * h * f + (u? - w?) / (2.0 * e) * spec.prebulge_height_m * f)
            };
            let tol = 1e-6;
            let strain = total(r.strain, dh.strain, up.strain, down.strain).unwrap();
            assert!(
                strain.abs() < tol * v.strain.unwrap() * f,
                "strain moved {strain}"
            );
            close(
                total(r.radius_m, dh.radius_m, up.radius_m, down.radius_m),
                v.radius_m.map(|q| q * f),
                tol,
            );
            close(
                total(r.stress_pa, dh.stress_pa, up.stress_pa, down.stress_pa),
                v.stress_pa.map(|q| q * f),
                tol,
            );
            // The scale and the clamp row move the height alone.
            let sd = |k: SourceKind| of(k).strain.unwrap() / dh.strain.unwrap();
            assert!((sd(SourceKind::Scale) / (h * f) - 1.0).abs() < 1e-12);
            assert!((sd(SourceKind::HeightOffset) / 3e-5 - 1.0).abs() < 1e-12);
            // An offset that moves the scale read at it: d (1 + k h).
            let with_scale = Sources {
                offset_scale_per_m: -10.0,
                ..sources
            };
            let got = point_shifts(&spec, &opts, &pt, &with_scale).unwrap();
            let off = got.iter().find(|(g, _)| *g == SourceKind::HeightOffset);
            let moved = off.unwrap().1.strain.unwrap() / dh.strain.unwrap();
            assert!((moved / (3e-5 * (1.0 - 10.0 * h)) - 1.0).abs() < 1e-12);
            assert!((sd(SourceKind::Points) / 1e-5 - 1.0).abs() < 1e-12);
        }
    }
}

/// Quantiles against printed tables: the normal (Abramowitz & Stegun
/// 1964, table 26.5) and Student's t (table 26.10; Fisher & Yates).
#[test]
fn quantiles_match_the_tables() {
    assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-12);
    assert!((normal_quantile(0.5)).abs() < 1e-15);
    assert!((normal_quantile(0.001) + 3.090_232_306_167_813).abs() < 1e-10);
    assert!((normal_quantile(1e-10) + 6.361_340_902_404_056).abs() < 1e-8);
    for (dof, want) in [
        (1.0, 12.706_204_736),
        (2.0, 4.302_652_730),
        (5.0, 2.570_581_836),
        (10.0, 2.228_138_852),
        (30.0, 2.042_272_456),
    ] {
        let t = student_t_quantile(0.975, dof);
        assert!((t - want).abs() < 1e-6, "dof {dof}: {t} vs {want}");
    }
    assert!((student_t_quantile(0.975, 1e6) - 1.959_966).abs() < 1e-5);
}

/// A straight line with known errors: the response's covariance is
/// `(X^T X)^-1` for unit errors (by hand: X = [1 0; 1 1; 1 2]), and a
/// shared offset moves only the intercept, by exactly its size.
#[test]
fn sandwich_by_hand() {
    let j = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0]);
    let mut s = DMatrix::zeros(3, 4);
    for i in 0..3 {
        s[(i, i)] = 1.0;
        s[(i, 3)] = 0.5;
    }
    let a = -response(&j, &s).unwrap();
    let u = ParamUncertainty {
        names: vec!["b".into(), "m".into()],
        values: vec![1.0, 2.0],
        response: a,
        dome_response: None,
        sources: vec![
            SourceKind::Points,
            SourceKind::Points,
            SourceKind::Points,
            SourceKind::HeightOffset,
        ],
        dof: 1,
        sigma_known: true,
        chi2: 0.0,
        weighted: true,
        readings_pa: vec![],
    };
    let pts = u.std_errors_from(SourceKind::Points);
    assert!((pts[0] - (5.0f64 / 6.0).sqrt()).abs() < 1e-14);
    assert!((pts[1] - 0.5f64.sqrt()).abs() < 1e-14);
    let off = u.std_errors_from(SourceKind::HeightOffset);
    assert!((off[0] - 0.5).abs() < 1e-14 && off[1].abs() < 1e-14);
    // A prediction that carries the same offset itself is unmoved by it.
    let g = [1.0, 1.0];
    let with = u.prediction_std(&g, &[(SourceKind::HeightOffset, 0.5)]);
    let pts_only = {
        let c = (5.0 / 6.0) + 0.5 - 2.0 * 0.5;
        f64::sqrt(c)
    };
    assert!((with - pts_only).abs() < 1e-14, "{with} vs {pts_only}");
}
