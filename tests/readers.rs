//! Every file reader, fed any bytes, returns a value or an error: never a
//! panic.
//!
//! Kinds of input, for every reader: arbitrary bytes; a valid file with a
//! few bytes replaced, inserted or cut; and, for TOML, lines assembled from
//! the keys, table headers and values the file formats use, and valid files
//! with some values swapped for those (so that parsing succeeds often and
//! the checks behind it run on odd values: NaN, negatives, empty lists, huge
//! integers, wrong types).

use std::path::{Path, PathBuf};

use bulge::io::Table;
use bulge::sim::scene::Scene;
use bulge::{Experiment, Material};
use proptest::prelude::*;

const CASES: u32 = 128;

const VALID_CSV: &str = "pressure_pa,height_m,file\n# comment\n1000,0.002,a.png\n2000, 0.003 ,\"b,c.png\"\n\n3000,,d.png\n";

const VALID_EXPERIMENT: &str = r#"[specimen]
radius_m = 0.0375
thickness_m = 0.00035
poisson = 0.45

[photos]
dir = "photos"
glob = "*.png"
roi_px = [10, 10, 200, 100]
template_rect_px = [50, 40, 20, 20]

[calibration]
metres_per_pixel = 1.0e-4

[pressure]
csv = "pressure.csv"

[simulate]
models = ["tp"]
"#;

const VALID_MATERIAL: &str = r#"model = "ogden"
poisson = 0.45
mu_pa = [630000.0, 1200.0]
alpha = [1.3, 5.0]

[fit]
r2 = 0.99
rmse_pa = 120.0

[fit.refined]
method = "axisym"
"#;

const VALID_SCENE: &str = r#"kind = "disc"
radius_m = 0.0375
thickness_m = 0.00035
pressure_pa = [5000, 7300, 8940]
material = "material.toml"

[mesh]
accuracy = 0.005
symmetry = true
"#;

const KEYS: &[&str] = &[
    "kind",
    "radius_m",
    "thickness_m",
    "poisson",
    "prebulge_height_m",
    "pressure_pa",
    "density_kg_m3",
    "material",
    "model",
    "young_pa",
    "c1_pa",
    "c2_pa",
    "c3_pa",
    "mu_pa",
    "alpha",
    "jm",
    "coefficients_pa",
    "strain_range",
    "strain_measure",
    "edge_length_m",
    "nodes",
    "accuracy",
    "symmetry",
    "corners",
    "length_m",
    "width_m",
    "at",
    "force_n",
    "dir",
    "glob",
    "roi_px",
    "template",
    "template_rect_px",
    "reference_frame",
    "apex_in_template_px",
    "metres_per_pixel",
    "points_px",
    "distance_m",
    "clamp_row_px",
    "csv",
    "r2",
    "possion",
    "\"quoted key\"",
];

const HEADERS: &[&str] = &[
    "[specimen]",
    "[photos]",
    "[calibration]",
    "[pressure]",
    "[material]",
    "[mesh]",
    "[[load]]",
    "[fit]",
    "[fit.refined]",
    "[simulate]",
    "[specimen.extra]",
    "[[specimen]]",
];

const VALUES: &[&str] = &[
    "0",
    "-0.0",
    "-5",
    "1",
    "3",
    "0.45",
    "0.5",
    "1.0e6",
    "1e308",
    "-1e-308",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "true",
    "\"\"",
    "\"disc\"",
    "\"sheet\"",
    "\"sphere-segment\"",
    "\"corner\"",
    "\"middle\"",
    "\"linear\"",
    "\"quartic\"",
    "\"neo-hookean\"",
    "\"mooney-rivlin\"",
    "\"yeoh\"",
    "\"ogden\"",
    "\"gent\"",
    "\"log\"",
    "\"engineering\"",
    "\"material.toml\"",
    "\"missing.toml\"",
    "\"*.png\"",
    "[]",
    "[1]",
    "[0, 0.5]",
    "[0.5, 0]",
    "[1e6, -5e6]",
    "[1, 2, 3, 4]",
    "[nan, inf]",
    "[\"II\", \"I\", \"I\"]",
    "[0.0, 0.0, -1.0]",
    "[[1, 2], [3, 4]]",
    "[10, 10, 200, 100]",
    "{ a = 1 }",
    "1979-05-27",
];

const CELLS: &[&str] = &[
    "pressure_pa",
    "height_m",
    "file",
    "1000",
    "-0",
    "1e400",
    "NaN",
    "inf",
    "",
    " ",
    "\"a,b\"",
    "\"",
    "#",
    "abc",
    "0x10",
    "\u{feff}x",
];

/// Arbitrary bytes, biased to short files.
fn bytes() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(any::<u8>(), 0..400)
}

/// A valid text with up to 8 edits: replace, insert or delete a byte, or
/// cut the rest.
fn mutated(valid: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let edit = (0u8..4, any::<prop::sample::Index>(), any::<u8>());
    prop::collection::vec(edit, 0..8).prop_map(move |edits| {
        let mut b = valid.as_bytes().to_vec();
        for (op, at, byte) in edits {
            let n = b.len();
            match op {
                0 if n > 0 => b[at.index(n)] = byte,
                1 => b.insert(at.index(n + 1), byte),
                2 if n > 0 => {
                    b.remove(at.index(n));
                }
                3 => b.truncate(at.index(n + 1)),
                _ => {}
            }
        }
        b
    })
}

/// Lines of `key = value` and table headers from the formats' vocabulary.
fn toml_soup() -> impl Strategy<Value = Vec<u8>> {
    let line = prop_oneof![
        4 => (prop::sample::select(KEYS), prop::sample::select(VALUES))
            .prop_map(|(k, v)| format!("{k} = {v}")),
        1 => prop::sample::select(HEADERS).prop_map(str::to_string),
    ];
    prop::collection::vec(line, 0..16).prop_map(|lines| (lines.join("\n") + "\n").into_bytes())
}

/// Rows of CSV cells from a small vocabulary, with ragged lengths.
fn csv_soup() -> impl Strategy<Value = Vec<u8>> {
    let row = prop::collection::vec(prop::sample::select(CELLS), 0..5).prop_map(|c| c.join(","));
    prop::collection::vec(row, 0..8).prop_map(|rows| rows.join("\n").into_bytes())
}

/// A valid text with the values of some `key = value` lines swapped for
/// values from the vocabulary.
fn revalued(valid: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let n = valid.lines().count();
    prop::collection::vec(prop::option::weighted(0.3, prop::sample::select(VALUES)), n).prop_map(
        move |swaps| {
            let mut out = String::new();
            for (line, swap) in valid.lines().zip(swaps) {
                match (line.split_once(" = "), swap) {
                    (Some((k, _)), Some(v)) => out.push_str(&format!("{k} = {v}")),
                    _ => out.push_str(line),
                }
                out.push('\n');
            }
            out.into_bytes()
        },
    )
}

fn any_toml(valid: &'static str) -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![bytes(), mutated(valid), toml_soup(), revalued(valid)]
}

/// Writes `bytes` as `name` in a fresh folder (beside a valid material file,
/// for scenes that name one) and calls `read` on it.
fn with_file<T>(name: &str, bytes: &[u8], read: impl FnOnce(&Path) -> T) -> T {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("material.toml"), VALID_MATERIAL).unwrap();
    let p: PathBuf = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    read(&p)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn csv_table_never_panics(b in prop_oneof![bytes(), mutated(VALID_CSV), csv_soup()]) {
        with_file("heights.csv", &b, |p| {
            if let Ok(t) = Table::read(p) {
                // every cell, as a number and as an optional number
                for name in t.headers.clone() {
                    let _ = t.numbers(&name);
                    let _ = t.optional_numbers(&name);
                }
                for r in 0..t.len() {
                    for c in 0..t.headers.len() + 1 {
                        let _ = t.cell(r, c);
                    }
                }
                let _ = t.require("pressure_pa");
            }
        });
    }

    #[test]
    fn experiment_never_panics(b in any_toml(VALID_EXPERIMENT)) {
        with_file("experiment.toml", &b, |p| {
            if let Ok(e) = Experiment::read(p) {
                prop_assert!(e.specimen.validate().is_ok());
            }
            Ok(())
        })?;
    }

    #[test]
    fn material_never_panics(b in any_toml(VALID_MATERIAL)) {
        with_file("m.toml", &b, |p| {
            if let Ok(m) = Material::read(p) {
                prop_assert!(m.validate().is_ok());
                // what was read is usable: the energy is defined at rest
                if let Some(h) = m.model.hyperelastic() {
                    prop_assert!(h.w(1.0, 1.0).abs() < 1e-6 * m.model.initial_young_pa().abs().max(1.0));
                }
            }
            Ok(())
        })?;
    }

    #[test]
    fn scene_never_panics(b in any_toml(VALID_SCENE)) {
        with_file("scene.toml", &b, |p| {
            let _ = Scene::read(p);
        });
    }
}

/// The valid files above are valid (so that the mutations start from
/// somewhere meaningful).
#[test]
fn the_seeds_read() {
    with_file("heights.csv", VALID_CSV.as_bytes(), |p| {
        let t = Table::read(p).unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t.cell(1, 2), "b,c.png");
    });
    with_file("experiment.toml", VALID_EXPERIMENT.as_bytes(), |p| {
        Experiment::read(p).unwrap();
    });
    with_file("m.toml", VALID_MATERIAL.as_bytes(), |p| {
        Material::read(p).unwrap();
    });
    with_file("scene.toml", VALID_SCENE.as_bytes(), |p| {
        Scene::read(p).unwrap();
    });
}
