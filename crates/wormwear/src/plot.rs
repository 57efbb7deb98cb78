//! SVG charts (plotters, SVG backend only: no system font library needed). One consistent
//! style for every stage: white background, labelled axes with units, legend when useful.

use crate::output::{write_atomic, OutputError};
use plotters::prelude::*;
use std::path::Path;

/// Palette shared by all charts.
pub const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(90, 90, 90),
];

/// One polyline of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Index into [`COLORS`].
    pub color: usize,
    /// Draw thicker.
    pub bold: bool,
}

/// Draws the series as lines and, if any has a label, the legend at `position`.
fn draw_series_with_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    series: &[Series],
    position: SeriesLabelPosition,
) -> Result<(), OutputError>
where
    DB::ErrorType: 'static,
{
    let mut labelled = false;
    for s in series {
        let color = COLORS[s.color % COLORS.len()];
        let style = color.stroke_width(if s.bold { 3 } else { 2 });
        let anno = chart
            .draw_series(LineSeries::new(s.points.iter().copied(), style))
            .map_err(plot_err)?;
        if !s.label.is_empty() {
            labelled = true;
            anno.label(s.label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
            });
        }
    }
    if labelled {
        chart
            .configure_series_labels()
            .position(position)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Bounding box (x0, x1, y0, y1) of the finite points; the unit square when there is none.
fn bounds(points: impl Iterator<Item = (f64, f64)>) -> (f64, f64, f64, f64) {
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
    }
    if b.0.is_finite() {
        b
    } else {
        (0.0, 1.0, 0.0, 1.0)
    }
}

fn plot_err(e: impl std::fmt::Display) -> OutputError {
    OutputError::Encode {
        what: "SVG chart".into(),
        message: e.to_string(),
    }
}

/// Line chart written atomically to `path`. With `equal_aspect` one unit has the same length
/// on both axes (profiles, sections).
pub fn line_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    equal_aspect: bool,
) -> Result<(), OutputError> {
    line_chart_spanned(path, title, x_label, y_label, series, equal_aspect, 0.0)
}

/// As [`line_chart`], with the y axis spanning at least `min_y_span` (so numerical noise on a
/// flat curve is drawn flat).
pub fn line_chart_spanned(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    equal_aspect: bool,
    min_y_span: f64,
) -> Result<(), OutputError> {
    let (mut x0, mut x1, mut y0, mut y1) =
        bounds(series.iter().flat_map(|s| s.points.iter().copied()));
    if y1 - y0 < min_y_span {
        let ym = 0.5 * (y0 + y1);
        (y0, y1) = (ym - 0.5 * min_y_span, ym + 0.5 * min_y_span);
    }
    let pad = |a: f64, b: f64| if b > a { 0.04 * (b - a) } else { 0.5 };
    let (px, py) = (pad(x0, x1), pad(y0, y1));
    (x0, x1, y0, y1) = (x0 - px, x1 + px, y0 - py, y1 + py);
    let width = 1000u32;
    let (margin_x, margin_y) = (90u32, 110u32);
    let mut height = 560u32;
    if equal_aspect {
        let plot_w = (width - margin_x) as f64;
        let mut plot_h = plot_w * (y1 - y0) / (x1 - x0);
        if plot_h > 900.0 {
            plot_h = 900.0;
            let half = 0.5 * (y1 - y0) * plot_w / plot_h;
            let xm = 0.5 * (x0 + x1);
            (x0, x1) = (xm - half, xm + half);
        } else if plot_h < 250.0 {
            plot_h = 250.0;
            let half = 0.5 * (x1 - x0) * plot_h / plot_w;
            let ym = 0.5 * (y0 + y1);
            (y0, y1) = (ym - half, ym + half);
        }
        height = plot_h as u32 + margin_y;
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(plot_err)?;
        draw_series_with_legend(&mut chart, series, SeriesLabelPosition::UpperRight)?;
        root.present().map_err(plot_err)?;
    }
    write_atomic(path, svg.as_bytes())
}

/// Colour of value t in [0, 1] on a perceptually ordered scale (viridis-like stops).
pub fn scale_color(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 6] = [
        (68.0, 1.0, 84.0),
        (65.0, 68.0, 135.0),
        (42.0, 120.0, 142.0),
        (34.0, 168.0, 132.0),
        (122.0, 209.0, 81.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let k = (x as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |u: f64, v: f64| (u + (v - u) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// A straight segment between two chart points.
pub type Segment = ((f64, f64), (f64, f64));

/// One quadrilateral cell of a flank map, corners in (x, y) chart units, with its value.
#[derive(Debug, Clone)]
pub struct MapCell {
    pub corners: [(f64, f64); 4],
    /// NaN draws the cell grey ("no value").
    pub value: f64,
}

/// Colour map of cells (e.g. the wheel flank in (z, r) mm) with a colour bar, overlay curves
/// and overlay segments (e.g. a pattern outline). Values are clipped to `range`.
#[allow(clippy::too_many_arguments)]
pub fn flank_map(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    cells: &[MapCell],
    range: (f64, f64),
    bar_label: &str,
    overlays: &[Series],
    segments: &[Segment],
) -> Result<(), OutputError> {
    let (x0, x1, y0, y1) = bounds(cells.iter().flat_map(|c| c.corners.iter().copied()));
    let (px, py) = (0.03 * (x1 - x0), 0.05 * (y1 - y0));
    let (width, height) = (1100u32, 620u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (main, bar) = root.split_horizontally(width - 150);
        let mut chart = ChartBuilder::on(&main)
            .caption(title, ("sans-serif", 21))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0 - px..x1 + px, y0 - py..y1 + py)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .disable_mesh()
            .draw()
            .map_err(plot_err)?;
        let (lo, hi) = range;
        let span = if hi > lo { hi - lo } else { 1.0 };
        let cell_color = |c: &MapCell| {
            if c.value.is_finite() {
                scale_color((c.value - lo) / span)
            } else {
                RGBColor(220, 220, 220)
            }
        };
        chart
            .draw_series(
                cells
                    .iter()
                    .map(|c| Polygon::new(c.corners.to_vec(), cell_color(c).filled())),
            )
            .map_err(plot_err)?;
        // Same-colour outlines hide the anti-aliasing seams between neighbouring cells.
        chart
            .draw_series(cells.iter().map(|c| {
                let mut ring = c.corners.to_vec();
                ring.push(c.corners[0]);
                PathElement::new(ring, cell_color(c).stroke_width(1))
            }))
            .map_err(plot_err)?;
        chart
            .draw_series(
                segments
                    .iter()
                    .map(|&(a, b)| PathElement::new(vec![a, b], BLACK.stroke_width(2))),
            )
            .map_err(plot_err)?;
        draw_series_with_legend(&mut chart, overlays, SeriesLabelPosition::UpperMiddle)?;
        // Colour bar.
        let mut bar_chart = ChartBuilder::on(&bar)
            .margin_top(60)
            .margin_bottom(70)
            .margin_right(70)
            .y_label_area_size(0)
            .right_y_label_area_size(60)
            .caption(bar_label, ("sans-serif", 15))
            .build_cartesian_2d(0.0..1.0, lo..lo + span)
            .map_err(plot_err)?;
        bar_chart
            .configure_mesh()
            .disable_x_axis()
            .disable_mesh()
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(plot_err)?;
        let steps = 64;
        bar_chart
            .draw_series((0..steps).map(|k| {
                let (a, b) = (
                    lo + span * k as f64 / steps as f64,
                    lo + span * (k + 1) as f64 / steps as f64,
                );
                Rectangle::new(
                    [(0.0, a), (1.0, b)],
                    scale_color((k as f64 + 0.5) / steps as f64).filled(),
                )
            }))
            .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    write_atomic(path, svg.as_bytes())
}
