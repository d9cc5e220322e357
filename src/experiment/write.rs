//! Experiment files written through the reader's own tables: the values by
//! serde (so a key written is a key read, spelled and typed alike), then
//! comments added around them (what `bulge init` found and how sure it is,
//! what `bulge synth` drew).

use serde::Serialize;
use toml_edit::{DocumentMut, RawString};

use super::{
    CalibrationConfig, CameraConfig, HeightsConfig, PhotosConfig, PressureConfig, SpecimenTable,
    Window,
};

/// The tables of an experiment file to be written, as [`super::Experiment`]
/// reads them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Draft {
    /// `[specimen]`.
    pub specimen: SpecimenTable,
    /// `[photos]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photos: Option<PhotosConfig>,
    /// `[heights]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heights: Option<HeightsConfig>,
    /// `[camera]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraConfig>,
    /// `[calibration]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<CalibrationConfig>,
    /// `[pressure]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure: Option<PressureConfig>,
    /// `[window]` (not written for the circle, the default).
    #[serde(skip_serializing_if = "Window::is_circle")]
    pub window: Window,
}

impl Draft {
    /// A file with only `[specimen]`.
    pub fn new(specimen: SpecimenTable) -> Self {
        Draft {
            specimen,
            photos: None,
            heights: None,
            camera: None,
            calibration: None,
            pressure: None,
            window: Window::Circle,
        }
    }
}

/// Where a comment goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// At the top of the file.
    Head,
    /// Above a table's header: `Table("camera")`.
    Table(&'static str),
    /// Above a key: `Key("calibration", "clamp_row_px")`.
    Key(&'static str, &'static str),
    /// At the end of the file.
    Tail,
}

/// A draft with its comments, rendered by [`Commented::render`].
#[derive(Debug, Clone, PartialEq)]
pub struct Commented {
    /// The values.
    pub draft: Draft,
    notes: Vec<(Place, String)>,
}

impl Commented {
    /// The draft without comments.
    pub fn new(draft: Draft) -> Self {
        Commented {
            draft,
            notes: Vec::new(),
        }
    }

    /// Adds a comment (one or more lines, without their `#`) at `place`;
    /// comments at one place keep their order. A comment on a key or table
    /// that the draft does not write is dropped.
    pub fn note(&mut self, place: Place, text: impl Into<String>) -> &mut Self {
        self.notes.push((place, text.into()));
        self
    }

    /// The file's text.
    ///
    /// # Panics
    /// Never for the tables of [`Draft`], which serialize to TOML; a value
    /// TOML cannot hold would be a bug in those types, which the module's
    /// round-trip tests would show.
    pub fn render(&self) -> String {
        let text = toml::to_string(&self.draft).expect("the experiment's tables serialize to TOML");
        let mut doc: DocumentMut = text
            .parse()
            .expect("toml's own output parses as a TOML document");
        let comment = |text: &str| -> String {
            text.lines()
                .map(|l| {
                    if l.is_empty() {
                        "#\n".to_string()
                    } else {
                        format!("# {l}\n")
                    }
                })
                .collect()
        };
        let mut head = String::new();
        let mut tail = String::new();
        let mut on_tables: Vec<(&str, String)> = Vec::new();
        let mut on_keys: Vec<((&str, &str), String)> = Vec::new();
        for (place, text) in &self.notes {
            let c = comment(text);
            match *place {
                Place::Head => head += &c,
                Place::Tail => tail += &c,
                Place::Table(t) => match on_tables.iter_mut().find(|(k, _)| *k == t) {
                    Some((_, s)) => *s += &c,
                    None => on_tables.push((t, c)),
                },
                Place::Key(t, k) => match on_keys.iter_mut().find(|(p, _)| *p == (t, k)) {
                    Some((_, s)) => *s += &c,
                    None => on_keys.push(((t, k), c)),
                },
            }
        }
        for ((t, k), c) in on_keys {
            if let Some(mut key) = doc
                .get_mut(t)
                .and_then(|i| i.as_table_mut())
                .and_then(|table| table.key_mut(k))
            {
                key.leaf_decor_mut().set_prefix(c);
            }
        }
        let mut first = true;
        let names: Vec<String> = doc.iter().map(|(k, _)| k.to_string()).collect();
        for name in names {
            let Some(table) = doc.get_mut(&name).and_then(|i| i.as_table_mut()) else {
                continue;
            };
            let mut prefix = if first {
                head.clone()
            } else {
                String::from("\n")
            };
            if first && !head.is_empty() {
                prefix.push('\n');
            }
            first = false;
            if let Some((_, c)) = on_tables.iter().find(|(k, _)| *k == name) {
                prefix += c;
            }
            table.decor_mut().set_prefix(prefix);
        }
        if !tail.is_empty() {
            doc.set_trailing(RawString::from(format!("\n{tail}")));
        }
        for (_, item) in doc.iter_mut() {
            if let Some(table) = item.as_table_mut() {
                for (_, value) in table.iter_mut() {
                    scientific(value);
                }
            }
        }
        doc.to_string()
    }
}

/// A float below 1e-4 or from 1e9 up (a standard deviation, a fine scale in
/// m/px) written in the exponent's form, the same number: `1.44e-7` rather
/// than `0.000000144` (a thickness of `0.00035` m stays as it is). Its
/// decor (the spacing and a trailing comment) is kept.
fn scientific(item: &mut toml_edit::Item) {
    let Some(toml_edit::Value::Float(f)) = item.as_value() else {
        return;
    };
    let v = *f.value();
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        return;
    }
    let decor = f.decor().clone();
    if let Ok(mut value) = format!("{v:e}").parse::<toml_edit::Value>() {
        *value.decor_mut() = decor;
        *item = toml_edit::Item::Value(value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::{Experiment, PrebulgeHeight, Specimen};

    fn draft() -> Draft {
        let mut d = Draft::new(SpecimenTable {
            thickness_std_m: Some(1e-5),
            ..SpecimenTable::of(&Specimen {
                radius_m: 0.0375,
                thickness_m: 3.5e-4,
                poisson: 0.45,
                prebulge_height_m: 0.001,
            })
        });
        d.calibration = Some(CalibrationConfig {
            metres_per_pixel: Some(4.6875e-5),
            clamp_row_px: Some(612.25),
            elevation_deg: Some(3.0),
            clamp_row_std_px: Some(0.02),
            ..CalibrationConfig::default()
        });
        d.pressure = Some(PressureConfig {
            csv: "pressure.csv".into(),
            offset_s: None,
            std_pa: Some(5.0),
            relative_std: None,
        });
        d.window = Window::Ellipse {
            semi_axes_m: [0.0375, 0.02],
        };
        d
    }

    fn read_back(text: &str) -> Experiment {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("experiment.toml");
        std::fs::write(&p, text).unwrap();
        Experiment::read(&p).unwrap_or_else(|e| panic!("{e}\n{text}"))
    }

    #[test]
    fn what_is_written_is_read_back_with_its_comments() {
        let mut c = Commented::new(draft());
        c.note(Place::Head, "written by a test\n\nsecond paragraph")
            .note(Place::Table("calibration"), "the clamp plane")
            .note(
                Place::Key("calibration", "clamp_row_px"),
                "found: 612.25 px",
            )
            .note(Place::Key("photos", "roi_px"), "not written: no [photos]")
            .note(Place::Tail, "[report]\nnothing");
        let text = c.render();
        assert!(text.starts_with("# written by a test\n#\n# second paragraph\n\n[specimen]"));
        assert!(text.contains("# the clamp plane\n[calibration]"), "{text}");
        assert!(
            text.contains("# found: 612.25 px\nclamp_row_px = 612.25\n"),
            "{text}"
        );
        assert!(text.contains("metres_per_pixel = 4.6875e-5\n"), "{text}");
        assert!(text.contains("clamp_row_std_px = 0.02\n"), "{text}");
        assert!(!text.contains("not written"), "{text}");
        assert!(text.ends_with("# [report]\n# nothing\n"), "{text}");
        let e = read_back(&text);
        let d = draft();
        assert_eq!(e.specimen, d.specimen.specimen());
        assert_eq!(e.specimen_std.thickness_std_m, 1e-5);
        assert_eq!(e.calibration, d.calibration);
        assert_eq!(e.pressure, d.pressure);
        assert_eq!(e.window, d.window);
        assert!(!e.prebulge_fit && e.photos.is_none() && e.camera.is_none());
    }

    #[test]
    fn a_dome_height_to_fit_is_written_as_the_word() {
        let mut d = draft();
        d.specimen.prebulge_height_m = PrebulgeHeight::Fit;
        let text = Commented::new(d).render();
        assert!(text.contains("prebulge_height_m = \"fit\""), "{text}");
        let e = read_back(&text);
        assert!(e.prebulge_fit);
        assert_eq!(e.specimen.prebulge_height_m, 0.0);
    }
}
