//! Shared helpers: run the real binary, find fixtures, make temporary folders.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Path of the repository (for fixtures and data).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file under `fixtures/`.
pub fn fixture(rel: &str) -> PathBuf {
    repo().join("fixtures").join(rel)
}

/// The result of one run of the binary.
pub struct Run {
    pub status: i32,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    fn from(o: Output) -> Self {
        Run {
            status: o.status.code().unwrap_or(-1),
            stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        }
    }

    /// Panics with both streams unless the run succeeded.
    pub fn ok(self) -> Self {
        assert_eq!(
            self.status, 0,
            "bulge failed\nstdout:\n{}\nstderr:\n{}",
            self.stdout, self.stderr
        );
        self
    }

    /// Panics unless the run was refused as bad input (exit 2) with a message
    /// containing every one of `needles`.
    pub fn bad_input(self, needles: &[&str]) -> Self {
        assert_eq!(
            self.status, 2,
            "expected exit 2\nstdout:\n{}\nstderr:\n{}",
            self.stdout, self.stderr
        );
        for n in needles {
            assert!(
                self.stderr.contains(n),
                "stderr lacks {n:?}:\n{}",
                self.stderr
            );
        }
        self
    }
}

/// Runs `bulge` with `args` in folder `dir`.
pub fn bulge_in(dir: &Path, args: &[&str]) -> Run {
    let o = Command::new(env!("CARGO_BIN_EXE_bulge"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the bulge binary runs");
    Run::from(o)
}

/// A fresh temporary folder.
pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary folder")
}

/// A CSV file as its header and its rows of fields.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rdr = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let head = rdr
        .headers()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .iter()
        .map(str::to_string)
        .collect();
    let rows = rdr
        .records()
        .map(|r| {
            r.unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .iter()
                .map(str::to_string)
                .collect()
        })
        .collect();
    (head, rows)
}

/// Every height of the tracked `heights` CSV (`height_m`) within the
/// relative `tol` of the synthetic `truth` CSV's (its third column,
/// `height_m`), row by row, and as many rows; each relative error printed.
pub fn assert_heights_within(heights: &Path, truth: &Path, tol: f64) {
    let (head, rows) = read_csv(heights);
    let (_, truth) = read_csv(truth);
    let col = head.iter().position(|h| h == "height_m").unwrap();
    assert_eq!(rows.len(), truth.len());
    for (r, t) in rows.iter().zip(&truth) {
        let (h, ht): (f64, f64) = (r[col].parse().unwrap(), t[2].parse().unwrap());
        eprintln!("{} {:+.3} %", t[0], 100.0 * (h / ht - 1.0));
        assert!((h / ht - 1.0).abs() < tol, "{h} against {ht}");
    }
}
