//! Tests of `io`.

use super::*;

/// The table a refusal names is the document's own: `[photos]`, `[[load]]`
/// for an element of an array of tables, never a row of a multi-line array;
/// the line is the value's.
#[test]
fn refusals_name_their_table_from_the_document() {
    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct Load {
        node: usize,
    }
    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct Photos {
        roi_px: [f64; 4],
    }
    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct F {
        photos: Photos,
        load: Vec<Load>,
    }
    let short = "[photos]\nroi_px = [\n  1.0, 2.0,\n  3.0,\n]\n\n[[load]]\nnode = 1\n";
    let e = parse_toml::<F>(Path::new("f.toml"), short).unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
    assert_eq!(
        e.message, "`roi_px` in [photos] must be a list of 4 values, not 3",
        "{e}"
    );
    let negative = "[photos]\nroi_px = [1, 2, 3, 4]\n\n[[load]]\nnode = 1\n\n[[load]]\nnode = -1\n";
    let e = parse_toml::<F>(Path::new("f.toml"), negative).unwrap_err();
    assert_eq!(e.line, Some(8), "{e}");
    assert_eq!(
        e.message, "`node` in [[load]] must be a whole number >= 0, not integer `-1`",
        "{e}"
    );
}

/// A wrong value inside a table after a multi-line array names the
/// table, not a row of the array.
#[test]
fn toml_messages_name_the_table_past_multi_line_arrays() {
    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct Cal {
        points_px: Vec<[f64; 2]>,
        clamp_row_px: f64,
    }
    #[derive(Debug, serde::Deserialize)]
    #[allow(dead_code)]
    struct File {
        calibration: Cal,
    }
    let text =
        "[calibration]\npoints_px = [\n  [1.0, 2.0],\n  [3.0, 4.0],\n]\nclamp_row_px = \"low\"\n";
    let m = parse_toml::<File>(Path::new("e.toml"), text).unwrap_err();
    assert_eq!(m.line, Some(6), "{m}");
    assert!(
        m.message
            .contains("`clamp_row_px` in [calibration] must be a number"),
        "{m}"
    );
}

#[test]
fn missing_column_names_file_and_found_columns() {
    let t = Table::parse(Path::new("h.csv"), b"a,b\n1,2\n").unwrap();
    let e = t.require("pressure_pa").unwrap_err().to_string();
    assert!(e.contains("h.csv"), "{e}");
    assert!(e.contains("pressure_pa"), "{e}");
    assert!(e.contains("found: a, b"), "{e}");
}

#[test]
fn bad_number_names_line_and_value() {
    let t = Table::parse(Path::new("h.csv"), b"a\n1\nabc\n").unwrap();
    let e = t.numbers("a").unwrap_err().to_string();
    assert!(e.contains("line 3"), "{e}");
    assert!(e.contains("`abc`"), "{e}");
    let t = Table::parse(Path::new("h.csv"), b"a\nNaN\n").unwrap();
    assert!(t.numbers("a").unwrap_err().to_string().contains("line 2"));
}

#[test]
fn empty_and_header_only_files_are_refused() {
    assert!(Table::parse(Path::new("e.csv"), b"").is_err());
    assert!(Table::parse(Path::new("e.csv"), b"a,b\n").is_err());
}

#[test]
fn atomic_write_replaces_whole_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("sub/out.csv");
    write_atomic(&p, b"one").unwrap();
    write_atomic(&p, b"two").unwrap();
    assert_eq!(fs::read(&p).unwrap(), b"two");
    assert_eq!(fs::read_dir(p.parent().unwrap()).unwrap().count(), 1);
}

#[test]
fn atomic_write_keeps_permissions_and_refuses_folders() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("run.sh");
    fs::write(&p, b"old").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        fs::set_permissions(&p, fs::Permissions::from_mode(0o750)).unwrap();
        write_atomic(&p, b"new").unwrap();
        let mode = fs::metadata(&p).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o750);
    }
    assert!(write_atomic(dir.path(), b"x").is_err());
    assert!(dir.path().is_dir());
}

#[cfg(unix)]
#[test]
fn atomic_write_goes_through_a_fifo() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    for round in 0..2 {
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || fs::read(fifo).unwrap())
        };
        if round == 0 {
            write_atomic(&fifo, b"through the pipe").unwrap();
        } else {
            write_atomic_with(&fifo, |tmp| fs::write(tmp, b"through the pipe")).unwrap();
        }
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        let ft = fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(ft.is_fifo(), "the FIFO was replaced");
        // nothing left beside it
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}

#[cfg(unix)]
#[test]
fn atomic_write_keeps_a_symlink_and_replaces_its_target() {
    let dir = tempfile::tempdir().unwrap();
    let real_dir = dir.path().join("real");
    fs::create_dir(&real_dir).unwrap();
    let real = real_dir.join("data.csv");
    fs::write(&real, b"old").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    write_atomic(&link, b"new").unwrap();
    assert!(
        fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read(&real).unwrap(), b"new");
    assert_eq!(fs::read_dir(&real_dir).unwrap().count(), 1);
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
    // a link to nothing yet: written through, creating its target
    let later = dir.path().join("later.csv");
    let dangling = dir.path().join("dangling.csv");
    std::os::unix::fs::symlink(&later, &dangling).unwrap();
    write_atomic(&dangling, b"made").unwrap();
    assert!(
        fs::symlink_metadata(&dangling)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read(&later).unwrap(), b"made");
}

#[test]
fn atomic_write_with_keeps_extension_and_old_file_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("fig.png");
    fs::write(&p, b"old").unwrap();
    let r = write_atomic_with(&p, |tmp| {
        assert_eq!(tmp.extension().unwrap(), "png");
        assert_eq!(tmp.parent(), p.parent());
        fs::write(tmp, b"half")?;
        Err(std::io::Error::other("drawing failed"))
    });
    assert!(matches!(r, Err(AtomicWriteError::Write(_))));
    assert_eq!(fs::read(&p).unwrap(), b"old");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    write_atomic_with(&p, |tmp| fs::write(tmp, b"new")).unwrap();
    assert_eq!(fs::read(&p).unwrap(), b"new");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn nearest_name_suggests_close_spellings_only() {
    let keys = ["model", "poisson", "c1_pa", "young_pa", "radius_m"];
    assert_eq!(nearest_name("possion", keys), Some("poisson"));
    assert_eq!(nearest_name("Poisson", keys), Some("poisson"));
    assert_eq!(nearest_name("c2_pa", keys), Some("c1_pa"));
    assert_eq!(nearest_name("young", keys), Some("young_pa"));
    assert_eq!(nearest_name("radius", keys), Some("radius_m"));
    assert_eq!(nearest_name("thickness", keys), None);
    assert_eq!(nearest_name("x", keys), None);
}

#[test]
fn read_toml_suggests_the_nearest_key() {
    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct S {
        radius_m: f64,
        thickness_m: f64,
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.toml");
    fs::write(&p, "radius_m = 1.0\nthicknes_m = 2.0\n").unwrap();
    let e = read_toml::<S>(&p).unwrap_err().to_string();
    assert!(e.contains("s.toml"), "{e}");
    assert!(e.contains("did you mean `thickness_m`?"), "{e}");
}

#[test]
fn toml_with_nan_is_not_written() {
    #[derive(serde::Serialize)]
    struct Fit {
        r2: f64,
        rmse_pa: Vec<f64>,
    }
    #[derive(serde::Serialize)]
    struct M {
        c1_pa: f64,
        fit: Fit,
    }
    let m = M {
        c1_pa: 1.0,
        fit: Fit {
            r2: f64::NAN,
            rmse_pa: vec![1.0],
        },
    };
    let e = to_toml_string(&m).unwrap_err().to_string();
    assert!(e.contains("`fit.r2 = NaN`"), "{e}");
    let m = M {
        c1_pa: 1.0,
        fit: Fit {
            r2: 0.9,
            rmse_pa: vec![1.0, f64::INFINITY],
        },
    };
    let e = to_toml_string(&m).unwrap_err().to_string();
    assert!(e.contains("`fit.rmse_pa[1] = inf`"), "{e}");
    let m = M {
        c1_pa: 1.0,
        fit: Fit {
            r2: 0.9,
            rmse_pa: vec![1.0],
        },
    };
    assert!(to_toml_string(&m).unwrap().contains("r2 = 0.9"));
}

#[test]
fn fmt_num_never_writes_nan() {
    assert_eq!(fmt_num(Some(f64::NAN)), "");
    assert_eq!(fmt_num(None), "");
    assert_eq!(fmt_num(Some(0.5)), "0.5");
}

#[test]
fn short_numbers_for_messages() {
    assert_eq!(fmt_short(1e-300), "1.00000e-300");
    assert_eq!(fmt_short(5000.0), "5000");
    assert_eq!(fmt_short(0.0125), "0.0125");
    assert_eq!(fmt_short(1.7e308), "1.70000e308");
    assert_eq!(fmt_short(0.0), "0");
}
