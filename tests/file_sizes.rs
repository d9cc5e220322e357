//! The source stays in files that each do one job: no file in `src/` over
//! 800 lines, and no command-line module (`src/cli/`) over 250 lines, since
//! a subcommand's module only parses, calls one library entry and writes.
//! The exceptions are listed here with the reason; the list only shrinks.

use std::path::{Path, PathBuf};

const MAX_LINES: usize = 800;
const MAX_CLI_LINES: usize = 250;

/// Files allowed over [`MAX_LINES`], with why.
const EXCEPTIONS: &[(&str, &str)] = &[];

/// Command-line modules allowed over [`MAX_CLI_LINES`], with why.
const CLI_EXCEPTIONS: &[(&str, &str)] = &[];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn too_long(root: &str, max: usize, exceptions: &[(&str, &str)]) -> Vec<String> {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&base.join(root), &mut files);
    files.sort();
    let mut long = Vec::new();
    for f in files {
        let name = f
            .strip_prefix(base)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let lines = std::fs::read_to_string(&f).unwrap().lines().count();
        let excepted = exceptions.iter().any(|(e, _)| *e == name);
        if lines > max && !excepted {
            long.push(format!("{name}: {lines} lines"));
        }
    }
    long
}

#[test]
fn no_source_file_is_over_800_lines() {
    let long = too_long("src", MAX_LINES, EXCEPTIONS);
    assert!(
        long.is_empty(),
        "split these along their seams (one job per file): {long:?}"
    );
}

#[test]
fn no_command_line_module_is_over_250_lines() {
    let long = too_long("src/cli", MAX_CLI_LINES, CLI_EXCEPTIONS);
    assert!(
        long.is_empty(),
        "move the work into a library entry; the module parses, calls it and writes: {long:?}"
    );
}

/// An exception that no longer applies is removed from the list.
#[test]
fn every_exception_is_still_needed() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (list, max) in [(EXCEPTIONS, MAX_LINES), (CLI_EXCEPTIONS, MAX_CLI_LINES)] {
        for (name, _) in list {
            let text = std::fs::read_to_string(base.join(name))
                .unwrap_or_else(|e| panic!("{name} is listed but cannot be read: {e}"));
            assert!(
                text.lines().count() > max,
                "{name} is under {max} lines now: remove it from the exceptions"
            );
        }
    }
}
