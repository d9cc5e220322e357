//! Strict reading of material files: every key known, every value of the
//! right type and in range.
//!
//! Unknown keys are refused with the nearest valid name ("did you mean
//! `poisson`?") or, for a parameter of another model, the models that take
//! it. The `[fit]` table (free-form provenance written by `bulge fit`,
//! including `[fit.refined]`) is accepted as it is.

use std::fmt::Write as _;
use std::path::Path;

use super::{Material, Model, StrainMeasure};
use crate::io::{InputError, nearest_name, toml_error};

/// A problem with a material: the key, the value and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    /// No `model = "..."`.
    #[error(
        "missing key `model`: add it, e.g. `model = \"neo-hookean\"` (one of {})",
        model_list()
    )]
    MissingModel,
    /// `model` names no model.
    #[error(
        "`model = {value}` is not a model{}: use one of {}",
        suggestion.map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default(),
        model_list()
    )]
    UnknownModel {
        /// The value as written.
        value: String,
        /// The nearest model name, if one is close.
        suggestion: Option<&'static str>,
    },
    /// A key that this model does not take.
    #[error("{}", unknown_key(key, model, suggestion, owners))]
    UnknownKey {
        /// The key as written.
        key: String,
        /// The model of the file.
        model: &'static str,
        /// The nearest valid key, if one is close.
        suggestion: Option<&'static str>,
        /// Other models that take this key.
        owners: Vec<&'static str>,
    },
    /// A required key is absent.
    #[error("missing key `{key}` for model \"{model}\": add it, e.g. `{key} = {example}`")]
    MissingKey {
        /// The key.
        key: &'static str,
        /// The model of the file.
        model: &'static str,
        /// An example value.
        example: &'static str,
    },
    /// A value of the wrong type.
    #[error("`{key} = {value}`: expected {expected}, e.g. `{key} = {example}`")]
    WrongType {
        /// The key.
        key: &'static str,
        /// The value as written.
        value: String,
        /// What was expected.
        expected: &'static str,
        /// An example value.
        example: &'static str,
    },
    /// A value out of range, or values inconsistent with each other.
    #[error("`{key} = {value}`: {fix}")]
    Invalid {
        /// The key (or keys).
        key: String,
        /// The value as written.
        value: String,
        /// What is wrong and how to fix it.
        fix: String,
    },
    /// Any other problem found while decoding.
    #[error("{0}")]
    Other(String),
}

fn model_list() -> String {
    Model::NAMES
        .iter()
        .map(|n| format!("\"{n}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

fn unknown_key(
    key: &str,
    model: &str,
    suggestion: &Option<&'static str>,
    owners: &[&'static str],
) -> String {
    let mut s = format!("unknown key `{key}`");
    if !owners.is_empty() {
        let _ = write!(
            s,
            " for model \"{model}\" (it takes {}): `{key}` is a parameter of {}; remove it or change the model",
            keys_of(model)
                .iter()
                .map(|k| format!("`{}`", k.name))
                .collect::<Vec<_>>()
                .join(", "),
            owners.join(", ")
        );
    } else if let Some(sug) = suggestion {
        let _ = write!(s, ": did you mean `{sug}`?");
    } else {
        let _ = write!(
            s,
            ": remove it (the keys of model \"{model}\" are {})",
            allowed(model)
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    s
}

/// What a key holds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Number,
    List,
    Pair,
    Name,
}

impl Kind {
    fn expected(self) -> &'static str {
        match self {
            Kind::Number => "a number",
            Kind::List => "a list of numbers",
            Kind::Pair => "a list of two numbers, [min, max]",
            Kind::Name => "a name in quotes",
        }
    }

    fn accepts(self, v: &toml::Value) -> bool {
        let number = |v: &toml::Value| matches!(v, toml::Value::Integer(_) | toml::Value::Float(_));
        match (self, v) {
            (Kind::Number, v) => number(v),
            (Kind::List, toml::Value::Array(a)) => a.iter().all(number),
            (Kind::Pair, toml::Value::Array(a)) => a.len() == 2 && a.iter().all(number),
            (Kind::Name, toml::Value::String(_)) => true,
            _ => false,
        }
    }
}

#[derive(Debug)]
struct Key {
    name: &'static str,
    kind: Kind,
    required: bool,
    example: &'static str,
}

const fn key(name: &'static str, kind: Kind, example: &'static str) -> Key {
    Key {
        name,
        kind,
        required: true,
        example,
    }
}

/// Keys of every material file, whatever the model (`fit` is free-form).
const COMMON: &[Key] = &[
    key("model", Kind::Name, "\"neo-hookean\""),
    key("poisson", Kind::Number, "0.45"),
];

/// The keys of `Material` outside the model: those in [`COMMON`] and the
/// free-form `fit` table.
const MATERIAL_FIELDS: &[&str] = &["model", "poisson", "fit"];

/// The parameters of each model, as `Model` spells them.
fn keys_of(model: &str) -> &'static [Key] {
    const LINEAR: &[Key] = &[key("young_pa", Kind::Number, "1.0e6")];
    const QUARTIC: &[Key] = &[
        key("coefficients_pa", Kind::List, "[1.2e6, -1.0e6, 2.0e6]"),
        key("strain_range", Kind::Pair, "[0.0, 0.6]"),
        Key {
            name: "strain_measure",
            kind: Kind::Name,
            required: false,
            example: "\"engineering\"",
        },
    ];
    const NEO_HOOKEAN: &[Key] = &[key("c1_pa", Kind::Number, "180000.0")];
    const MOONEY_RIVLIN: &[Key] = &[
        key("c1_pa", Kind::Number, "180000.0"),
        key("c2_pa", Kind::Number, "18000.0"),
    ];
    const YEOH: &[Key] = &[
        key("c1_pa", Kind::Number, "180000.0"),
        key("c2_pa", Kind::Number, "-2000.0"),
        key("c3_pa", Kind::Number, "50.0"),
    ];
    const OGDEN: &[Key] = &[
        key("mu_pa", Kind::List, "[630000.0, 1200.0]"),
        key("alpha", Kind::List, "[1.3, 5.0]"),
    ];
    const GENT: &[Key] = &[
        key("mu_pa", Kind::Number, "350000.0"),
        key("jm", Kind::Number, "80.0"),
    ];
    match model {
        "linear" => LINEAR,
        "quartic" => QUARTIC,
        "neo-hookean" => NEO_HOOKEAN,
        "mooney-rivlin" => MOONEY_RIVLIN,
        "yeoh" => YEOH,
        "ogden" => OGDEN,
        "gent" => GENT,
        _ => &[],
    }
}

fn allowed(model: &str) -> impl Iterator<Item = &'static str> + '_ {
    MATERIAL_FIELDS
        .iter()
        .copied()
        .chain(keys_of(model).iter().map(|k| k.name))
}

impl Model {
    /// Every model name, as `material.toml` spells it.
    pub const NAMES: [&'static str; 7] = [
        "linear",
        "quartic",
        "neo-hookean",
        "mooney-rivlin",
        "yeoh",
        "ogden",
        "gent",
    ];

    /// Checks the parameters: finite, of the right sign, lists of matching
    /// lengths. The error names the key, the value and the fix.
    pub fn validate(&self) -> Result<(), MaterialError> {
        match self {
            Model::Linear { young_pa } => positive("young_pa", *young_pa, "Young's modulus"),
            Model::Quartic {
                coefficients_pa,
                strain_range,
                strain_measure: _,
            } => {
                if coefficients_pa.is_empty() {
                    return Err(invalid(
                        "coefficients_pa",
                        "[]",
                        "give at least c_0, the small-strain modulus in Pa, e.g. [1.2e6, -1.0e6, 2.0e6]",
                    ));
                }
                for (k, c) in coefficients_pa.iter().enumerate() {
                    finite(&format!("coefficients_pa[{k}]"), *c)?;
                }
                let [lo, hi] = *strain_range;
                if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                    return Err(invalid(
                        "strain_range",
                        &format!("[{lo}, {hi}]"),
                        "write the strain range the law was fitted over as [min, max], finite, with min < max",
                    ));
                }
                Ok(())
            }
            Model::NeoHookean { c1_pa } => positive("c1_pa", *c1_pa, "C1 (half the shear modulus)"),
            Model::MooneyRivlin { c1_pa, c2_pa } => {
                finite("c1_pa", *c1_pa)?;
                finite("c2_pa", *c2_pa)?;
                if c1_pa + c2_pa <= 0.0 {
                    return Err(invalid(
                        "c1_pa + c2_pa",
                        &format!("{c1_pa} + {c2_pa}"),
                        "the small-strain shear modulus 2 (C1 + C2) must be positive",
                    ));
                }
                Ok(())
            }
            Model::Yeoh {
                c1_pa,
                c2_pa,
                c3_pa,
            } => {
                positive("c1_pa", *c1_pa, "C1 (half the small-strain shear modulus)")?;
                finite("c2_pa", *c2_pa)?;
                finite("c3_pa", *c3_pa)
            }
            Model::Ogden { mu_pa, alpha } => {
                if mu_pa.len() != alpha.len() {
                    return Err(invalid(
                        "mu_pa, alpha",
                        &format!("{} and {} terms", mu_pa.len(), alpha.len()),
                        "give one alpha per mu (e.g. mu_pa = [630000.0, 1200.0], alpha = [1.3, 5.0])",
                    ));
                }
                if !(1..=3).contains(&mu_pa.len()) {
                    return Err(invalid(
                        "mu_pa",
                        &fmt_list(mu_pa),
                        "give 1 to 3 terms (one alpha per mu)",
                    ));
                }
                for (k, (m, a)) in mu_pa.iter().zip(alpha).enumerate() {
                    finite(&format!("mu_pa[{k}]"), *m)?;
                    finite(&format!("alpha[{k}]"), *a)?;
                    if *a == 0.0 {
                        return Err(invalid(
                            &format!("alpha[{k}]"),
                            "0",
                            "an exponent of 0 gives no stress (mu / alpha is undefined): drop the term or give it a non-zero alpha",
                        ));
                    }
                }
                let shear: f64 = mu_pa.iter().zip(alpha).map(|(m, a)| m * a).sum();
                if shear <= 0.0 {
                    return Err(invalid(
                        "mu_pa, alpha",
                        &format!("{} and {}", fmt_list(mu_pa), fmt_list(alpha)),
                        "the small-strain shear modulus sum(mu_i alpha_i) / 2 must be positive",
                    ));
                }
                Ok(())
            }
            Model::Gent { mu_pa, jm } => {
                positive("mu_pa", *mu_pa, "the shear modulus")?;
                positive(
                    "jm",
                    *jm,
                    "the locking parameter Jm (the largest I1 - 3 the chains allow, e.g. 80)",
                )
            }
        }
    }
}

fn fmt_list(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

fn invalid(key: &str, value: &str, fix: &str) -> MaterialError {
    MaterialError::Invalid {
        key: key.to_string(),
        value: value.to_string(),
        fix: fix.to_string(),
    }
}

fn finite(key: &str, v: f64) -> Result<(), MaterialError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            key,
            &v.to_string(),
            "not a finite number; write the measured or fitted value",
        ))
    }
}

fn positive(key: &str, v: f64, what: &str) -> Result<(), MaterialError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            key,
            &v.to_string(),
            &format!("{what} must be a positive finite number"),
        ))
    }
}

impl Material {
    /// Reads a material file strictly: unknown keys, values of the wrong
    /// type, and parameters out of range are refused with the file, the
    /// key, the value and the fix (see [`Material::from_table`]).
    pub fn read(path: impl AsRef<Path>) -> Result<Material, InputError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::file(path, format!("cannot read the file: {e}")))?;
        let table: toml::Table = toml::from_str(&text).map_err(|e| toml_error(path, &text, &e))?;
        Material::from_table(&table).map_err(|e| {
            let line = match &e {
                MaterialError::UnknownKey { key, .. } => line_of_key(&text, key),
                MaterialError::WrongType { key, .. } => line_of_key(&text, key),
                MaterialError::UnknownModel { .. } => line_of_key(&text, "model"),
                MaterialError::Invalid { key, .. } => {
                    let first = key.split([',', '[', ' ']).next().unwrap_or(key);
                    line_of_key(&text, first)
                }
                _ => None,
            };
            InputError {
                path: path.to_path_buf(),
                line,
                column: None,
                message: e.to_string(),
                setting: None,
            }
        })
    }

    /// A material from a parsed TOML table (a file, or a `[material]` table
    /// inside another file), checked as [`Material::read`] does.
    pub fn from_table(table: &toml::Table) -> Result<Material, MaterialError> {
        let model = match table.get("model") {
            None => return Err(MaterialError::MissingModel),
            Some(toml::Value::String(s)) => match Model::NAMES.iter().find(|n| **n == s) {
                Some(n) => *n,
                None => {
                    return Err(MaterialError::UnknownModel {
                        value: format!("\"{s}\""),
                        suggestion: nearest_name(s, Model::NAMES),
                    });
                }
            },
            Some(other) => {
                return Err(MaterialError::UnknownModel {
                    value: other.to_string(),
                    suggestion: None,
                });
            }
        };
        for (k, v) in table {
            if allowed(model).any(|a| a == k) {
                if let Some(spec) = COMMON.iter().chain(keys_of(model)).find(|s| s.name == k)
                    && !spec.kind.accepts(v)
                {
                    return Err(MaterialError::WrongType {
                        key: spec.name,
                        value: v.to_string(),
                        expected: spec.kind.expected(),
                        example: spec.example,
                    });
                }
                continue;
            }
            let owners: Vec<&'static str> = Model::NAMES
                .iter()
                .copied()
                .filter(|m| keys_of(m).iter().any(|s| s.name == k))
                .collect();
            return Err(MaterialError::UnknownKey {
                key: k.clone(),
                model,
                suggestion: nearest_name(k, allowed(model)),
                owners,
            });
        }
        for spec in COMMON.iter().chain(keys_of(model)) {
            if spec.required && !table.contains_key(spec.name) {
                return Err(MaterialError::MissingKey {
                    key: spec.name,
                    model,
                    example: spec.example,
                });
            }
        }
        if let Some(toml::Value::String(s)) = table.get("strain_measure")
            && ![StrainMeasure::Engineering, StrainMeasure::Log]
                .iter()
                .any(|m| m.name() == s)
        {
            return Err(invalid(
                "strain_measure",
                &format!("\"{s}\""),
                "use \"engineering\" (lambda - 1) or \"log\" (ln lambda)",
            ));
        }
        let m: Material = toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| MaterialError::Other(e.message().trim().to_string()))?;
        m.validate()?;
        Ok(m)
    }

    /// Checks the Poisson ratio and the model's parameters (see
    /// [`Model::validate`]).
    pub fn validate(&self) -> Result<(), MaterialError> {
        let nu = self.poisson;
        if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
            return Err(invalid(
                "poisson",
                &nu.to_string(),
                "the Poisson ratio must be in [0, 0.5) (rubber: 0.45 to 0.499; 0.5 is singular in the plane-stress formulas)",
            ));
        }
        self.model.validate()
    }
}

/// The 1-based line of a top-level `key = ...` (top-level keys come before
/// the first table header).
fn line_of_key(text: &str, key: &str) -> Option<u64> {
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if t.starts_with('[') {
            return None;
        }
        let t = t.trim_start_matches(['"', '\'']);
        if let Some(rest) = t.strip_prefix(key) {
            let rest = rest.trim_start_matches(['"', '\'']).trim_start();
            if rest.starts_with('=') {
                return Some(i as u64 + 1);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::tests::models;

    fn read_str(text: &str) -> Result<Material, crate::io::InputError> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("material.toml");
        std::fs::write(&p, text).unwrap();
        Material::read(&p)
    }

    fn all_models() -> Vec<Model> {
        let mut v = models();
        v.push(Model::Linear { young_pa: 1.0e6 });
        v.push(Model::Quartic {
            coefficients_pa: vec![1.2e6, -1.0e6, 2.0e6],
            strain_range: [0.0, 0.6],
            strain_measure: StrainMeasure::Log,
        });
        v
    }

    /// The key lists here and the fields of `Model` and `Material` agree:
    /// whatever is written reads back.
    #[test]
    fn every_written_material_reads_back() {
        for model in all_models() {
            let fit = crate::fit::Provenance {
                source: "test".into(),
                r2: Some(0.99),
                refined: Some(crate::fit::RefinedRecord {
                    method: "axisym".into(),
                    height_rms_before: Some(0.02),
                    height_rms_after: Some(0.005),
                    iterations: 3,
                    axisym_solves: 40,
                    cap_law: Some(Model::NeoHookean { c1_pa: 1.0e5 }),
                    constraint: None,
                    prebulge_height_m: Some(0.003),
                    uncertainty: None,
                }),
                ..Default::default()
            };
            let m = Material {
                model,
                poisson: 0.45,
                fit: Some(fit),
            };
            let text = toml::to_string(&m).unwrap();
            let back = read_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(back, m);
            // and every key written is one the spec knows, with its type
            let table: toml::Table = toml::from_str(&text).unwrap();
            for spec in keys_of(m.model.name()) {
                if spec.required {
                    assert!(table.contains_key(spec.name), "{}", spec.name);
                }
            }
        }
    }

    #[test]
    fn misspelt_key_gets_the_nearest_name() {
        let e = read_str("model = \"neo-hookean\"\npoisson = 0.45\npossion = 0.3\nc1_pa = 1e5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("material.toml, line 3"), "{e}");
        assert!(
            e.contains("unknown key `possion`: did you mean `poisson`?"),
            "{e}"
        );
        let e = read_str("model = \"neo-hookean\"\nposson = 0.45\nc1_pa = 1e5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("did you mean `poisson`?"), "{e}");
    }

    #[test]
    fn parameter_of_another_model_names_the_models_that_take_it() {
        let e = read_str("model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = 1e5\nc2_pa = 1e4\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown key `c2_pa`"), "{e}");
        assert!(e.contains("mooney-rivlin, yeoh"), "{e}");
        assert!(e.contains("remove it or change the model"), "{e}");
    }

    #[test]
    fn unknown_model_is_refused_with_suggestion() {
        let e = read_str("model = \"mooney_rivlin\"\npoisson = 0.45\nc1_pa = 1e5\nc2_pa = 1e4\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("did you mean `mooney-rivlin`?"), "{e}");
        let e = read_str("poisson = 0.45\nc1_pa = 1e5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing key `model`"), "{e}");
    }

    #[test]
    fn ogden_lists_must_match_and_hold_one_to_three_terms() {
        let e = read_str(
            "model = \"ogden\"\npoisson = 0.45\nmu_pa = [630000.0, 1200.0]\nalpha = [1.3]\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`mu_pa, alpha = 2 and 1 terms`"), "{e}");
        assert!(e.contains("one alpha per mu"), "{e}");
        let e = read_str("model = \"ogden\"\npoisson = 0.45\nmu_pa = []\nalpha = []\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("give 1 to 3 terms"), "{e}");
        let e = read_str(
            "model = \"ogden\"\npoisson = 0.45\nmu_pa = [1, 1, 1, 1]\nalpha = [1, 2, 3, 4]\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("give 1 to 3 terms"), "{e}");
        let e = read_str("model = \"ogden\"\npoisson = 0.45\nmu_pa = [1e5]\nalpha = [0]\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha[0] = 0"), "{e}");
    }

    #[test]
    fn signs_and_finiteness_are_checked() {
        let cases = [
            (
                "model = \"gent\"\npoisson = 0.45\nmu_pa = 3.5e5\njm = -5\n",
                "`jm = -5`",
            ),
            (
                "model = \"gent\"\npoisson = 0.45\nmu_pa = 0\njm = 80\n",
                "`mu_pa = 0`",
            ),
            (
                "model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = -1\n",
                "`c1_pa = -1`",
            ),
            (
                "model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = nan\n",
                "`c1_pa = NaN`",
            ),
            (
                "model = \"linear\"\npoisson = 0.5\nyoung_pa = 1e6\n",
                "`poisson = 0.5`",
            ),
            (
                "model = \"linear\"\npoisson = -0.1\nyoung_pa = 1e6\n",
                "`poisson = -0.1`",
            ),
            (
                "model = \"linear\"\npoisson = 0.3\nyoung_pa = inf\n",
                "`young_pa = inf`",
            ),
            (
                "model = \"quartic\"\npoisson = 0.45\ncoefficients_pa = [1e6, inf]\nstrain_range = [0, 0.5]\n",
                "`coefficients_pa[1] = inf`",
            ),
            (
                "model = \"quartic\"\npoisson = 0.45\ncoefficients_pa = [1e6]\nstrain_range = [0.5, 0.1]\n",
                "`strain_range = [0.5, 0.1]`",
            ),
            (
                "model = \"mooney-rivlin\"\npoisson = 0.45\nc1_pa = -2e5\nc2_pa = 1e5\n",
                "`c1_pa + c2_pa = -200000 + 100000`",
            ),
        ];
        for (text, want) in cases {
            let e = read_str(text).unwrap_err().to_string();
            assert!(e.contains("material.toml"), "{e}");
            assert!(e.contains(want), "{want}: {e}");
        }
        let e = read_str("model = \"gent\"\npoisson = 0.45\nmu_pa = 3.5e5\njm = -5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 4"), "{e}");
    }

    #[test]
    fn wrong_types_and_missing_keys_name_the_key() {
        let e = read_str("model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = \"a\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`c1_pa = \"a\"`: expected a number"), "{e}");
        let e = read_str(
            "model = \"quartic\"\npoisson = 0.45\ncoefficients_pa = [1e6]\nstrain_range = [0.5]\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("strain_range"), "{e}");
        let e = read_str("model = \"neo-hookean\"\nc1_pa = 1e5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing key `poisson`"), "{e}");
        let e = read_str("model = \"quartic\"\npoisson = 0.45\ncoefficients_pa = [1e6]\nstrain_range = [0, 0.5]\nstrain_measure = \"hencky\"\n")
            .unwrap_err().to_string();
        assert!(e.contains("strain_measure = \"hencky\""), "{e}");
    }

    #[test]
    fn the_fit_table_is_free_form() {
        let m = read_str(
            "model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = 1e5\n\n[fit]\nr2 = 0.99\nanything = \"goes\"\n\n[fit.refined]\nmethod = \"axisym\"\n",
        )
        .unwrap();
        assert_eq!(m.model, Model::NeoHookean { c1_pa: 1e5 });
        assert!(m.fit.is_some());
    }

    /// Unknown keys are refused by serde itself too (for readers that go
    /// through `read_toml` or `toml::from_str`).
    #[test]
    fn serde_refuses_unknown_keys() {
        let r: Result<Material, _> =
            toml::from_str("model = \"neo-hookean\"\npoisson = 0.45\nc1_pa = 1e5\nc2_pa = 1\n");
        assert!(r.unwrap_err().message().contains("unknown field `c2_pa`"));
    }
}
