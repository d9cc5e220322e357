//! XY charts to SVG and PNG with plotters, for every stage that draws.
//!
//! A [`Figure`] is a stack of [`Panel`]s sharing the width (for instance a
//! fit above its residuals); a panel holds line and scatter [`Series`], the
//! scatter ones with optional vertical error bars, axis labels (put the unit
//! in the label: `"stress (MPa)"`) and a legend. The text is drawn with the
//! bundled DejaVu Sans (`assets/DejaVuSans.ttf`, registered once through
//! plotters' `ab_glyph` feature), so the PNG looks the same on a machine
//! without system fonts, and the SVG names the same family.
//!
//! ```no_run
//! use bulge::report::plot::{Figure, Panel, Series};
//! let panel = Panel::new("strain (-)", "stress (MPa)")
//!     .with(Series::scatter("data", vec![(0.1, 0.2), (0.2, 0.35)]))
//!     .with(Series::line("fit", vec![(0.0, 0.0), (0.25, 0.42)]));
//! let fig = Figure::new("Example", vec![panel]);
//! let svg: String = fig.to_svg().unwrap();
//! fig.write_png(std::path::Path::new("example.png")).unwrap();
//! ```

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// The bundled font.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
/// Family name under which the bundled font is registered.
pub const FONT: &str = "sans-serif";

static REGISTER: Once = Once::new();

/// Registers the bundled font with plotters (idempotent).
pub fn register_font() {
    REGISTER.call_once(|| {
        // The font is a valid TrueType file bundled with the sources; the
        // unit test `font_registers` guards this.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS);
    });
}

/// Why a figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A drawing error from plotters.
    #[error("cannot draw the figure: {0}")]
    Draw(String),
    /// A file error.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The target file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Nothing to draw.
    #[error("the figure has no finite data to draw")]
    Empty,
}

fn draw_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Connected line.
    Line,
    /// Dashed connected line.
    Dashed,
    /// Markers.
    Scatter,
}

/// Most points of a series drawn (see `Series::stride`).
const MAX_DRAWN: usize = 5000;

/// One data series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend entry; empty for none.
    pub name: String,
    /// `(x, y)` points; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line or markers.
    pub style: Style,
    /// Symmetric vertical error bars (one per point), scatter only.
    pub y_err: Option<Vec<f64>>,
    /// Palette index; `None` takes the series' position.
    pub color: Option<usize>,
}

impl Series {
    /// A line series.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            style: Style::Line,
            y_err: None,
            color: None,
        }
    }

    /// A scatter series.
    pub fn scatter(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            style: Style::Scatter,
            ..Self::line(name, points)
        }
    }

    /// Adds vertical error bars (half-widths).
    pub fn with_errors(mut self, y_err: Vec<f64>) -> Self {
        self.y_err = Some(y_err);
        self
    }

    /// Dashed line.
    pub fn dashed(mut self) -> Self {
        self.style = Style::Dashed;
        self
    }

    /// Fixes the palette colour.
    pub fn color(mut self, index: usize) -> Self {
        self.color = Some(index);
        self
    }

    /// Every `stride()`-th point is drawn: a figure of a million markers is
    /// a file of hundreds of megabytes that shows no more than a few
    /// thousand would.
    fn stride(&self) -> usize {
        self.points.len().div_ceil(MAX_DRAWN).max(1)
    }

    /// The legend entry, saying when only some points are drawn.
    fn label(&self) -> String {
        match self.stride() {
            1 => self.name.clone(),
            k => format!("{} (1 in {k} of {} drawn)", self.name, self.points.len()),
        }
    }

    fn finite(&self) -> impl Iterator<Item = (usize, (f64, f64))> + '_ {
        self.points
            .iter()
            .copied()
            .enumerate()
            .step_by(self.stride())
            .filter(|(_, (x, y))| x.is_finite() && y.is_finite())
    }
}

/// Where the legend goes.
pub use plotters::chart::SeriesLabelPosition as LegendPosition;

/// One chart: axes, labels and series.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Title above the panel (optional).
    pub title: Option<String>,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Draw a horizontal line at y = 0 (residual plots).
    pub zero_line: bool,
    /// Legend position.
    pub legend: LegendPosition,
    /// Relative height of the panel in its figure.
    pub weight: f64,
}

impl Panel {
    /// An empty panel with axis labels.
    pub fn new(x_label: impl Into<String>, y_label: impl Into<String>) -> Self {
        Self {
            title: None,
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            zero_line: false,
            legend: LegendPosition::UpperLeft,
            weight: 1.0,
        }
    }

    /// Adds a series.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Sets the title.
    pub fn titled(mut self, t: impl Into<String>) -> Self {
        self.title = Some(t.into());
        self
    }

    /// Draws y = 0.
    pub fn zero_line(mut self) -> Self {
        self.zero_line = true;
        self
    }

    /// Relative height.
    pub fn weight(mut self, w: f64) -> Self {
        self.weight = w;
        self
    }

    /// Legend position.
    pub fn legend(mut self, p: LegendPosition) -> Self {
        self.legend = p;
        self
    }

    fn ranges(&self) -> Option<((f64, f64), (f64, f64))> {
        let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
        let mut yr = (f64::INFINITY, f64::NEG_INFINITY);
        for s in &self.series {
            for (i, (x, y)) in s.finite() {
                let e = s
                    .y_err
                    .as_ref()
                    .and_then(|e| e.get(i).copied())
                    .filter(|e| e.is_finite())
                    .unwrap_or(0.0)
                    .abs();
                xr = (xr.0.min(x), xr.1.max(x));
                yr = (yr.0.min(y - e), yr.1.max(y + e));
            }
        }
        if self.zero_line {
            yr = (yr.0.min(0.0), yr.1.max(0.0));
        }
        (xr.0 <= xr.1 && yr.0 <= yr.1).then(|| (pad(xr), pad(yr)))
    }
}

/// Widens a range by 5 % each side (and a degenerate one to a unit width).
fn pad((lo, hi): (f64, f64)) -> (f64, f64) {
    let w = hi - lo;
    if w > 0.0 {
        (lo - 0.05 * w, hi + 0.05 * w)
    } else {
        let d = if lo != 0.0 { 0.1 * lo.abs() } else { 1.0 };
        (lo - d, hi + d)
    }
}

/// Tick label: plain with up to 4 significant digits, scientific when
/// very large or small.
pub fn tick(v: f64) -> String {
    if v.abs() < 1e-12 {
        // Round-off residue of a tick at zero (e.g. -2.8e-17).
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let digits = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Tick label on an axis spanning `[lo, hi]`: as many decimals as the tick
/// spacing (about a tenth of the span) needs, scientific notation when the
/// axis values are very large or small, and "0" for round-off residues of
/// zero.
pub fn tick_in(v: f64, lo: f64, hi: f64) -> String {
    let span = (hi - lo).abs();
    if span.is_nan() || span <= 0.0 || !v.is_finite() {
        return tick(v);
    }
    if v.abs() < 1e-9 * span {
        return "0".into();
    }
    let step = span / 10.0;
    let mag = lo.abs().max(hi.abs());
    if !(1e-3..1e5).contains(&mag) {
        let p = ((mag / step).log10().ceil() as i64).clamp(1, 6) as usize;
        return format!("{v:.p$e}");
    }
    let decimals = (1 - step.log10().floor() as i64).clamp(0, 10) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Colour-blind-safe palette (Okabe & Ito 2008, black first; its yellow,
/// unreadable on white, replaced by dark red).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(153, 0, 0),
];

/// A stack of panels with a title.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Title above the whole figure.
    pub title: String,
    /// Panels, top to bottom.
    pub panels: Vec<Panel>,
    /// Size in pixels (SVG user units).
    pub size: (u32, u32),
}

impl Figure {
    /// A figure of 900 x 700 pixels.
    pub fn new(title: impl Into<String>, panels: Vec<Panel>) -> Self {
        Self {
            title: title.into(),
            panels,
            size: (900, 700),
        }
    }

    /// Sets the size in pixels.
    pub fn size(mut self, w: u32, h: u32) -> Self {
        self.size = (w, h);
        self
    }

    /// Draws into any plotters backend.
    pub fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        register_font();
        if self.panels.iter().all(|p| p.ranges().is_none()) {
            return Err(PlotError::Empty);
        }
        root.fill(&WHITE).map_err(draw_err)?;
        let root = root
            .titled(&self.title, (FONT, 22).into_font())
            .map_err(draw_err)?;
        let total: f64 = self
            .panels
            .iter()
            .map(|p| p.weight.max(0.0))
            .sum::<f64>()
            .max(1e-9);
        let mut rest = root;
        for (k, panel) in self.panels.iter().enumerate() {
            let area = if k + 1 == self.panels.len() {
                rest.clone()
            } else {
                let h = rest.dim_in_pixel().1 as f64;
                let remaining: f64 = self.panels[k..].iter().map(|p| p.weight.max(0.0)).sum();
                let px = (h * panel.weight.max(0.0) / remaining.max(1e-9)).round() as i32;
                let (top, bottom) = rest.split_vertically(px);
                rest = bottom;
                top
            };
            let _ = total;
            draw_panel(&area, panel)?;
        }
        Ok(())
    }

    /// Renders to an SVG document in memory.
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, self.size).into_drawing_area();
            self.draw(root.clone())?;
            root.present().map_err(draw_err)?;
        }
        Ok(buf)
    }

    /// Writes an SVG file whole or not at all.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        let svg = self.to_svg()?;
        crate::io::write_atomic(path, svg.as_bytes()).map_err(|source| PlotError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// The figure as PNG bytes (RGB, drawn in memory).
    pub fn to_png(&self) -> Result<Vec<u8>, PlotError> {
        let (w, h) = self.size;
        let mut rgb = vec![0u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, self.size).into_drawing_area();
            self.draw(root.clone())?;
            root.present().map_err(draw_err)?;
        }
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(draw_err)?;
        writer.write_image_data(&rgb).map_err(draw_err)?;
        writer.finish().map_err(draw_err)?;
        Ok(out)
    }

    /// Writes a PNG file whole or not at all ([`crate::io::write_atomic`]).
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        let png = self.to_png()?;
        crate::io::write_atomic(path, &png).map_err(|source| PlotError::Io {
            path: path.display().to_string(),
            source,
        })
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), PlotError> {
    let Some(((x0, x1), (y0, y1))) = panel.ranges() else {
        return Ok(());
    };
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    if let Some(t) = &panel.title {
        builder.caption(t, (FONT, 17).into_font());
    }
    let mut chart = builder
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FONT, 13).into_font())
        .axis_desc_style((FONT, 15).into_font())
        .x_label_formatter(&|v| tick_in(*v, x0, x1))
        .y_label_formatter(&|v| tick_in(*v, y0, y1))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(draw_err)?;
    if panel.zero_line {
        chart
            .draw_series(LineSeries::new(
                [(x0, 0.0), (x1, 0.0)],
                RGBColor(150, 150, 150),
            ))
            .map_err(draw_err)?;
    }
    let mut legend = false;
    for (k, s) in panel.series.iter().enumerate() {
        let color = PALETTE[s.color.unwrap_or(k) % PALETTE.len()];
        let pts: Vec<(f64, f64)> = s.finite().map(|(_, p)| p).collect();
        let anno = match s.style {
            Style::Line => chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(draw_err)?,
            Style::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(2)))
                .map_err(draw_err)?,
            Style::Scatter => {
                if let Some(err) = &s.y_err {
                    let bars: Vec<_> = s
                        .finite()
                        .filter_map(|(i, (x, y))| {
                            let e = err.get(i).copied().filter(|e| e.is_finite())?.abs();
                            Some(ErrorBar::new_vertical(
                                x,
                                y - e,
                                y,
                                y + e,
                                color.stroke_width(1),
                                6,
                            ))
                        })
                        .collect();
                    chart.draw_series(bars).map_err(draw_err)?;
                }
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, color.filled())))
                    .map_err(draw_err)?
            }
        };
        if !s.name.is_empty() {
            legend = true;
            match s.style {
                Style::Scatter => anno
                    .label(s.label())
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled())),
                _ => anno.label(s.label()).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                }),
            };
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .position(panel.legend.clone())
            .label_font((FONT, 13).into_font())
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(120, 120, 120))
            .draw()
            .map_err(draw_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> Figure {
        let fit = Panel::new("stretch (-)", "stress (MPa)")
            .with(
                Series::scatter("data", vec![(1.0, 0.0), (1.5, 0.4), (2.0, 0.6)])
                    .with_errors(vec![0.02, 0.03, f64::NAN]),
            )
            .with(Series::line(
                "fit",
                vec![(1.0, 0.0), (1.5, 0.41), (2.0, 0.59)],
            ))
            .with(Series::line("other", vec![(1.0, 0.0), (2.0, 0.7)]).dashed())
            .weight(2.0);
        let res = Panel::new("stretch (-)", "residual (kPa)")
            .with(Series::scatter(
                "",
                vec![(1.0, 0.0), (1.5, -10.0), (2.0, 10.0), (2.5, f64::NAN)],
            ))
            .zero_line();
        Figure::new("Test figure", vec![fit, res])
    }

    /// A million markers draw as a few thousand, and the legend says so.
    #[test]
    fn large_series_are_thinned_and_labelled() {
        let pts: Vec<(f64, f64)> = (0..1_000_000)
            .map(|i| (i as f64, (i as f64).sqrt()))
            .collect();
        let small = Figure::new(
            "small",
            vec![Panel::new("x", "y").with(Series::scatter("data", pts[..5000].to_vec()))],
        )
        .to_svg()
        .unwrap();
        let big = Figure::new(
            "big",
            vec![Panel::new("x", "y").with(Series::scatter("data", pts))],
        )
        .to_svg()
        .unwrap();
        assert!(big.contains("data (1 in 200 of 1000000 drawn)"));
        assert!(!small.contains("drawn)"));
        assert!(
            big.len() < 2 * small.len(),
            "{} vs {} bytes",
            big.len(),
            small.len()
        );
    }

    #[test]
    fn font_registers() {
        assert!(
            plotters::style::register_font("bulge-test", FontStyle::Normal, DEJAVU_SANS).is_ok()
        );
    }

    #[test]
    fn svg_has_labels_and_series() {
        let svg = figure().to_svg().unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        for needle in [
            "Test figure",
            "stress (MPa)",
            "residual (kPa)",
            "data",
            "fit",
            "<circle",
            "<polyline",
        ] {
            assert!(svg.contains(needle), "missing {needle}");
        }
    }

    #[test]
    fn png_written_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.png");
        figure().write_png(&p).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn empty_figure_refused() {
        let f = Figure::new(
            "x",
            vec![Panel::new("a", "b").with(Series::line("n", vec![(f64::NAN, 1.0)]))],
        );
        assert!(matches!(f.to_svg(), Err(PlotError::Empty)));
    }

    #[test]
    fn ticks_are_compact() {
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(1.5), "1.5");
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(1234.0), "1234");
        assert_eq!(tick(2.0e6), "2.00e6");
        assert_eq!(tick_in(0.25, 0.0, 1.0), "0.25");
        assert_eq!(tick_in(2.5, 0.0, 5.0), "2.5");
        assert_eq!(tick_in(-2.78e-17, -0.2, 0.3), "0");
        // Residuals of an exact fit: round-off sized, still distinguishable.
        assert_eq!(tick_in(1.0e-16, -2.0e-16, 2.0e-16), "1.0e-16");
        assert_eq!(tick_in(1.5e6, 0.0, 2.0e6), "1.5e6");
    }
}
