//! `report.html`: one self-contained file (inline CSS, images embedded as
//! base64 PNG, no script, no network) that a colleague can open in any
//! browser: the experiment, photos with the matched template drawn, height
//! against pressure, the material fit, the error table, the settings used and
//! the time each stage took.

use super::table::{self, Timing, esc};
use crate::pipeline::{Comparison, ModelRun};

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    use ::base64::Engine as _;
    ::base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// An embedded picture.
#[derive(Debug, Clone)]
pub struct Picture {
    /// Caption under it.
    pub caption: String,
    /// PNG bytes.
    pub png: Vec<u8>,
}

/// Everything the report shows.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Title (the experiment file).
    pub title: String,
    /// The experiment as key/value pairs (specimen, photos, calibration).
    pub experiment: Vec<(String, String)>,
    /// Annotated photos.
    pub photos: Vec<Picture>,
    /// Height against pressure.
    pub heights: Option<Picture>,
    /// The fit figure.
    pub fit: Option<Picture>,
    /// The material file as written.
    pub material_toml: String,
    /// Per model, whether it agrees with the measured heights within the
    /// uncertainty (model, verdict).
    pub verdicts: Vec<(String, String)>,
    /// Why the law was chosen and each law's verdict on the heights, when
    /// the run chose it.
    pub laws: Option<(String, Vec<(String, String)>)>,
    /// The comparison rows.
    pub rows: Vec<Comparison>,
    /// The simulated models.
    pub runs: Vec<ModelRun>,
    /// Settings used, key/value.
    pub settings: Vec<(String, String)>,
    /// Stage timings.
    pub timings: Vec<Timing>,
    /// Warnings and notes (unsolved pressures, fit warnings).
    pub notes: Vec<String>,
}

pub(crate) const CSS: &str = "body{font-family:-apple-system,'Segoe UI',Helvetica,Arial,sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}\
h1{font-size:1.6em;border-bottom:2px solid #36c;padding-bottom:.2em}h2{font-size:1.25em;margin-top:1.8em;color:#234}\
table{border-collapse:collapse;margin:.6em 0;font-size:.92em}td,th{border:1px solid #ccc;padding:.25em .6em}th{background:#eef2f8}\
table.num td{text-align:right;font-variant-numeric:tabular-nums}tr.sum td{background:#f6f6f6;font-weight:600}\
td.bad{color:#b00;font-weight:600}.kv td:first-child{font-weight:600;white-space:nowrap}\
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #ddd}figcaption{font-size:.88em;color:#555}\
.photos{display:flex;flex-wrap:wrap;gap:12px}.photos figure{flex:1 1 300px;margin:0}\
pre{background:#f6f8fa;padding:.8em;overflow-x:auto;font-size:.85em}ul.notes li{color:#850}";

pub(crate) fn kv(pairs: &[(String, String)]) -> String {
    let mut s = String::from("<table class=\"kv\">");
    for (k, v) in pairs {
        s.push_str(&format!("<tr><td>{}</td><td>{}</td></tr>", esc(k), esc(v)));
    }
    s.push_str("</table>\n");
    s
}

pub(crate) fn img(p: &Picture) -> String {
    format!(
        "<figure><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>\n",
        esc(&p.caption),
        base64(&p.png),
        esc(&p.caption)
    )
}

/// Relative error above which a table cell is marked (2 %, the closed-loop
/// target of TP MSS).
pub const FLAG: f64 = 0.02;

impl Report {
    /// The whole HTML document.
    pub fn to_html(&self) -> String {
        let mut s = String::new();
        s.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
        s.push_str(&format!(
            "<title>bulge run: {}</title><style>{CSS}</style></head><body>\n",
            esc(&self.title)
        ));
        s.push_str(&format!(
            "<h1>Bubble inflation test: {}</h1>\n",
            esc(&self.title)
        ));
        s.push_str(
            "<p>Photos &rarr; apex heights (track) &rarr; stress and strain (stress) &rarr; material (fit) &rarr; \
             simulated heights (simulate: mass-spring models and the exact axisymmetric reference of the same material) \
             &rarr; this report, made by <code>bulge run</code>.</p>\n",
        );
        s.push_str("<h2>Measured against simulated heights</h2>\n");
        s.push_str(&format!(
            "<p>Relative error = simulated / measured &minus; 1; cells above {:.0} % in red. Measured heights are \
             &plusmn; one standard deviation (height_std_m of the tracking stage).</p>\n",
            FLAG * 100.0
        ));
        s.push_str(&table::html(&self.rows, &self.runs, FLAG));
        if !self.verdicts.is_empty() {
            s.push_str(
                "<p>Within the uncertainty? Each model's height minus the measured one, over the standard deviation of \
                 that difference (the measured height's own, the corrected law's through its parameters' covariance, \
                 the calibration, pressure gauge and specimen included):</p>\n",
            );
            s.push_str("<table><tr><th>model</th><th>verdict</th></tr>");
            for (m, v) in &self.verdicts {
                let bad = if v.starts_with("misses") {
                    " class=\"bad\""
                } else {
                    ""
                };
                s.push_str(&format!(
                    "<tr><td>{}</td><td{bad}>{}</td></tr>",
                    esc(m),
                    esc(v)
                ));
            }
            s.push_str("</table>\n");
        }
        if let Some((why, lines)) = &self.laws {
            s.push_str("<h2>The law the heights call for</h2>\n");
            s.push_str(&format!(
                "<p>Every law fitted and corrected to the heights, then ranked on them (laws.csv): chosen {}</p>\n",
                esc(why)
            ));
            s.push_str("<table><tr><th>law</th><th>on the heights</th></tr>");
            for (m, v) in lines {
                let bad = if v.contains("misses") || v.contains("negative stiffness") {
                    " class=\"bad\""
                } else {
                    ""
                };
                s.push_str(&format!(
                    "<tr><td>{}</td><td{bad}>{}</td></tr>",
                    esc(m),
                    esc(v)
                ));
            }
            s.push_str("</table>\n");
        }
        if let Some(p) = &self.heights {
            s.push_str(&img(p));
        }
        if !self.notes.is_empty() {
            s.push_str("<ul class=\"notes\">");
            for n in &self.notes {
                s.push_str(&format!("<li>{}</li>", esc(n)));
            }
            s.push_str("</ul>\n");
        }
        s.push_str("<h2>Experiment</h2>\n");
        s.push_str(&kv(&self.experiment));
        if !self.photos.is_empty() {
            s.push_str(
                "<h2>Photos</h2>\n<p>Blue: the search region; green: the matched template; red: the apex found.</p>\n<div class=\"photos\">",
            );
            for p in &self.photos {
                s.push_str(&img(p));
            }
            s.push_str("</div>\n");
        }
        s.push_str("<h2>Material</h2>\n");
        if let Some(p) = &self.fit {
            s.push_str(&img(p));
        }
        s.push_str(&format!(
            "<p>material.toml:</p><pre>{}</pre>\n",
            esc(&self.material_toml)
        ));
        s.push_str("<h2>Settings used</h2>\n");
        s.push_str(&kv(&self.settings));
        s.push_str("<h2>Speed</h2>\n<table class=\"num\"><tr><th>stage</th><th>time (s)</th><th>work</th></tr>");
        let total: f64 = self.timings.iter().map(|t| t.seconds).sum();
        for t in &self.timings {
            s.push_str(&format!(
                "<tr><td style=\"text-align:left\">{}</td><td>{:.3}</td><td style=\"text-align:left\">{}</td></tr>",
                t.stage.name(),
                t.seconds,
                esc(&t.what)
            ));
        }
        s.push_str(&format!("<tr class=\"sum\"><td style=\"text-align:left\">total</td><td>{total:.3}</td><td></td></tr></table>\n"));
        s.push_str("<h2>Simulation runs</h2>\n<table class=\"num\"><tr><th>model</th><th>solver</th><th>nodes</th><th>pressures solved</th><th>time (s)</th></tr>");
        for r in &self.runs {
            let solved = r.points.iter().filter(|p| p.height_m.is_some()).count();
            s.push_str(&format!(
                "<tr><td style=\"text-align:left\">{}</td><td style=\"text-align:left\">{}</td><td>{}</td><td>{} of {}</td><td>{:.3}</td></tr>",
                esc(r.model.name()),
                esc(&r.solver),
                if r.nodes == 0 { "-".to_string() } else { r.nodes.to_string() },
                solved,
                r.points.len(),
                r.wall_s
            ));
        }
        s.push_str("</table>\n</body></html>\n");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        // RFC 4648 section 10.
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn report_is_self_contained() {
        let r = Report {
            title: "exp <1>".into(),
            photos: vec![Picture {
                caption: "frame 0".into(),
                png: vec![1, 2, 3],
            }],
            ..Report::default()
        };
        let h = r.to_html();
        assert!(h.contains("exp &lt;1&gt;"));
        assert!(h.contains("data:image/png;base64,AQID"));
        assert!(!h.contains("http://") && !h.contains("https://") && !h.contains("<script"));
    }
}
