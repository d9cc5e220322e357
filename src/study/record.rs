//! What a study keeps of each specimen's run ([`Record`], written as
//! [`RECORD`] in the specimen's folder) and the fingerprint that decides
//! whether it can be read back instead of redone.

use std::fs;
use std::path::Path;
use std::time::UNIX_EPOCH;

use serde::{Deserialize, Serialize};

use super::Member;
use super::file::input_files;
use crate::experiment::{Experiment, Specimen};
use crate::fit::inverse::law_parameters;
use crate::material::Material;
use crate::pipeline::{PipelineError, RunOutput, Settings, measured_heights};

/// The record's file name in the specimen's folder.
pub const RECORD: &str = "study_fit.toml";

/// What `study_fit.toml` keeps of a specimen: what the study needs, and
/// the fingerprint of what it was made from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// Hash of the bulge version, the settings, the experiment file and the
    /// input files.
    pub fingerprint: String,
    /// The experiment file.
    pub experiment: String,
    /// The law fitted.
    pub law: String,
    /// The specimen's thickness used, m.
    pub thickness_m: f64,
    /// Parameter names with units.
    pub parameters: Vec<String>,
    /// Their corrected values.
    pub values: Vec<f64>,
    /// Their first-order standard errors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_errors: Option<Vec<f64>>,
    /// Their covariance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The specimen as the correction used it (for the joint fit).
    pub specimen: Specimen,
    /// The corrected law (without its provenance).
    pub material: Material,
    /// The heights the law was corrected to, when the window is circular
    /// and the law was corrected (for the joint fit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub heights: Vec<Height>,
}

/// One measured height of a record.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Height {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Apex height, m.
    pub height_m: f64,
    /// Its standard deviation, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_std_m: Option<f64>,
}

/// 64-bit FNV-1a (a fixed, documented hash: the fingerprint must not
/// change between builds).
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        // a separator, so that ("ab", "c") and ("a", "bc") differ
        self.0 ^= 0xff;
        self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// Files up to this size are fingerprinted by content, larger ones by size
/// and modification time.
const BY_CONTENT: u64 = 1 << 20;

/// The fingerprint of a specimen: the bulge version, its settings, and each
/// input file (the experiment file, pressure log, template, video and
/// photos) by its name from the experiment's folder and its content, or
/// size and modification time when large.
pub fn fingerprint(exp: &Experiment, s: &Settings) -> String {
    let mut h = Fnv::new();
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    h.bytes(format!("{s:?}").as_bytes());
    for p in input_files(exp) {
        // named from the experiment's folder: the same study run from
        // another working folder is the same
        let name = p.strip_prefix(&exp.base_dir).unwrap_or(&p);
        h.bytes(name.to_string_lossy().as_bytes());
        match fs::metadata(&p) {
            Ok(m) if m.len() <= BY_CONTENT => match fs::read(&p) {
                Ok(b) => h.bytes(&b),
                Err(_) => h.bytes(b"unreadable"),
            },
            Ok(m) => {
                let t = m
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_nanos());
                h.bytes(format!("{} {t}", m.len()).as_bytes());
            }
            Err(_) => h.bytes(b"missing"),
        }
    }
    format!("{:016x}", h.0)
}

/// The record of a member's finished run.
pub fn record(m: &Member, o: &RunOutput) -> Result<Record, PipelineError> {
    let (parameters, values, _) = law_parameters(&o.fit.material.model).ok_or_else(|| {
        PipelineError::Input(format!(
            "the fitted law ({}) has no parameters to compare across specimens",
            o.fit.material.model.name()
        ))
    })?;
    let u = o.fit.refined.as_ref().and_then(|r| r.uncertainty.as_ref());
    Ok(Record {
        fingerprint: m.fingerprint.clone(),
        experiment: m.exp.path.display().to_string(),
        law: m.settings.fit.label(),
        thickness_m: o.specimen.thickness_m,
        parameters,
        values,
        std_errors: u.map(|u| u.std_errors()),
        covariance: u.map(|u| {
            let c = u.covariance();
            (0..c.nrows())
                .map(|i| (0..c.ncols()).map(|j| c[(i, j)]).collect())
                .collect()
        }),
        specimen: o.specimen,
        material: Material {
            fit: None,
            ..o.fit.material.clone()
        },
        heights: if m.settings.window.is_circle() && o.fit.refined.is_some() {
            measured_heights(&o.stress.points)
                .iter()
                .map(|q| Height {
                    pressure_pa: q.pressure_pa,
                    height_m: q.height_m,
                    height_std_m: q.height_std_m,
                })
                .collect()
        } else {
            vec![]
        },
    })
}

/// The earlier record in `dir` of a member, when it was made from the same
/// inputs and settings.
pub fn reusable(dir: &Path, m: &Member) -> Option<Record> {
    let text = fs::read_to_string(dir.join(RECORD)).ok()?;
    let r: Record = toml::from_str(&text).ok()?;
    (r.fingerprint == m.fingerprint).then_some(r)
}
