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
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
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
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 15))
                .draw()
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    write_atomic(path, svg.as_bytes())
}
