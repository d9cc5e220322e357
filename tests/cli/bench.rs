//! Integration test of `bulge bench --quick`.
use std::fs;

use crate::util::{bulge_in, read_csv, tempdir};

/// The quick bench writes its CSV, Markdown and PNG; every row is either an
/// error figure or a status saying why not; the Newton disc row is within
/// 1 % of the axisymmetric height; no NaN anywhere.
#[test]
fn quick_bench_writes_table_and_plot() {
    let dir = tempdir();
    bulge_in(dir.path(), &["bench", "--quick", "--out", "b"]).ok();
    let csv = fs::read_to_string(dir.path().join("b/bench.csv")).unwrap();
    assert!(!csv.contains("NaN") && !csv.contains("inf"));
    let (head, rows) = read_csv(&dir.path().join("b/bench.csv"));
    let at = |n: &str| head.iter().position(|h| *h == n).unwrap();
    assert!(rows.len() >= 15, "{}", rows.len());
    for r in &rows {
        assert!(
            !r[at("relative_error")].is_empty() || !r[at("status")].is_empty(),
            "{r:?}"
        );
    }
    let newton = rows
        .iter()
        .find(|r| r[at("case")] == "disc" && r[at("method")] == "newton" && r[at("model")] == "tp")
        .unwrap();
    let e: f64 = newton[at("relative_error")].parse().unwrap();
    assert!(e < 0.01, "{e}");
    assert!(rows.iter().any(|r| r[at("pareto")] == "1"));
    let png = fs::read(dir.path().join("b/bench.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    assert!(
        fs::read_to_string(dir.path().join("b/bench.md"))
            .unwrap()
            .contains("| method |")
    );
}
