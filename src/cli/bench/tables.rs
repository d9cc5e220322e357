//! The outputs of `bulge bench` from its runs: each case's Pareto front, the
//! CSV, the Markdown table and the plot of log wall time against log error.

use std::fmt::Write as _;

use super::runs::Entry;
use bulge::io::{CsvOut, fmt_num};
use bulge::report::plot::{Figure, Panel, Series};

/// The cases, in table order.
const CASES: [&str; 2] = ["disc", "sheet"];

/// Indices of the entries on the Pareto front of one case (no other entry
/// is both faster and more accurate), by increasing wall time.
pub fn pareto(entries: &[Entry], case: &str) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..entries.len())
        .filter(|&i| {
            entries[i].case == case && entries[i].error.is_some() && entries[i].status == "ok"
        })
        .collect();
    idx.sort_by(|&a, &b| entries[a].wall_s.total_cmp(&entries[b].wall_s));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        let e = entries[i].error.expect("filtered");
        if e < best {
            best = e;
            front.push(i);
        }
    }
    front
}

/// `bench.csv`: one row per run, with its place on the Pareto front.
pub fn csv(entries: &[Entry]) -> CsvOut {
    let mut csv = CsvOut::new(&[
        "case",
        "method",
        "model",
        "nodes",
        "tolerance",
        "wall_s",
        "steps",
        "relative_error",
        "pareto",
        "status",
    ]);
    let fronts: Vec<usize> = CASES.iter().flat_map(|c| pareto(entries, c)).collect();
    for (i, e) in entries.iter().enumerate() {
        csv.row(&[
            e.case.to_string(),
            e.method.clone(),
            e.model.name().to_string(),
            e.nodes.to_string(),
            format!("{:e}", e.tolerance),
            format!("{:.6}", e.wall_s),
            e.steps.to_string(),
            fmt_num(e.error),
            (fronts.contains(&i) as u8).to_string(),
            e.status.clone(),
        ]);
    }
    csv
}

/// `bench.md`: one table per case.
pub fn markdown(entries: &[Entry]) -> String {
    let mut s = String::new();
    for case in CASES {
        let front = pareto(entries, case);
        let _ = writeln!(
            s,
            "\n### {}\n\n| method | model | nodes | tolerance | wall_s | steps | relative error | Pareto | status |\n|---|---|---|---|---|---|---|---|---|",
            if case == "disc" {
                "Disc bubble (a = 37.5 mm, t = 0.35 mm, E = 1 MPa, nu = 0.45, 5 kPa): error of the apex height against the axisymmetric solution"
            } else {
                "the Sudhamani & Merriliance sheet (0.1 m, E = 50 kPa, 10 N/m at the middle): error of the loaded node's displacement against Newton at 1e-10 on the same mesh"
            }
        );
        for (i, e) in entries.iter().enumerate().filter(|(_, e)| e.case == case) {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.0e} | {:.4} | {} | {} | {} | {} |",
                e.method,
                e.model.name(),
                e.nodes,
                e.tolerance,
                e.wall_s,
                e.steps,
                e.error
                    .map(|v| format!("{v:.2e}"))
                    .unwrap_or_else(|| "-".into()),
                if front.contains(&i) { "yes" } else { "" },
                e.status.replace('|', "/")
            );
        }
    }
    s
}

/// `bench.png`: per case, log10 wall time against log10 error of each
/// method, and the Pareto front.
pub fn plot(entries: &[Entry]) -> Figure {
    let methods = [
        "newton",
        "dr",
        "explicit-euler",
        "symplectic-euler",
        "verlet",
        "implicit-euler",
        "xpbd",
    ];
    let mut panels = Vec::new();
    for case in CASES {
        let mut panel =
            Panel::new("log10 wall time (s)", "log10 relative error").titled(if case == "disc" {
                "disc bubble against the axisymmetric solution"
            } else {
                "the Sudhamani & Merriliance sheet against the converged static solution"
            });
        for (k, m) in methods.iter().enumerate() {
            let pts: Vec<(f64, f64)> = entries
                .iter()
                .filter(|e| e.case == case && e.method == *m)
                .filter_map(|e| {
                    e.error
                        .map(|err| (e.wall_s.max(1e-6).log10(), err.max(1e-16).log10()))
                })
                .collect();
            if !pts.is_empty() {
                panel = panel.with(Series::scatter(*m, pts).color(k));
            }
        }
        let front: Vec<(f64, f64)> = pareto(entries, case)
            .into_iter()
            .map(|i| {
                let e = &entries[i];
                (
                    e.wall_s.max(1e-6).log10(),
                    e.error.expect("front").max(1e-16).log10(),
                )
            })
            .collect();
        if !front.is_empty() {
            panel = panel.with(Series::line("Pareto front", front).dashed().color(7));
        }
        panels.push(panel);
    }
    Figure::new("bulge bench: speed against error", panels).size(900, 1100)
}
