//! Refusing, before anything is written, a command whose outputs would land
//! on its inputs.
//!
//! A command lists every path it reads and every path it will write
//! (including derived ones such as `m_curve.csv` next to `m.toml`), then calls
//! [`OutputPlan::check`]:
//!
//! ```
//! use bulge::io::OutputPlan;
//!
//! let dir = tempfile::tempdir()?;
//! let input = dir.path().join("heights.csv");
//! std::fs::write(&input, "pressure_pa,height_m\n1000,0.002\n")?;
//! let plan = OutputPlan::new()
//!     .input(&input)
//!     .output_as("-o", &input);
//! let err = plan.check().unwrap_err();
//! assert!(err.to_string().contains("heights.csv"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Paths are compared after resolving symbolic links, `.` and `..`; an output
//! that does not exist yet is resolved through its nearest existing folder.
//! On Unix two paths to the same file (hard links, bind mounts) are also
//! caught, by device and inode.

use std::io;
use std::path::{Component, Path, PathBuf};

/// Why a command's outputs are refused. Every message names both paths and
/// says what to change.
#[derive(Debug, thiserror::Error)]
pub enum OutputConflict {
    /// An output is one of the inputs.
    #[error(
        "{} `{}` is the input `{}`{}: writing it would destroy the input; choose another output path",
        what(label),
        output.display(),
        input.display(),
        same_as(output, input, resolved)
    )]
    SameAsInput {
        /// What the output is (e.g. the option that names it), if given.
        label: Option<String>,
        /// The output as given.
        output: PathBuf,
        /// The input as given.
        input: PathBuf,
        /// The file both resolve to.
        resolved: PathBuf,
    },
    /// An output folder holds an input.
    #[error(
        "{} `{}` contains the input `{}`: files written there could replace it; choose an output folder that holds no input, e.g. `{}`",
        what(label),
        output.display(),
        input.display(),
        sibling(output)
    )]
    ContainsInput {
        /// What the output is, if given.
        label: Option<String>,
        /// The output folder as given.
        output: PathBuf,
        /// The input inside it, as given.
        input: PathBuf,
    },
    /// An output lies inside an input folder.
    #[error(
        "{} `{}` is inside the input folder `{}`: it would be written among the files being read; choose an output path outside `{}`",
        what(label),
        output.display(),
        input.display(),
        input.display()
    )]
    InsideInput {
        /// What the output is, if given.
        label: Option<String>,
        /// The output as given.
        output: PathBuf,
        /// The input folder as given.
        input: PathBuf,
    },
    /// Two outputs are the same file.
    #[error(
        "{} `{}` and {} `{}` are the same file{}: one would overwrite the other; give them different paths",
        what(first_label),
        first.display(),
        what(second_label),
        second.display(),
        same_as(first, second, resolved)
    )]
    SameOutput {
        /// What the first output is, if given.
        first_label: Option<String>,
        /// The first output as given.
        first: PathBuf,
        /// What the second output is, if given.
        second_label: Option<String>,
        /// The second output as given.
        second: PathBuf,
        /// The file both resolve to.
        resolved: PathBuf,
    },
    /// A path could not be resolved (e.g. the current folder is gone).
    #[error("cannot resolve `{}`: {source}", path.display())]
    Resolve {
        /// The path as given.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
}

fn what(label: &Option<String>) -> String {
    match label {
        Some(l) => format!("the output {l}"),
        None => "the output".to_string(),
    }
}

fn same_as(a: &Path, b: &Path, resolved: &Path) -> String {
    if a == resolved && b == resolved {
        String::new()
    } else {
        format!(" (both are `{}`)", resolved.display())
    }
}

fn sibling(output: &Path) -> String {
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    output
        .with_file_name(format!("{name}-out"))
        .display()
        .to_string()
}

#[derive(Debug, Clone)]
struct Output {
    label: Option<String>,
    path: PathBuf,
}

/// The inputs and outputs of one command, checked together before anything
/// is written. Inputs and outputs may be files or folders.
#[derive(Debug, Clone, Default)]
pub struct OutputPlan {
    inputs: Vec<PathBuf>,
    outputs: Vec<Output>,
}

/// A path resolved for comparison.
struct Resolved {
    path: PathBuf,
    /// Device and inode when the path exists (Unix only).
    id: Option<(u64, u64)>,
    /// The path exists and is a FIFO, device or socket.
    special: bool,
}

impl OutputPlan {
    /// An empty plan.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file or folder the command reads.
    pub fn input(mut self, path: impl AsRef<Path>) -> Self {
        self.inputs.push(path.as_ref().to_path_buf());
        self
    }

    /// Adds several inputs.
    pub fn inputs<P: AsRef<Path>>(mut self, paths: impl IntoIterator<Item = P>) -> Self {
        self.inputs
            .extend(paths.into_iter().map(|p| p.as_ref().to_path_buf()));
        self
    }

    /// Adds a file or folder the command writes.
    pub fn output(mut self, path: impl AsRef<Path>) -> Self {
        self.outputs.push(Output {
            label: None,
            path: path.as_ref().to_path_buf(),
        });
        self
    }

    /// Adds an output with a label for the messages, e.g. `"-o"`,
    /// `"--profile"` or `"curve CSV"`.
    pub fn output_as(mut self, label: impl Into<String>, path: impl AsRef<Path>) -> Self {
        self.outputs.push(Output {
            label: Some(label.into()),
            path: path.as_ref().to_path_buf(),
        });
        self
    }

    /// Adds several outputs.
    pub fn outputs<P: AsRef<Path>>(mut self, paths: impl IntoIterator<Item = P>) -> Self {
        for p in paths {
            self = self.output(p);
        }
        self
    }

    /// The inputs, as given.
    pub fn input_paths(&self) -> &[PathBuf] {
        &self.inputs
    }

    /// The outputs, as given.
    pub fn output_paths(&self) -> impl Iterator<Item = &Path> {
        self.outputs.iter().map(|o| o.path.as_path())
    }

    /// Refuses (the first found of) an output that is an input, an output
    /// folder that contains an input, an output inside an input folder, and
    /// two outputs that are the same file.
    ///
    /// FIFOs, devices and sockets (`/dev/stdin`, `/dev/stdout`, pipes) are
    /// streams, not files that an output could overwrite: an input and an
    /// output that both resolve to the same one are accepted.
    pub fn check(&self) -> Result<(), OutputConflict> {
        let resolve_all = |paths: &mut dyn Iterator<Item = &Path>| {
            paths
                .map(|p| {
                    resolve(p).map_err(|source| OutputConflict::Resolve {
                        path: p.to_path_buf(),
                        source,
                    })
                })
                .collect::<Result<Vec<_>, _>>()
        };
        let ins = resolve_all(&mut self.inputs.iter().map(PathBuf::as_path))?;
        let outs = resolve_all(&mut self.outputs.iter().map(|o| o.path.as_path()))?;
        for (o, ro) in self.outputs.iter().zip(&outs) {
            for (i, ri) in self.inputs.iter().zip(&ins) {
                if same_file(ro, ri) {
                    if ro.special && ri.special {
                        continue;
                    }
                    return Err(OutputConflict::SameAsInput {
                        label: o.label.clone(),
                        output: o.path.clone(),
                        input: i.clone(),
                        resolved: ri.path.clone(),
                    });
                }
                if ri.path.starts_with(&ro.path) {
                    return Err(OutputConflict::ContainsInput {
                        label: o.label.clone(),
                        output: o.path.clone(),
                        input: i.clone(),
                    });
                }
                if ro.path.starts_with(&ri.path) {
                    return Err(OutputConflict::InsideInput {
                        label: o.label.clone(),
                        output: o.path.clone(),
                        input: i.clone(),
                    });
                }
            }
        }
        for (k, (a, ra)) in self.outputs.iter().zip(&outs).enumerate() {
            for (b, rb) in self.outputs.iter().zip(&outs).skip(k + 1) {
                if same_file(ra, rb) && !(ra.special && rb.special) {
                    return Err(OutputConflict::SameOutput {
                        first_label: a.label.clone(),
                        first: a.path.clone(),
                        second_label: b.label.clone(),
                        second: b.path.clone(),
                        resolved: ra.path.clone(),
                    });
                }
            }
        }
        Ok(())
    }
}

fn same_file(a: &Resolved, b: &Resolved) -> bool {
    a.path == b.path || matches!((a.id, b.id), (Some(x), Some(y)) if x == y)
}

/// Resolves a path that may not exist: the longest existing prefix is
/// canonicalised (links resolved) and the rest is joined with `.` and `..`
/// applied lexically.
fn resolve(path: &Path) -> io::Result<Resolved> {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()?.join(path)
    };
    if let Ok(c) = abs.canonicalize() {
        return Ok(existing(c));
    }
    // Walk up to the nearest existing ancestor, keeping the missing tail.
    let mut tail: Vec<Component> = Vec::new();
    let mut base = abs.as_path();
    let resolved_base = loop {
        match base.parent() {
            Some(parent) => {
                if let Some(last) = base.components().next_back() {
                    tail.push(last);
                }
                base = parent;
                if let Ok(c) = base.canonicalize() {
                    break c;
                }
            }
            None => break base.to_path_buf(),
        }
    };
    let mut out = resolved_base;
    for c in tail.into_iter().rev() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    // `missing/../in.csv` names an existing file after all
    if let Ok(c) = out.canonicalize() {
        return Ok(existing(c));
    }
    Ok(Resolved {
        path: out,
        id: None,
        special: false,
    })
}

fn existing(c: PathBuf) -> Resolved {
    let meta = std::fs::metadata(&c).ok();
    Resolved {
        id: meta.as_ref().and_then(file_id),
        special: meta.as_ref().is_some_and(|m| !m.is_file() && !m.is_dir()),
        path: c,
    }
}

#[cfg(unix)]
fn file_id(m: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn file_id(_: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn setup() -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.csv");
        fs::write(&input, "a\n1\n").unwrap();
        (dir, input)
    }

    #[test]
    fn distinct_paths_pass() {
        let (dir, input) = setup();
        let plan = OutputPlan::new()
            .input(&input)
            .output(dir.path().join("out.csv"))
            .output(dir.path().join("new/folder/out.toml"));
        plan.check().unwrap();
    }

    #[test]
    fn output_equal_to_input_is_refused_with_both_paths() {
        let (_dir, input) = setup();
        let e = OutputPlan::new()
            .input(&input)
            .output_as("-o", &input)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains("the output -o"), "{msg}");
        assert!(msg.matches("in.csv").count() >= 2, "{msg}");
        assert!(msg.contains("choose another output path"), "{msg}");
    }

    #[test]
    fn spelling_of_the_path_does_not_matter() {
        let (dir, input) = setup();
        fs::create_dir(dir.path().join("sub")).unwrap();
        let odd = dir.path().join("sub/.././in.csv");
        let e = OutputPlan::new()
            .input(&input)
            .output(&odd)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
        // an output whose folder does not exist yet, reaching back by `..`
        let odd = dir.path().join("missing/../in.csv");
        let e = OutputPlan::new()
            .input(&input)
            .output(&odd)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
    }

    #[test]
    fn relative_and_absolute_spellings_meet() {
        let (dir, input) = setup();
        // the relative path is resolved against the current folder; express
        // the input relative to it through the absolute temp path's root
        let cwd = std::env::current_dir().unwrap();
        let depth = cwd.components().count() - 1;
        let mut rel = PathBuf::new();
        for _ in 0..depth {
            rel.push("..");
        }
        let rel = rel.join(input.strip_prefix("/").unwrap());
        let e = OutputPlan::new()
            .input(&input)
            .output(&rel)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
        drop(dir);
    }

    #[cfg(unix)]
    #[test]
    fn symlink_to_input_is_refused() {
        let (dir, input) = setup();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let e = OutputPlan::new()
            .input(&input)
            .output(&link)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains("link.csv") && msg.contains("both are"),
            "{msg}"
        );
        // and the other way round: the input read through a link
        let e = OutputPlan::new()
            .input(&link)
            .output(&input)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
    }

    #[cfg(unix)]
    #[test]
    fn hard_link_to_input_is_refused() {
        let (dir, input) = setup();
        let link = dir.path().join("hard.csv");
        fs::hard_link(&input, &link).unwrap();
        let e = OutputPlan::new()
            .input(&input)
            .output(&link)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameAsInput { .. }), "{e:?}");
    }

    #[test]
    fn output_folder_holding_an_input_is_refused() {
        let (dir, _) = setup();
        let logs = dir.path().join("logs");
        fs::create_dir(&logs).unwrap();
        let exp = logs.join("experiment.toml");
        fs::write(&exp, "").unwrap();
        let e = OutputPlan::new()
            .input(&exp)
            .output_as("--out", &logs)
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::ContainsInput { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains("logs") && msg.contains("experiment.toml"),
            "{msg}"
        );
        assert!(msg.contains("logs-out"), "{msg}");
        // the folder that holds the input's folder too
        let e = OutputPlan::new()
            .input(&exp)
            .output(dir.path())
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::ContainsInput { .. }), "{e:?}");
    }

    #[test]
    fn output_inside_an_input_folder_is_refused() {
        let (dir, _) = setup();
        let photos = dir.path().join("photos");
        fs::create_dir(&photos).unwrap();
        let e = OutputPlan::new()
            .input(&photos)
            .output(photos.join("heights.csv"))
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::InsideInput { .. }), "{e:?}");
        assert!(e.to_string().contains("photos"), "{e}");
        // a sibling whose name starts the same is not inside
        OutputPlan::new()
            .input(&photos)
            .output(dir.path().join("photos2/heights.csv"))
            .check()
            .unwrap();
    }

    #[test]
    fn two_outputs_on_one_file_are_refused() {
        let (dir, input) = setup();
        let out = dir.path().join("out.json");
        let e = OutputPlan::new()
            .input(&input)
            .output_as("-o", &out)
            .output_as("--profile", dir.path().join("./out.json"))
            .check()
            .unwrap_err();
        assert!(matches!(e, OutputConflict::SameOutput { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains("-o") && msg.contains("--profile"), "{msg}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_read_and_written_is_a_stream_not_a_file() {
        let (dir, input) = setup();
        let fifo = dir.path().join("pipe");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(ok.success());
        OutputPlan::new()
            .input(&fifo)
            .output(&fifo)
            .check()
            .unwrap();
        // but a regular input is still protected
        assert!(
            OutputPlan::new()
                .inputs([&input, &fifo])
                .output(&input)
                .check()
                .is_err()
        );
    }
}
