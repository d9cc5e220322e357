//! The files of a study of one material across specimens
//! ([`crate::fit::study`]), built in memory: `study.csv` (one row per
//! specimen, then the mean, standard deviation, coefficient of variation,
//! the 95 % interval of the mean and the inverse-variance pooled value),
//! `study.svg` (each parameter per specimen with its 95 % error bar, the
//! mean and its interval) and the self-contained `study.html`; with the
//! joint fit of every specimen's heights when given; and the
//! table printed on the terminal. `bulge study` writes them.

use super::html::{CSS, Picture, img, kv};
use super::plot::{Figure, LegendPosition, Panel, Series};
use super::run_files::OutFile;
use super::table::esc;
use crate::fit::study::Study;
use crate::fit::uncertainty::normal_quantile;
use crate::io::{CsvOut, fmt_num};
use crate::pipeline::{PipelineError, Stage};

/// What the study's files show besides the [`Study`] itself.
#[derive(Debug, Clone, Default)]
pub struct StudyInfo {
    /// Title (the study file, or the experiments' folder).
    pub title: String,
    /// The law fitted (e.g. `mooney-rivlin`).
    pub law: String,
    /// Per specimen in the study's order: its thickness, m.
    pub thickness_m: Vec<f64>,
    /// The specimens whose earlier result was read back.
    pub reused: Vec<String>,
    /// The specimens left out, with why.
    pub failed: Vec<(String, String)>,
    /// Settings shared by the specimens, key/value.
    pub settings: Vec<(String, String)>,
    /// One law fitted to every specimen's heights together
    /// ([`crate::fit::study::joint`]), in the order of the study's names,
    /// and its standard errors when known.
    pub joint: Option<(Vec<f64>, Option<Vec<f64>>)>,
}

/// The study's files and its terminal table.
#[derive(Debug, Clone)]
pub struct StudyFiles {
    /// `study.csv`, `study.svg`, `study.png`, `study.html`.
    pub files: Vec<OutFile>,
    /// The table for the terminal.
    pub terminal: String,
}

/// The column of a parameter's standard deviation: `c1_pa` -> `c1_std_pa`,
/// a parameter without a unit (`alpha1`) -> `alpha1_std`.
pub fn std_column(name: &str) -> String {
    match name.strip_suffix("_pa") {
        Some(base) => format!("{base}_std_pa"),
        None => format!("{name}_std"),
    }
}

/// A parameter for people: stresses in kPa.
fn shown(name: &str) -> (String, f64) {
    match name.strip_suffix("_pa") {
        Some(base) => (format!("{base} (kPa)"), 1e-3),
        None => (name.to_string(), 1.0),
    }
}

/// The summary rows: label, value and (for the mean and the pooled value)
/// its standard error per parameter.
type SummaryRow = (&'static str, Vec<f64>, Option<Vec<f64>>);

fn summary(s: &Study, joint: Option<&(Vec<f64>, Option<Vec<f64>>)>) -> Vec<SummaryRow> {
    let n = s.specimens.len() as f64;
    let mut rows: Vec<SummaryRow> = vec![
        (
            "mean",
            s.mean.clone(),
            Some(s.std.iter().map(|v| v / n.sqrt()).collect()),
        ),
        ("std", s.std.clone(), None),
        ("cv", s.cv.clone(), None),
        ("ci95_low", s.mean_ci95.iter().map(|c| c[0]).collect(), None),
        (
            "ci95_high",
            s.mean_ci95.iter().map(|c| c[1]).collect(),
            None,
        ),
    ];
    if let Some((v, se)) = &s.pooled {
        rows.push(("pooled", v.clone(), Some(se.clone())));
    }
    if let Some((v, se)) = joint {
        rows.push(("joint", v.clone(), se.clone()));
    }
    rows
}

/// `study.csv` (the summary rows: mean, std, cv, ci95_low, ci95_high,
/// pooled, joint, each when there is one).
pub fn csv(s: &Study, info: &StudyInfo) -> CsvOut {
    let mut head = vec!["specimen".to_string(), "thickness_m".to_string()];
    for n in &s.names {
        head.push(n.clone());
        head.push(std_column(n));
    }
    head.push("outlier".into());
    let mut out = CsvOut::new(&head);
    for (j, f) in s.specimens.iter().enumerate() {
        let mut row = vec![f.name.clone(), fmt_num(info.thickness_m.get(j).copied())];
        for k in 0..s.names.len() {
            row.push(fmt_num(Some(f.values[k])));
            row.push(fmt_num(f.std_errors.as_ref().map(|e| e[k])));
        }
        let flagged: Vec<&str> = s
            .names
            .iter()
            .zip(&f.outlier)
            .filter(|(_, o)| **o)
            .map(|(n, _)| n.as_str())
            .collect();
        row.push(flagged.join(" "));
        out.row(&row);
    }
    for (label, v, se) in summary(s, info.joint.as_ref()) {
        let mut row = vec![label.to_string(), String::new()];
        for k in 0..s.names.len() {
            row.push(fmt_num(Some(v[k])));
            row.push(fmt_num(se.as_ref().map(|e| e[k])));
        }
        row.push(String::new());
        out.row(&row);
    }
    out
}

/// Each parameter against the specimen's number (1 to n, the table's
/// order) with its 95 % error bar, the mean as a line and its 95 % interval
/// as a dashed pair.
pub fn figure(s: &Study) -> Figure {
    let z = normal_quantile(0.975);
    let n = s.specimens.len();
    let panels = s
        .names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let (label, f) = shown(name);
            let pts: Vec<(f64, f64)> = s
                .specimens
                .iter()
                .enumerate()
                .map(|(j, sp)| ((j + 1) as f64, sp.values[k] * f))
                .collect();
            let errs: Vec<f64> = s
                .specimens
                .iter()
                .map(|sp| sp.std_errors.as_ref().map_or(0.0, |e| z * e[k] * f))
                .collect();
            let across = |v: f64| vec![(0.5, v * f), (n as f64 + 0.5, v * f)];
            Panel::new("specimen (as numbered in the table)", label.clone())
                .titled(label)
                .with(
                    Series::scatter("specimen (95 % error bar)", pts)
                        .with_errors(errs)
                        .color(0),
                )
                .with(Series::line("mean", across(s.mean[k])).color(3))
                .with(
                    Series::line("95 % interval of the mean", across(s.mean_ci95[k][0]))
                        .color(1)
                        .dashed(),
                )
                .with(
                    Series::line("", across(s.mean_ci95[k][1]))
                        .color(1)
                        .dashed(),
                )
                .legend(LegendPosition::UpperRight)
        })
        .collect();
    let h = 350 * s.names.len().max(1) as u32 + 100;
    Figure::new("The material across the specimens", panels).size(900, h)
}

fn number(name: &str, v: f64) -> String {
    let (_, f) = shown(name);
    format!("{:.4}", v * f)
}

/// The table on the terminal (stresses in kPa), with the joint fit's
/// values (and their 95 % intervals when known) when given.
pub fn terminal(s: &Study, joint: Option<&(Vec<f64>, Option<Vec<f64>>)>) -> String {
    let z = normal_quantile(0.975);
    let w = s
        .specimens
        .iter()
        .map(|f| f.name.len())
        .max()
        .unwrap_or(0)
        .max(9);
    let mut t = format!("{:<w$}", "specimen");
    for n in &s.names {
        t.push_str(&format!(" {:>24}", format!("{} +- 95 %", shown(n).0)));
    }
    t.push_str("  outlier\n");
    for f in &s.specimens {
        t.push_str(&format!("{:<w$}", f.name));
        for (k, n) in s.names.iter().enumerate() {
            let e = f
                .std_errors
                .as_ref()
                .map_or(String::from("-"), |e| number(n, z * e[k]));
            t.push_str(&format!(
                " {:>24}",
                format!("{} +- {e}", number(n, f.values[k]))
            ));
        }
        let flagged: Vec<&str> = s
            .names
            .iter()
            .zip(&f.outlier)
            .filter(|(_, o)| **o)
            .map(|(n, _)| n.as_str())
            .collect();
        t.push_str(&format!("  {}\n", flagged.join(" ")));
    }
    t.push_str(&format!("{:<w$}", "mean"));
    for (k, n) in s.names.iter().enumerate() {
        let [lo, hi] = s.mean_ci95[k];
        t.push_str(&format!(
            " {:>24}",
            format!(
                "{} [{}, {}]",
                number(n, s.mean[k]),
                number(n, lo),
                number(n, hi)
            )
        ));
    }
    t.push_str(&format!("\n{:<w$}", "cv"));
    for cv in &s.cv {
        t.push_str(&format!(" {:>24}", format!("{:.2} %", 100.0 * cv)));
    }
    if let Some((v, se)) = &s.pooled {
        t.push_str(&format!("\n{:<w$}", "pooled"));
        for (k, n) in s.names.iter().enumerate() {
            t.push_str(&format!(
                " {:>24}",
                format!("{} +- {}", number(n, v[k]), number(n, z * se[k]))
            ));
        }
    }
    t.push('\n');
    if let Some((j, se)) = joint {
        t.push_str(&format!("{:<w$}", "joint"));
        for (k, n) in s.names.iter().enumerate() {
            let cell = match se {
                Some(se) => format!("{} +- {}", number(n, j[k]), number(n, z * se[k])),
                None => number(n, j[k]),
            };
            t.push_str(&format!(" {cell:>24}"));
        }
        t.push('\n');
    }
    t
}

/// `study.html`: one self-contained page (inline CSS, the figure embedded).
pub fn html(s: &Study, info: &StudyInfo, png: Vec<u8>) -> String {
    let z = normal_quantile(0.975);
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    h.push_str(&format!(
        "<title>bulge study: {}</title><style>{CSS}</style></head><body>\n<h1>Material study: {}</h1>\n",
        esc(&info.title),
        esc(&info.title)
    ));
    h.push_str(&format!(
        "<p>{} specimens, each through the whole pipeline (track &rarr; stress &rarr; fit, the {} law corrected to its own \
         heights through the exact axisymmetric inflation with its own thickness and radius); made by <code>bulge study</code>. \
         Each specimen's own report is in <code>specimens/&lt;name&gt;/report.html</code>.</p>\n",
        s.specimens.len(),
        esc(&info.law)
    ));
    h.push_str(
        "<h2>Parameters</h2>\n<p>Per specimen: the corrected value &plusmn; 1.96 first-order standard errors. Mean: over \
         the specimens, with the 95 % interval by Student's t with n &minus; 1 degrees of freedom (the specimens' scatter). \
         Pooled: the inverse-variance weighted mean and its standard error. Joint: one law fitted to every \
         specimen's heights together, each with its own dimensions. A parameter in red lies outside the 99 % \
         prediction interval of the other specimens.</p>\n<table class=\"num\"><tr><th>specimen</th><th>thickness (mm)</th>",
    );
    for n in &s.names {
        h.push_str(&format!("<th>{}</th>", esc(&shown(n).0)));
    }
    h.push_str("</tr>");
    for (j, f) in s.specimens.iter().enumerate() {
        h.push_str(&format!(
            "<tr><td style=\"text-align:left\">{}</td><td>{}</td>",
            esc(&f.name),
            info.thickness_m
                .get(j)
                .map_or(String::new(), |t| format!("{:.4}", t * 1e3))
        ));
        for (k, n) in s.names.iter().enumerate() {
            let cls = if f.outlier[k] { " class=\"bad\"" } else { "" };
            let e = f.std_errors.as_ref().map_or(String::new(), |e| {
                format!(" &plusmn; {}", number(n, z * e[k]))
            });
            h.push_str(&format!("<td{cls}>{}{e}</td>", number(n, f.values[k])));
        }
        h.push_str("</tr>");
    }
    for (label, v, se) in summary(s, info.joint.as_ref()) {
        h.push_str(&format!(
            "<tr class=\"sum\"><td style=\"text-align:left\">{label}</td><td></td>"
        ));
        for (k, n) in s.names.iter().enumerate() {
            let cell = match label {
                "cv" => format!("{:.2} %", 100.0 * v[k]),
                _ => match &se {
                    Some(e) => format!("{} &plusmn; {}", number(n, v[k]), number(n, z * e[k])),
                    None => number(n, v[k]),
                },
            };
            h.push_str(&format!("<td>{cell}</td>"));
        }
        h.push_str("</tr>");
    }
    h.push_str("</table>\n");
    h.push_str(&img(&Picture {
        caption: "Each parameter per specimen with its 95 % error bar; the mean (solid) and its 95 % interval (dashed)."
            .into(),
        png,
    }));
    if !info.reused.is_empty() || !info.failed.is_empty() {
        h.push_str("<ul class=\"notes\">");
        if !info.reused.is_empty() {
            h.push_str(&format!(
                "<li>reused (inputs and settings unchanged since the last study): {}</li>",
                esc(&info.reused.join(", "))
            ));
        }
        for (name, why) in &info.failed {
            h.push_str(&format!("<li>left out: {}: {}</li>", esc(name), esc(why)));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("<h2>Settings used</h2>\n");
    h.push_str(&kv(&info.settings));
    h.push_str("</body></html>\n");
    h
}

/// Every file of the study, and the terminal table.
pub fn study_files(s: &Study, info: &StudyInfo) -> Result<StudyFiles, PipelineError> {
    let bad = |what: &str, e: super::plot::PlotError| PipelineError::Output(format!("{what}: {e}"));
    let fig = figure(s);
    let svg = fig.to_svg().map_err(|e| bad("study.svg", e))?;
    let png = fig.to_png().map_err(|e| bad("study.png", e))?;
    let page = html(s, info, png.clone());
    let file = |name, bytes| OutFile {
        name,
        stage: Stage::Report,
        bytes,
    };
    Ok(StudyFiles {
        files: vec![
            file("study.csv", csv(s, info).into_bytes()),
            file("study.svg", svg.into_bytes()),
            file("study.png", png),
            file("study.html", page.into_bytes()),
        ],
        terminal: terminal(s, info.joint.as_ref()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::study::{SpecimenFit, gather};

    fn study() -> Study {
        let fits = (1..=4)
            .map(|i| SpecimenFit {
                name: format!("s<{i}>"),
                values: vec![1e5 + 1e3 * i as f64, 2.0 + 0.1 * i as f64],
                std_errors: Some(vec![500.0, 0.05]),
                outlier: vec![],
            })
            .collect();
        gather(vec!["mu1_pa".into(), "alpha1".into()], fits).unwrap()
    }

    /// One row per specimen then the summary rows, the units in the column
    /// names; the page is self-contained and escapes the names.
    #[test]
    fn csv_and_page() {
        let s = study();
        let info = StudyInfo {
            title: "t".into(),
            thickness_m: vec![3.5e-4; 4],
            joint: Some((vec![1.02e5, 2.2], Some(vec![1.5e3, 0.1]))),
            ..StudyInfo::default()
        };
        let text = String::from_utf8(csv(&s, &info).into_bytes()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "specimen,thickness_m,mu1_pa,mu1_std_pa,alpha1,alpha1_std,outlier"
        );
        let labels: Vec<&str> = lines[1..]
            .iter()
            .map(|l| l.split(',').next().unwrap())
            .collect();
        assert_eq!(
            labels,
            [
                "s<1>",
                "s<2>",
                "s<3>",
                "s<4>",
                "mean",
                "std",
                "cv",
                "ci95_low",
                "ci95_high",
                "pooled",
                "joint"
            ]
        );
        assert!(lines[5].starts_with("mean,,102500,"), "{}", lines[5]);
        let f = study_files(&s, &info).unwrap();
        let page = String::from_utf8(f.files[3].bytes.clone()).unwrap();
        assert!(page.contains("s&lt;1&gt;") && page.contains("data:image/png;base64,"));
        assert!(
            !page.contains("http://") && !page.contains("https://") && !page.contains("<script")
        );
        assert!(f.terminal.contains("mu1 (kPa) +- 95 %"), "{}", f.terminal);
        assert!(f.terminal.contains("joint"), "{}", f.terminal);
    }
}
