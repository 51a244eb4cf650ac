//! Line charts drawn with plotters into PNG files: linear or logarithmic
//! axes, one line and marker style per series, and the legend in a panel
//! beside the chart so that it never hides data. Text uses the DejaVu Sans
//! font bundled in `xtask/assets` (no system font lookup).

use std::path::Path;

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// DejaVu Sans 2.37 (licence: `xtask/assets/DejaVuSans-LICENSE.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The font family every text of a figure uses.
const FAMILY: &str = "sans-serif";

/// Colours that stay apart on white (the "tab10" palette and black).
pub const PALETTE: [RGBColor; 11] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
];

/// The shape drawn at each data point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// A circle.
    Circle,
    /// A triangle pointing up.
    Triangle,
    /// An axis-aligned square.
    Square,
    /// A square standing on a corner.
    Diamond,
    /// A diagonal cross.
    Cross,
}

impl Marker {
    /// Shapes to cycle through, one per series.
    pub const CYCLE: [Marker; 5] = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
        Marker::Cross,
    ];
}

/// How the points of a series are joined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    /// Not joined (markers only).
    None,
    /// A solid line.
    Solid,
    /// A dashed line.
    Dashed,
}

/// One labelled data series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text; an empty label leaves the series out of the legend,
    /// and a series without points appears in the legend only.
    pub label: String,
    /// The data, in axis units.
    pub points: Vec<(f64, f64)>,
    /// Line and marker colour.
    pub color: RGBColor,
    /// Marker at each point, if any.
    pub marker: Option<Marker>,
    /// Filled (true) or outlined markers.
    pub filled: bool,
    /// How the points are joined.
    pub line: Line,
}

/// An axis: its label, scale and, optionally, fixed bounds.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Label, with units.
    pub label: String,
    /// Logarithmic (base 10) scale.
    pub log: bool,
    /// Bounds; `None` takes the data's (snapped to decades on a log axis).
    pub range: Option<(f64, f64)>,
}

impl Axis {
    /// A linear axis with bounds from the data.
    pub fn linear(label: &str) -> Self {
        Self {
            label: label.to_owned(),
            log: false,
            range: None,
        }
    }

    /// A logarithmic axis with bounds from the data ([`log_bounds`]).
    pub fn log(label: &str) -> Self {
        Self {
            log: true,
            ..Self::linear(label)
        }
    }

    /// The same axis with fixed bounds.
    pub fn with_range(self, lo: f64, hi: f64) -> Self {
        Self {
            range: Some((lo, hi)),
            ..self
        }
    }

    /// The bounds for `values`: the fixed ones, else [`log_bounds`] of the
    /// data (log), else the data's span with 5 % margins (linear).
    fn bounds(&self, values: impl Iterator<Item = f64>) -> Result<(f64, f64)> {
        if let Some(r) = self.range {
            return Ok(r);
        }
        let (lo, hi) = values
            .filter(|v| v.is_finite() && (!self.log || *v > 0.0))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if lo > hi {
            return Err(anyhow!("axis `{}` has no plottable data", self.label));
        }
        Ok(if self.log {
            log_bounds(lo, hi)
        } else {
            let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1.0));
            (lo - pad, hi + pad)
        })
    }
}

/// Bounds of a log axis around the positive data span `lo..=hi`: the
/// nearest values 1, 2 or 5 × 10ⁿ outside it, widened to whole decades if
/// no decade (the only labelled ticks) would fall inside.
fn log_bounds(lo: f64, hi: f64) -> (f64, f64) {
    let nice = |v: f64, up: bool| {
        let e = v.log10().floor();
        let steps = [1.0, 2.0, 5.0, 10.0];
        let m = v / 10f64.powf(e);
        let pick = if up {
            steps.iter().copied().find(|s| *s >= m * (1.0 - 1e-12))
        } else {
            steps
                .iter()
                .rev()
                .copied()
                .find(|s| *s <= m * (1.0 + 1e-12))
        };
        pick.unwrap_or(1.0) * 10f64.powf(e)
    };
    let (a, b) = (nice(lo, false), nice(hi, true));
    if b.log10().floor() >= a.log10().ceil() {
        (a, b)
    } else {
        (
            10f64.powf(lo.log10().floor()),
            10f64.powf(hi.log10().ceil()),
        )
    }
}

/// A chart with its legend, saved as a PNG.
#[derive(Debug, Clone)]
pub struct Figure {
    /// Caption above the chart.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The data.
    pub series: Vec<Series>,
    /// Heading of the legend panel.
    pub legend_title: String,
}

/// Image size in pixels.
const SIZE: (u32, u32) = (1280, 760);
/// Font sizes: caption, axis labels, tick labels and legend.
const CAPTION: u32 = 26;
const AXIS_LABEL: u32 = 21;
const TICK: u32 = 18;
const LEGEND: u32 = 17;
/// Legend row height and sample width (pixels).
const ROW: i32 = 28;
const SAMPLE: i32 = 44;

impl Figure {
    /// Draws the figure into the PNG file `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| anyhow!("the bundled font is not a valid TrueType font"))?;
        let root = BitMapBackend::new(path, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let legend_font = TextStyle::from((FAMILY, LEGEND).into_font());
        let mut widest = root.estimate_text_size(&self.legend_title, &legend_font)?.0;
        for s in &self.series {
            widest = widest.max(root.estimate_text_size(&s.label, &legend_font)?.0 + SAMPLE as u32);
        }
        let legend_width = (widest + 40).min(SIZE.0 / 2);
        let (chart, legend) = root.split_horizontally(SIZE.0 - legend_width);
        let x = self.x.bounds(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        )?;
        let y = self.y.bounds(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.1)),
        )?;
        match (self.x.log, self.y.log) {
            (false, false) => self.draw_chart(&chart, x.0..x.1, y.0..y.1)?,
            (true, false) => self.draw_chart(&chart, (x.0..x.1).log_scale(), y.0..y.1)?,
            (false, true) => self.draw_chart(&chart, x.0..x.1, (y.0..y.1).log_scale())?,
            (true, true) => {
                self.draw_chart(&chart, (x.0..x.1).log_scale(), (y.0..y.1).log_scale())?
            }
        }
        self.draw_legend(&legend)?;
        root.present()?;
        Ok(())
    }

    /// Saves the figure as `img/<file>` and returns the Markdown that shows
    /// it with the alternative text `alt`, from a page beside `img`.
    pub fn save_in(&self, img: &Path, file: &str, alt: &str) -> Result<String> {
        self.save(&img.join(file))?;
        Ok(format!("![{alt}](img/{file})\n\n"))
    }

    fn draw_chart<X, Y>(
        &self,
        area: &DrawingArea<BitMapBackend<'_>, Shift>,
        x: X,
        y: Y,
    ) -> Result<()>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let mut chart = ChartBuilder::on(area)
            .caption(&self.title, (FAMILY, CAPTION))
            .margin(20)
            .x_label_area_size(64)
            .y_label_area_size(96)
            .build_cartesian_2d(x, y)?;
        let (x_log, y_log) = (self.x.log, self.y.log);
        let x_ticks = move |v: &f64| tick_label(*v, x_log);
        let y_ticks = move |v: &f64| tick_label(*v, y_log);
        chart
            .configure_mesh()
            .x_desc(self.x.label.as_str())
            .y_desc(self.y.label.as_str())
            .x_labels(if x_log { 60 } else { 10 })
            .y_labels(if y_log { 60 } else { 10 })
            .x_label_formatter(&x_ticks)
            .y_label_formatter(&y_ticks)
            .label_style((FAMILY, TICK))
            .axis_desc_style((FAMILY, AXIS_LABEL))
            .bold_line_style(RGBColor(222, 222, 222))
            .light_line_style(TRANSPARENT)
            .draw()?;
        for s in &self.series {
            let stroke = s.color.stroke_width(2);
            let points = s.points.iter().copied();
            match s.line {
                Line::None => {}
                Line::Solid => {
                    chart.draw_series(LineSeries::new(points, stroke))?;
                }
                Line::Dashed => {
                    chart.draw_series(DashedLineSeries::new(points, 9, 6, stroke))?;
                }
            }
            if let Some(m) = s.marker {
                for &p in &s.points {
                    draw_marker(chart.plotting_area(), m, p, s)?;
                }
            }
        }
        Ok(())
    }

    fn draw_legend(&self, area: &DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()> {
        let font = (FAMILY, LEGEND).into_font();
        let top = 20 + CAPTION as i32 + 14;
        area.draw(&Text::new(
            self.legend_title.as_str(),
            (8, top),
            font.clone(),
        ))?;
        let entries = self.series.iter().filter(|s| !s.label.is_empty());
        for (i, s) in entries.enumerate() {
            let y = top + ROW * (i as i32 + 1) + ROW / 2;
            let stroke = s.color.stroke_width(2);
            match s.line {
                Line::None => {}
                Line::Solid => {
                    area.draw(&PathElement::new(vec![(8, y), (8 + SAMPLE - 8, y)], stroke))?;
                }
                Line::Dashed => {
                    for x0 in [8, 8 + 14, 8 + 28] {
                        area.draw(&PathElement::new(vec![(x0, y), (x0 + 8, y)], stroke))?;
                    }
                }
            }
            if let Some(m) = s.marker {
                draw_marker(area, m, (8 + (SAMPLE - 8) / 2, y), s)?;
            }
            area.draw(&Text::new(
                s.label.as_str(),
                (8 + SAMPLE, y - LEGEND as i32 / 2 - 1),
                font.clone(),
            ))?;
        }
        Ok(())
    }
}

/// Draws marker `m` of series `s` at `at` (in the area's coordinates).
fn draw_marker<C, CT>(
    area: &DrawingArea<BitMapBackend<'_>, CT>,
    m: Marker,
    at: C,
    s: &Series,
) -> Result<()>
where
    C: Clone + 'static,
    CT: plotters::coord::CoordTranslate<From = C>,
{
    let style = if s.filled {
        s.color.filled()
    } else {
        s.color.stroke_width(2)
    };
    let r = 5;
    match m {
        Marker::Circle => area.draw(&Circle::new(at, r, style))?,
        Marker::Triangle => area.draw(&TriangleMarker::new(at, r + 1, style))?,
        Marker::Cross => area.draw(&Cross::new(at, r, style))?,
        Marker::Square => area.draw(
            &(EmptyElement::at(at) + Rectangle::new([(-r + 1, -r + 1), (r - 1, r - 1)], style)),
        )?,
        Marker::Diamond => area.draw(
            &(EmptyElement::at(at)
                + Polygon::new(
                    vec![(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)],
                    style,
                )),
        )?,
    }
    Ok(())
}

/// A tick label: on a log axis only the decades are labelled (as 0.01,
/// 1, 100 near unity and as powers of ten beyond), on a linear axis the
/// value with at most three decimals.
fn tick_label(v: f64, log: bool) -> String {
    if !log {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return if s == "-0" { "0".into() } else { s.into() };
    }
    let e = v.log10().round();
    if (v / 10f64.powf(e) - 1.0).abs() > 1e-6 {
        return String::new();
    }
    let e = e as i32;
    if (-2..=4).contains(&e) {
        let s = format!("{v:.2}");
        return s.trim_end_matches('0').trim_end_matches('.').to_owned();
    }
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if e < 0 {
        s.push('⁻');
    }
    for d in e.unsigned_abs().to_string().bytes() {
        s.push(SUP[usize::from(d - b'0')]);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::tick_label;

    #[test]
    fn tick_labels() {
        assert_eq!(tick_label(1e-5, true), "10⁻⁵");
        assert_eq!(tick_label(0.01, true), "0.01");
        assert_eq!(tick_label(1000.0, true), "1000");
        assert_eq!(tick_label(3e-3, true), "");
        assert_eq!(tick_label(0.25, false), "0.25");
        assert_eq!(tick_label(-0.0, false), "0");
    }

    #[test]
    fn log_bounds_are_tight_but_hold_a_decade() {
        assert_eq!(super::log_bounds(0.08, 2.56), (0.05, 5.0));
        assert_eq!(super::log_bounds(2.2e-4, 0.07), (2e-4, 0.1));
        assert_eq!(super::log_bounds(2.0, 3.0), (1.0, 10.0));
    }
}
