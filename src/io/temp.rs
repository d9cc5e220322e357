//! Temporary files of atomic writes, and their removal when the process is
//! interrupted.
//!
//! Every temporary file is registered in a process-wide list before it is
//! created and leaves the list when it is renamed onto its target or removed.
//! [`remove_temporary_files`] removes whatever is in the list;
//! `install_cleanup_on_signal` (feature `cli`) makes Ctrl-C (SIGINT),
//! SIGTERM and SIGHUP do that and exit with status 130.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Temporary files in flight. Creation, rename and the signal-time removal
/// all hold this lock, so a file is either removed by the handler or renamed
/// onto its target, never left behind half-written.
static IN_FLIGHT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

static COUNTER: AtomicU64 = AtomicU64::new(0);

fn registry() -> MutexGuard<'static, Vec<PathBuf>> {
    IN_FLIGHT.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every registered temporary file (for a custom interrupt handler;
/// [`install_cleanup_on_signal`] calls it). Returns how many were removed.
pub fn remove_temporary_files() -> usize {
    remove_all(&mut registry())
}

fn remove_all(list: &mut Vec<PathBuf>) -> usize {
    let mut removed = 0;
    for p in list.drain(..) {
        if fs::remove_file(&p).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Registers a file that the interrupt handler removes, as a temporary file
/// is (an output folder's lock file, while its run lasts).
#[cfg(all(feature = "plots", feature = "opencv"))]
pub(crate) fn remove_on_signal(path: &Path) {
    registry().push(path.to_path_buf());
}

/// Removes `path` and takes it off the list of `remove_on_signal`.
#[cfg(all(feature = "plots", feature = "opencv"))]
pub(crate) fn remove_now(path: &Path) {
    let mut list = registry();
    let _ = fs::remove_file(path);
    list.retain(|p| p != path);
}

/// The temporary files currently being written, in registration order.
pub fn temporary_files() -> Vec<PathBuf> {
    registry().clone()
}

/// Installs, once per process, a handler for Ctrl-C (SIGINT), SIGTERM and
/// SIGHUP that removes the temporary files of unfinished atomic writes and
/// exits with status 130. Further calls do nothing. Call it at the start of
/// `main`; the targets of unfinished writes keep their old content.
#[cfg(feature = "cli")]
pub fn install_cleanup_on_signal() -> io::Result<()> {
    // the error kept as its kind and text: io::Error is not Clone
    static INSTALLED: std::sync::OnceLock<Option<(io::ErrorKind, String)>> =
        std::sync::OnceLock::new();
    INSTALLED
        .get_or_init(|| {
            ctrlc::set_handler(|| {
                // The lock is kept until the process ends: no write can
                // register, create or rename a file after the cleanup.
                let mut list = registry();
                remove_all(&mut list);
                std::process::exit(130);
            })
            .err()
            .map(|e| {
                (
                    io::ErrorKind::Other,
                    format!("cannot install the interrupt handler: {e}"),
                )
            })
        })
        .clone()
        .map_or(Ok(()), |(kind, text)| Err(io::Error::new(kind, text)))
}

/// A registered temporary file next to a target; removed (and unregistered)
/// on drop unless renamed onto the target by [`TempFile::persist`].
#[derive(Debug)]
pub(crate) struct TempFile {
    path: PathBuf,
    live: bool,
}

impl TempFile {
    /// A fresh name next to `target`: hidden, with the process id, a counter
    /// and the target's extension kept last (for writers that choose the
    /// format by extension).
    fn name_for(dir: &Path, target: &Path) -> PathBuf {
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let ext = target
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        dir.join(format!(".{name}.{}-{n}.tmp{ext}", std::process::id()))
    }

    /// Registers and creates an empty temporary file next to `target`.
    pub(crate) fn create(target: &Path) -> io::Result<(TempFile, fs::File)> {
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Self::create_in(dir, target)
    }

    /// Registers and creates an empty temporary file for `target` in `dir`.
    pub(crate) fn create_in(dir: &Path, target: &Path) -> io::Result<(TempFile, fs::File)> {
        let path = Self::name_for(dir, target);
        let mut list = registry();
        let file = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)?;
        list.push(path.clone());
        Ok((TempFile { path, live: true }, file))
    }

    /// The temporary path.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file onto `target` and unregisters it.
    pub(crate) fn persist(mut self, target: &Path) -> io::Result<()> {
        let mut list = registry();
        let r = fs::rename(&self.path, target);
        if r.is_ok() {
            list.retain(|p| p != &self.path);
            self.live = false;
        }
        r
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if self.live {
            let mut list = registry();
            let _ = fs::remove_file(&self.path);
            list.retain(|p| p != &self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registered_while_alive_and_removed_on_drop() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fig.png");
        let (t, _f) = TempFile::create(&target).unwrap();
        let p = t.path().to_path_buf();
        assert!(p.exists());
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with(".fig.png.") && name.ends_with(".tmp.png"),
            "{name}"
        );
        assert!(temporary_files().contains(&p));
        drop(t);
        assert!(!p.exists());
        assert!(!temporary_files().contains(&p));
    }

    #[test]
    fn persist_unregisters() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a.csv");
        let (t, _f) = TempFile::create(&target).unwrap();
        let p = t.path().to_path_buf();
        t.persist(&target).unwrap();
        assert!(target.exists() && !p.exists());
        assert!(!temporary_files().contains(&p));
    }

    #[test]
    fn remove_all_removes_the_listed_files() {
        // (not the global list: that would pull files from under the writes
        // of tests running alongside)
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(".x.tmp");
        fs::write(&p, b"x").unwrap();
        let mut list = vec![p.clone(), dir.path().join("never-created")];
        assert_eq!(remove_all(&mut list), 1);
        assert!(list.is_empty() && !p.exists());
    }

    #[cfg(feature = "cli")]
    const CHILD_DIR: &str = "BULGE_TEST_SIGNAL_CHILD_DIR";

    /// Run by `a_signal_removes_the_temporary_file_and_exits_130` in a
    /// child process: starts a write that never finishes.
    #[cfg(feature = "cli")]
    #[test]
    #[ignore = "a child of a_signal_removes_the_temporary_file_and_exits_130"]
    fn signal_child() {
        let Some(dir) = std::env::var_os(CHILD_DIR) else {
            return;
        };
        install_cleanup_on_signal().unwrap();
        install_cleanup_on_signal().unwrap();
        let target = Path::new(&dir).join("out.csv");
        let _ = crate::io::write_atomic_with(&target, |tmp| {
            fs::write(tmp, b"half a file")?;
            std::thread::sleep(std::time::Duration::from_secs(60));
            Ok::<(), io::Error>(())
        });
        panic!("the signal did not end the process");
    }

    #[cfg(all(unix, feature = "cli"))]
    #[test]
    fn a_signal_removes_the_temporary_file_and_exits_130() {
        use std::process::{Command, Stdio};
        use std::time::{Duration, Instant};
        for signal in ["INT", "TERM"] {
            let dir = tempfile::tempdir().unwrap();
            let mut child = Command::new(std::env::current_exe().unwrap())
                .args(["--exact", "io::temp::tests::signal_child", "--ignored"])
                .args(["--test-threads", "1", "--nocapture"])
                .env(CHILD_DIR, dir.path())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap();
            let start = Instant::now();
            let has_file = || fs::read_dir(dir.path()).unwrap().count() > 0;
            while !has_file() {
                assert!(start.elapsed() < Duration::from_secs(60), "no temp file");
                std::thread::sleep(Duration::from_millis(20));
            }
            let killed = Command::new("kill")
                .args([format!("-{signal}"), child.id().to_string()])
                .status()
                .unwrap();
            assert!(killed.success());
            let status = child.wait().unwrap();
            assert_eq!(status.code(), Some(130), "SIG{signal}: {status:?}");
            let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
            assert!(left.is_empty(), "SIG{signal} left {left:?}");
        }
    }
}
