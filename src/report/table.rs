//! The comparison table in Tudruj et al.'s (2023) Table 3 layout (pressure, measured
//! height, simulated height per model, relative error), as terminal text,
//! Markdown and HTML, and the stage-timing table.

use crate::pipeline::{Comparison, ModelRun};

pub use crate::pipeline::Timing;

fn mm(v: Option<f64>) -> String {
    v.map(|h| format!("{:.3}", h * 1e3))
        .unwrap_or_else(|| "-".into())
}

fn pct(v: Option<f64>) -> String {
    v.map(|e| format!("{:+.2}", e * 100.0))
        .unwrap_or_else(|| "-".into())
}

/// Mean and largest absolute relative error of each model over the rows
/// where both heights exist.
pub fn error_summary(rows: &[Comparison], n_models: usize) -> Vec<(Option<f64>, Option<f64>)> {
    (0..n_models)
        .map(|k| {
            let e: Vec<f64> = rows
                .iter()
                .filter_map(|r| r.rel_errors()[k])
                .map(f64::abs)
                .collect();
            if e.is_empty() {
                (None, None)
            } else {
                (
                    Some(e.iter().sum::<f64>() / e.len() as f64),
                    Some(e.iter().cloned().fold(0.0, f64::max)),
                )
            }
        })
        .collect()
}

/// The table as fixed-width text for the terminal: heights in mm, errors in
/// percent of the measured height.
pub fn terminal(rows: &[Comparison], runs: &[ModelRun]) -> String {
    let mut head = format!("{:>12} {:>12}", "pressure_pa", "measured_mm");
    for r in runs {
        head.push_str(&format!(
            " {:>12} {:>8}",
            format!("{}_mm", r.model),
            "err_%"
        ));
    }
    let mut s = head.clone();
    s.push('\n');
    s.push_str(&"-".repeat(head.len()));
    s.push('\n');
    for row in rows {
        s.push_str(&format!(
            "{:>12.1} {:>12}",
            row.pressure_pa,
            mm(row.measured_m)
        ));
        for (h, e) in row.simulated_m.iter().zip(row.rel_errors()) {
            s.push_str(&format!(" {:>12} {:>8}", mm(*h), pct(e)));
        }
        s.push('\n');
    }
    s.push_str(&"-".repeat(head.len()));
    s.push('\n');
    let sum = error_summary(rows, runs.len());
    s.push_str(&format!("{:>25}", "mean |err| %"));
    for (mean, _) in &sum {
        s.push_str(&format!(
            " {:>12} {:>8}",
            "",
            mean.map(|e| format!("{:.2}", e * 100.0))
                .unwrap_or("-".into())
        ));
    }
    s.push('\n');
    s.push_str(&format!("{:>25}", "max |err| %"));
    for (_, max) in &sum {
        s.push_str(&format!(
            " {:>12} {:>8}",
            "",
            max.map(|e| format!("{:.2}", e * 100.0))
                .unwrap_or("-".into())
        ));
    }
    s.push('\n');
    s
}

/// The table in Markdown.
pub fn markdown(rows: &[Comparison], runs: &[ModelRun]) -> String {
    let mut s = String::from("| pressure (Pa) | measured (mm) |");
    let mut sep = String::from("|---:|---:|");
    for r in runs {
        s.push_str(&format!(" {} (mm) | error (%) |", r.model));
        sep.push_str("---:|---:|");
    }
    s.push('\n');
    s.push_str(&sep);
    s.push('\n');
    for row in rows {
        s.push_str(&format!(
            "| {:.1} | {} |",
            row.pressure_pa,
            measured_cell(row)
        ));
        for (h, e) in row.simulated_m.iter().zip(row.rel_errors()) {
            s.push_str(&format!(" {} | {} |", mm(*h), pct(e)));
        }
        s.push('\n');
    }
    s
}

/// The measured height in mm with its standard deviation, `12.345 ± 0.006`.
fn measured_cell(row: &Comparison) -> String {
    let std = row
        .measured_std_m
        .map(|d| format!(" ± {:.3}", d * 1e3))
        .unwrap_or_default();
    format!("{}{std}", mm(row.measured_m))
}

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The table as an HTML `<table>`; errors above `flag` (relative) are marked.
pub fn html(rows: &[Comparison], runs: &[ModelRun], flag: f64) -> String {
    let mut s = String::from(
        "<table class=\"num\"><thead><tr><th>pressure (Pa)</th><th>measured (mm)</th>",
    );
    for r in runs {
        s.push_str(&format!(
            "<th>{} (mm)</th><th>error (%)</th>",
            esc(r.model.name())
        ));
    }
    s.push_str("</tr></thead><tbody>\n");
    for row in rows {
        s.push_str(&format!(
            "<tr><td>{:.1}</td><td>{}</td>",
            row.pressure_pa,
            measured_cell(row)
        ));
        for (h, e) in row.simulated_m.iter().zip(row.rel_errors()) {
            let cls = if e.is_some_and(|e| e.abs() > flag) {
                " class=\"bad\""
            } else {
                ""
            };
            s.push_str(&format!("<td>{}</td><td{cls}>{}</td>", mm(*h), pct(e)));
        }
        s.push_str("</tr>\n");
    }
    let sum = error_summary(rows, runs.len());
    s.push_str("<tr class=\"sum\"><td colspan=\"2\">mean |error| (%)</td>");
    for (mean, _) in &sum {
        s.push_str(&format!(
            "<td></td><td>{}</td>",
            mean.map(|e| format!("{:.2}", e * 100.0))
                .unwrap_or("-".into())
        ));
    }
    s.push_str("</tr><tr class=\"sum\"><td colspan=\"2\">max |error| (%)</td>");
    for (_, max) in &sum {
        s.push_str(&format!(
            "<td></td><td>{}</td>",
            max.map(|e| format!("{:.2}", e * 100.0))
                .unwrap_or("-".into())
        ));
    }
    s.push_str("</tr></tbody></table>\n");
    s
}

/// Stage timings as terminal text.
pub fn timings_terminal(t: &[Timing]) -> String {
    let total: f64 = t.iter().map(|t| t.seconds).sum();
    let mut s = String::new();
    for x in t {
        s.push_str(&format!(
            "{:>10} {:>9.3} s  {}\n",
            x.stage.name(),
            x.seconds,
            x.what
        ));
    }
    s.push_str(&format!("{:>10} {:>9.3} s\n", "total", total));
    s
}

/// Stage timings in Markdown.
pub fn timings_markdown(t: &[Timing]) -> String {
    let mut s = String::from("| stage | time (s) | work |\n|---|---:|---|\n");
    for x in t {
        s.push_str(&format!(
            "| {} | {:.3} | {} |\n",
            x.stage.name(),
            x.seconds,
            x.what
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(name: &str) -> ModelRun {
        ModelRun {
            model: name.parse().expect("a model name"),
            solver: "newton".into(),
            nodes: 3,
            points: vec![],
            wall_s: 0.0,
            stop: None,
        }
    }

    #[test]
    fn errors_and_layout() {
        let rows = vec![
            Comparison {
                pressure_pa: 1000.0,
                measured_m: Some(0.010),
                measured_std_m: Some(1e-5),
                simulated_m: vec![Some(0.0102), None],
            },
            Comparison {
                pressure_pa: 2000.0,
                measured_m: Some(0.020),
                measured_std_m: None,
                simulated_m: vec![Some(0.0196), Some(0.021)],
            },
        ];
        // (10.2 - 10) / 10 = +2 %, (19.6 - 20) / 20 = -2 %, (21 - 20) / 20 = +5 %.
        let e = rows[0].rel_errors();
        assert!((e[0].unwrap() - 0.02).abs() < 1e-12 && e[1].is_none());
        let sum = error_summary(&rows, 2);
        assert!((sum[0].0.unwrap() - 0.02).abs() < 1e-12);
        assert!((sum[1].1.unwrap() - 0.05).abs() < 1e-12);
        let runs = [run("tp"), run("van-gelder")];
        let t = terminal(&rows, &runs);
        assert!(t.contains("tp_mm") && t.contains("van-gelder_mm"), "{t}");
        assert!(
            t.contains("+2.00") && t.contains("-2.00") && t.contains("+5.00"),
            "{t}"
        );
        let m = markdown(&rows, &runs);
        assert_eq!(m.lines().count(), 4, "{m}");
        let h = html(&rows, &runs, 0.03);
        assert!(h.contains("class=\"bad\">+5.00"), "{h}");
        assert_eq!(esc("a<b&\"c\""), "a&lt;b&amp;&quot;c&quot;");
    }
}
