//! The table of laws of a run that chose its law
//! ([`crate::fit::select`]): `laws.csv` and its lines in the report.

use crate::fit::select::Selection;
use crate::io::{CsvOut, fmt_num};

/// `laws.csv`: one row per law, the chosen one marked.
pub fn laws_csv(sel: &Selection) -> CsvOut {
    let mut out = CsvOut::new(&[
        "law",
        "parameters",
        "heights",
        "chi2",
        "dof",
        "chi2_95",
        "p_value",
        "aicc",
        "bic",
        "height_rms_relative_error",
        "max_abs_z",
        "negative_stiffness",
        "springs_rms_relative_deviation",
        "chosen",
        "verdict",
    ]);
    for (i, r) in sel.rows.iter().enumerate() {
        out.row(&[
            r.model.label(),
            r.params.to_string(),
            r.n.to_string(),
            fmt_num(r.chi2),
            r.dof.to_string(),
            fmt_num(r.chi2_95),
            fmt_num(r.p_value),
            fmt_num(r.aicc),
            fmt_num(r.bic),
            fmt_num(r.rms_rel),
            fmt_num(r.max_z),
            (!r.negative_stiffness.is_empty()).to_string(),
            fmt_num(r.springs_rms_rel),
            (i == sel.chosen).to_string(),
            r.verdict().replace(',', ";"),
        ]);
    }
    out
}

/// Per law, `(label, verdict)`, the chosen one marked, for the report's
/// lists and table.
pub fn laws_lines(sel: &Selection) -> Vec<(String, String)> {
    sel.rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let label = format!(
                "{} ({} parameter{}){}",
                r.model.label(),
                r.params,
                if r.params == 1 { "" } else { "s" },
                if i == sel.chosen { ", chosen" } else { "" }
            );
            let aicc = r.aicc.map(|a| format!(", AICc {a:.1}")).unwrap_or_default();
            let rms = r
                .rms_rel
                .map(|v| format!(", rms height error {:.2} %", 100.0 * v))
                .unwrap_or_default();
            (label, format!("{}{aicc}{rms}", r.verdict()))
        })
        .collect()
}
