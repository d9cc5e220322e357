//! What a study is made of: a study file (`[[specimens]] experiment = ...`
//! and an optional shared `[run]` table) or two or more experiment files,
//! read into named experiments; and the input files of an experiment that
//! its fingerprint covers.

use std::fs;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::experiment::Experiment;
use crate::io::InputError;
use crate::pipeline::RunOptions;

/// The study file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    /// Settings shared by the specimens.
    #[serde(default)]
    run: Option<RunOptions>,
    /// The specimens.
    specimens: Vec<SpecimenEntry>,
}

/// One `[[specimens]]` entry.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecimenEntry {
    /// The experiment file, relative to the study file.
    experiment: PathBuf,
    /// Its name (default: the experiment file's folder).
    #[serde(default)]
    name: Option<String>,
}

/// A study as read: its title, the specimens (name, experiment) and the
/// options they share.
#[derive(Debug)]
pub struct StudyInputs {
    /// The study file's path, or how many experiment files were given.
    pub title: String,
    /// Each specimen's name and experiment, in the order given.
    pub members: Vec<(String, Experiment)>,
    /// The study file's `[run]` table (empty for a list of experiments).
    pub shared: RunOptions,
}

/// Every input file of an experiment: the files it names and its photos.
pub fn input_files(exp: &Experiment) -> Vec<PathBuf> {
    let (mut files, folder) = exp.input_files();
    if let (Some(dir), Some(ph)) = (folder, &exp.photos)
        && let Ok(photos) = crate::track::list_photos(&dir, ph.glob())
    {
        files.extend(photos);
    }
    files
}

/// A specimen's name: the experiment file's folder, else its file stem.
fn default_name(path: &Path) -> String {
    let folder = path
        .parent()
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned());
    folder
        .filter(|n| !n.is_empty() && n != "." && n != "..")
        .unwrap_or_else(|| {
            path.file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned())
        })
}

/// Whether a name can be an output folder's.
fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n != "."
        && n != ".."
        && n.chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c))
}

/// Whether a TOML file is a study file (it has `specimens`).
fn is_study_file(path: &Path) -> Result<bool, InputError> {
    let text = fs::read_to_string(path)
        .map_err(|e| InputError::file(path, format!("cannot read the file: {e}")))?;
    Ok(text
        .parse::<toml::Table>()
        .map(|t| t.contains_key("specimens"))
        .unwrap_or(false))
}

/// The study given as one study file or two or more experiment files.
pub fn read(inputs: &[PathBuf]) -> Result<StudyInputs, InputError> {
    let study = match inputs {
        [one] if is_study_file(one)? => Some(one.clone()),
        [one] => {
            return Err(InputError::file(
                one,
                "a study needs two specimens or more: give a study file with [[specimens]] entries, or two or more experiment files",
            ));
        }
        many => {
            for p in many {
                if is_study_file(p)? {
                    return Err(InputError::file(
                        p,
                        "this is a study file: give either one study file or experiment files, not both",
                    ));
                }
            }
            None
        }
    };
    let mut members = Vec::new();
    let (title, shared) = match &study {
        Some(path) => {
            let f: StudyFile = crate::io::read_toml(path)?;
            if f.specimens.len() < 2 {
                return Err(InputError::file(
                    path,
                    format!(
                        "[[specimens]] lists {}: a study needs two specimens or more (add `[[specimens]]` entries with `experiment = \"...\"`)",
                        f.specimens.len()
                    ),
                ));
            }
            let base = path.parent().unwrap_or(Path::new(""));
            for (k, e) in f.specimens.iter().enumerate() {
                let file = base.join(&e.experiment);
                let exp = Experiment::read(&file).map_err(|err| {
                    InputError::file(
                        path,
                        format!(
                            "[[specimens]] entry {} (experiment = \"{}\", relative to the study file): {err}",
                            k + 1,
                            e.experiment.display()
                        ),
                    )
                })?;
                let name = match &e.name {
                    Some(n) if !valid_name(n) => {
                        return Err(InputError::file(
                            path,
                            format!(
                                "[[specimens]] entry {}: name = \"{n}\" cannot name a folder: use letters, digits, '.', '_' and '-'",
                                k + 1
                            ),
                        ));
                    }
                    Some(n) => n.clone(),
                    None => default_name(&file),
                };
                members.push((name, exp));
            }
            (path.display().to_string(), f.run.unwrap_or_default())
        }
        None => {
            for p in inputs {
                members.push((default_name(p), Experiment::read(p)?));
            }
            (
                format!("{} experiment files", inputs.len()),
                RunOptions::default(),
            )
        }
    };
    for (i, (n, e)) in members.iter().enumerate() {
        if !valid_name(n) {
            return Err(InputError::file(
                &e.path,
                format!(
                    "the specimen's name `{n}` (its folder's) cannot name an output folder: give it a `name` in a study file (letters, digits, '.', '_' and '-')"
                ),
            ));
        }
        // One experiment listed twice would count one specimen twice in the
        // mean, its interval and the pooled fit.
        let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => a == b,
        };
        if let Some((m, first)) = members[..i].iter().find(|(_, f)| same(&f.path, &e.path)) {
            return Err(InputError::file(
                &first.path,
                format!(
                    "the specimens `{m}` and `{n}` are one experiment file: each specimen is counted once in the mean, its interval and the pooled fit; list it once"
                ),
            ));
        }
        if let Some((_, first)) = members[..i].iter().find(|(m, _)| m == n) {
            return Err(InputError::file(
                &e.path,
                format!(
                    "two specimens are named `{n}` ({} and this one): give each a distinct `name` in the study file (or keep each experiment in a folder of its own name)",
                    first.path.display()
                ),
            ));
        }
    }
    Ok(StudyInputs {
        title,
        members,
        shared,
    })
}
