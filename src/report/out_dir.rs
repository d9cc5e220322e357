//! An output folder that holds one run's files as a set.
//!
//! * A lock (`.bulge-lock`, locked by the operating system while the run
//!   lasts) refuses a second run into the same folder while one is
//!   writing; the file is removed when the run ends or is interrupted, and
//!   one left by a killed run holds no lock: the next run takes it over.
//! * `manifest.toml` lists the files of the last run and the stage that made
//!   each. Files of the previous run that the new one did not write (a rerun
//!   that stopped at an earlier stage, or fewer outputs) are removed, so the
//!   folder never mixes the outputs of two runs.
//! * Each file is written whole (temporary file, then rename).

use std::fs::{self, OpenOptions};
use std::io::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::run_files::OutFile;

/// Name of the lock file inside the folder.
pub const LOCK_FILE: &str = ".bulge-lock";
/// Name of the manifest inside the folder.
pub const MANIFEST: &str = "manifest.toml";

/// Why the folder could not be used.
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    /// Another run holds the lock.
    #[error(
        "{dir} is in use by another bulge run ({holder}); wait for it to end, or, if no run is writing there, delete {lock}"
    )]
    Locked {
        /// The folder.
        dir: PathBuf,
        /// What the lock file says.
        holder: String,
        /// The lock file.
        lock: PathBuf,
    },
    /// The path exists and is not a folder.
    #[error("{0} exists and is not a folder: give a folder for the outputs")]
    NotAFolder(PathBuf),
    /// A file system error.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

impl crate::Refusal for OutDirError {
    /// The user's choice of folder is at fault (not the system).
    fn is_bad_input(&self) -> bool {
        !matches!(self, OutDirError::Io { .. })
    }
}

/// `manifest.toml`: which files belong to the last run.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The run's status: `complete`, or the stage it stopped at.
    pub status: String,
    /// The files, in the order written.
    #[serde(default)]
    pub files: Vec<ManifestEntry>,
}

/// One file of a manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestEntry {
    /// File name inside the folder.
    pub name: String,
    /// The stage that made it.
    pub stage: String,
    /// Size, bytes.
    pub bytes: u64,
}

/// An output folder locked for one run; the lock goes when this is dropped.
///
/// The lock is the operating system's (`flock` on Linux and macOS,
/// `LockFileEx` on Windows) on the lock file, held while this value lives:
/// the system releases it when the process ends, however it ends. So a lock
/// file left behind by a killed run (SIGKILL, a power cut) holds no lock,
/// and the next run takes it over and says so ([`OutDir::taken_over`]).
/// The file itself is removed when the run ends, also on Ctrl-C, SIGTERM
/// and SIGHUP (the interrupt handler of `crate::io`).
#[derive(Debug)]
pub struct OutDir {
    dir: PathBuf,
    lock: PathBuf,
    /// The open lock file, locked.
    _held: fs::File,
    taken_over: Option<String>,
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutDirError + '_ {
    move |source| OutDirError::Io {
        path: path.to_path_buf(),
        source,
    }
}

impl OutDir {
    /// Creates the folder if needed and takes its lock.
    pub fn lock(dir: impl AsRef<Path>) -> Result<OutDir, OutDirError> {
        let dir = dir.as_ref().to_path_buf();
        if dir.exists() && !dir.is_dir() {
            return Err(OutDirError::NotAFolder(dir));
        }
        fs::create_dir_all(&dir).map_err(io_err(&dir))?;
        let lock = dir.join(LOCK_FILE);
        // A run that ends removes its lock file while it still holds the
        // lock: one who opened the file before that and locks it after holds
        // a lock on a removed file, so the lock counts only if the file is
        // still the folder's.
        for _ in 0..8 {
            // Whether the file was there before this run: a run killed
            // between creating the file and writing its process number
            // leaves an empty one, which is taken over all the same.
            let (mut f, found) = match OpenOptions::new()
                .read(true)
                .write(true)
                .create_new(true)
                .open(&lock)
            {
                Ok(f) => (f, false),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    match OpenOptions::new().read(true).write(true).open(&lock) {
                        Ok(f) => (f, true),
                        // removed by the run that held it since: try again
                        Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                        Err(e) => return Err(io_err(&lock)(e)),
                    }
                }
                Err(e) => return Err(io_err(&lock)(e)),
            };
            let holder = || {
                fs::read_to_string(&lock)
                    .map(|s| s.trim().to_string())
                    .ok()
                    .filter(|s| !s.is_empty())
            };
            match f.try_lock() {
                Ok(()) => {}
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(OutDirError::Locked {
                        holder: holder().unwrap_or_else(|| "a process starting".into()),
                        dir,
                        lock,
                    });
                }
                Err(fs::TryLockError::Error(e)) => return Err(io_err(&lock)(e)),
            }
            if !same_file(&f, &lock) {
                continue;
            }
            let taken_over =
                match found {
                    true => Some(holder().unwrap_or_else(|| {
                        "an empty lock file: a run stopped as it started".into()
                    })),
                    false => None,
                };
            f.set_len(0).map_err(io_err(&lock))?;
            writeln!(f, "process {}", std::process::id()).map_err(io_err(&lock))?;
            crate::io::temp::remove_on_signal(&lock);
            return Ok(OutDir {
                dir,
                lock,
                _held: f,
                taken_over,
            });
        }
        Err(OutDirError::Locked {
            holder: "runs that start and end as this one starts".into(),
            dir,
            lock,
        })
    }

    /// What the lock file said when this run took it over from a run that
    /// had ended without removing it (killed, or the machine stopped):
    /// `None` when there was no lock file.
    pub fn taken_over(&self) -> Option<&str> {
        self.taken_over.as_deref()
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The manifest of the previous run, if any (an unreadable one counts as
    /// none).
    pub fn previous(&self) -> Option<Manifest> {
        let text = fs::read_to_string(self.dir.join(MANIFEST)).ok()?;
        toml::from_str(&text).ok()
    }

    /// Writes `files` (each whole), then the manifest with `status`, then
    /// removes the files of the previous run that are not among them.
    pub fn write_set(&self, files: &[OutFile], status: &str) -> Result<(), OutDirError> {
        let previous = self.previous();
        for f in files {
            let p = self.dir.join(f.name);
            crate::io::write_atomic(&p, &f.bytes).map_err(io_err(&p))?;
        }
        let manifest = Manifest {
            status: status.to_string(),
            files: files
                .iter()
                .map(|f| ManifestEntry {
                    name: f.name.to_string(),
                    stage: f.stage.name().to_string(),
                    bytes: f.bytes.len() as u64,
                })
                .collect(),
        };
        let text = toml::to_string(&manifest).map_err(|e| OutDirError::Io {
            path: self.dir.join(MANIFEST),
            source: std::io::Error::other(e),
        })?;
        let mp = self.dir.join(MANIFEST);
        crate::io::write_atomic(&mp, text.as_bytes()).map_err(io_err(&mp))?;
        if let Some(prev) = previous {
            for old in prev.files {
                let stale = !files.iter().any(|f| f.name == old.name);
                // only plain names of this folder: a manifest never points outside
                if stale && Path::new(&old.name).file_name() == Some(old.name.as_ref()) {
                    let _ = fs::remove_file(self.dir.join(&old.name));
                }
            }
        }
        Ok(())
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        // Removed while still locked (the lock goes with the file handle,
        // dropped after this).
        crate::io::temp::remove_now(&self.lock);
    }
}

/// Whether the open file `f` is the file at `path` (the same device and
/// inode; on systems without them, always).
fn same_file(f: &fs::File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (f.metadata(), fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (f, path);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Refusal;
    use crate::pipeline::Stage;

    fn file(name: &'static str, stage: Stage) -> OutFile {
        OutFile {
            name,
            stage,
            bytes: name.as_bytes().to_vec(),
        }
    }

    /// A second run into a locked folder is refused; the lock goes with the
    /// first run.
    #[test]
    fn one_run_at_a_time() {
        let d = tempfile::tempdir().unwrap();
        let first = OutDir::lock(d.path()).unwrap();
        let e = OutDir::lock(d.path()).unwrap_err();
        assert!(matches!(e, OutDirError::Locked { .. }), "{e}");
        assert!(e.to_string().contains(LOCK_FILE), "{e}");
        drop(first);
        assert!(OutDir::lock(d.path()).is_ok());
    }

    /// A lock file left by a run that was killed (no process holds its
    /// lock) is taken over, with what it said; the lock is the operating
    /// system's, held while the run lasts, and the file goes with the run.
    #[test]
    fn a_stale_lock_file_is_taken_over() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join(LOCK_FILE), "process 4194999\n").unwrap();
        let out = OutDir::lock(d.path()).unwrap();
        assert_eq!(out.taken_over(), Some("process 4194999"));
        let text = std::fs::read_to_string(d.path().join(LOCK_FILE)).unwrap();
        assert_eq!(text.trim(), format!("process {}", std::process::id()));
        assert!(matches!(
            OutDir::lock(d.path()),
            Err(OutDirError::Locked { .. })
        ));
        drop(out);
        assert!(!d.path().join(LOCK_FILE).exists());
        assert_eq!(OutDir::lock(d.path()).unwrap().taken_over(), None);
        // killed between creating the file and writing its process number
        std::fs::write(d.path().join(LOCK_FILE), "").unwrap();
        let out = OutDir::lock(d.path()).unwrap();
        assert!(out.taken_over().unwrap().contains("empty lock file"));
    }

    /// A rerun that stops at an earlier stage leaves no file of the previous
    /// run's later stages; the manifest says what is there.
    #[test]
    fn a_shorter_rerun_removes_the_stale_files() {
        let d = tempfile::tempdir().unwrap();
        let full = [
            file("heights.csv", Stage::Track),
            file("material.toml", Stage::Fit),
            file("report.html", Stage::Report),
        ];
        OutDir::lock(d.path())
            .unwrap()
            .write_set(&full, "complete")
            .unwrap();
        assert!(d.path().join("report.html").exists());
        std::fs::write(d.path().join("notes.txt"), "mine").unwrap();
        let out = OutDir::lock(d.path()).unwrap();
        out.write_set(&full[..1], "stopped at fit").unwrap();
        assert!(d.path().join("heights.csv").exists());
        assert!(!d.path().join("material.toml").exists());
        assert!(!d.path().join("report.html").exists());
        // a file bulge did not write is left alone
        assert!(d.path().join("notes.txt").exists());
        let m = out.previous().unwrap();
        assert_eq!(m.status, "stopped at fit");
        assert_eq!(m.files.len(), 1);
    }

    #[test]
    fn a_file_is_not_a_folder() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join("x");
        std::fs::write(&f, "").unwrap();
        let e = OutDir::lock(&f).unwrap_err();
        assert!(
            matches!(e, OutDirError::NotAFolder(_)) && e.is_bad_input(),
            "{e}"
        );
    }
}
