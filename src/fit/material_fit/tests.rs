use super::*;
use crate::fit::hyperelastic::Equibiaxial;
use crate::material::StrainMeasure;

/// Modulus-law data: engineering strain and secant modulus.
fn modulus_data(strain: &[f64], modulus: &[f64]) -> Loaded {
    Loaded {
        source: Source::Raw,
        equibiaxial: Equibiaxial {
            stretch: strain.iter().map(|e| 1.0 + e).collect(),
            stress_pa: strain.iter().zip(modulus).map(|(e, m)| e * m).collect(),
            measure: StressMeasure::Nominal,
        },
        stress_column: "nominal_stress_pa".into(),
        strain: strain.to_vec(),
        modulus_pa: modulus.iter().map(|&m| Some(m)).collect(),
        modulus_std_pa: vec![None; strain.len()],
        shifts: vec![None; strain.len()],
        strain_measure: StrainMeasure::Engineering,
        lines: (2..2 + strain.len() as u64).collect(),
    }
}

#[test]
fn model_names_round_trip() {
    for name in [
        "quartic",
        "neo-hookean",
        "mooney-rivlin",
        "yeoh",
        "ogden-1",
        "ogden-2",
        "ogden-3",
        "gent",
        "all",
    ] {
        let m: FitModel = name.parse().unwrap();
        assert_eq!(m.to_string(), name);
    }
    assert_eq!(
        "ogden".parse::<FitModel>().unwrap(),
        FitModel::Hyperelastic(Kind::Ogden(3))
    );
    let e = "ogdne".parse::<FitModel>().unwrap_err().to_string();
    assert!(e.contains("ogdne") && e.contains("mooney-rivlin"), "{e}");
}

/// A quartic law recovered exactly from its own values, with the
/// provenance saying what was fitted.
#[test]
fn quartic_from_exact_data() {
    let c = [1.0e6, -2.0e5, 3.0e5, 1.0e4, -5.0e3];
    let strain: Vec<f64> = (0..12).map(|i| 0.02 + 0.04 * i as f64).collect();
    let modulus: Vec<f64> = strain.iter().map(|&e| quartic::eval(&c, e)).collect();
    let data = modulus_data(&strain, &modulus);
    let f = fit_material(&data, &FitSettings::default(), "exact").unwrap();
    let Model::Quartic {
        coefficients_pa, ..
    } = &f.material.model
    else {
        panic!("not a quartic")
    };
    for (a, b) in coefficients_pa.iter().zip(&c) {
        assert!((a - b).abs() < 1e-6 * 1e6, "{a} vs {b}");
    }
    let p = f.provenance();
    assert_eq!(
        (p.points, p.degree, p.source.as_str()),
        (12, Some(4), "exact")
    );
    assert!(p.r2.unwrap() > 1.0 - 1e-12);
}

/// Too few points: refused, or the degree lowered when asked.
#[test]
fn few_points_lower_the_degree_only_when_asked() {
    let strain = [0.1, 0.2, 0.3];
    let data = modulus_data(&strain, &[1.0e6, 1.1e6, 1.3e6]);
    assert!(matches!(
        fit_material(&data, &FitSettings::default(), "x"),
        Err(FitError::TooFewPoints { .. })
    ));
    let s = FitSettings {
        lower_degree: true,
        ..FitSettings::default()
    };
    let f = fit_material(&data, &s, "x").unwrap();
    assert_eq!(f.model, FitModel::Quartic { degree: 2 });
    assert!(f.warnings[0].contains("degree lowered from 4 to 2"));
}
