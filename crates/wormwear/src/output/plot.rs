//! SVG charts (plotters, SVG backend only: no system font library needed). One consistent
//! style for every stage: white background, labelled axes with units, legend when useful.

use super::{write_atomic, OutputError};
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

/// Markers at the points of the `k`-th series: shapes and sizes differ from series to series,
/// the earlier ones larger, so that curves lying on each other stay visible.
fn draw_markers<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    points: &[(f64, f64)],
    k: usize,
    color: RGBColor,
) -> Result<(), OutputError>
where
    DB::ErrorType: 'static,
{
    let size = 7 - (k % 4) as u32;
    let result = match k % 3 {
        0 => chart
            .draw_series(points.iter().map(|&p| Circle::new(p, size, color.filled())))
            .map(|_| ()),
        1 => chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| TriangleMarker::new(p, size + 1, color.filled())),
            )
            .map(|_| ()),
        _ => chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| Cross::new(p, size, color.stroke_width(2))),
            )
            .map(|_| ()),
    };
    result.map_err(plot_err)
}

/// Draws the series as lines and, if any has a label, the legend at `position`.
fn draw_series_with_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    series: &[Series],
    (position, markers): (SeriesLabelPosition, bool),
) -> Result<(), OutputError>
where
    DB::ErrorType: 'static,
{
    let mut labelled = false;
    for (k, s) in series.iter().enumerate() {
        let color = COLORS[s.color % COLORS.len()];
        let style = color.stroke_width(if s.bold { 3 } else { 2 });
        if markers {
            draw_markers(chart, &s.points, k, color)?;
        } else if s.points.len() == 1 {
            // A single point draws no line: mark it.
            chart
                .draw_series(s.points.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(plot_err)?;
        }
        let anno = chart
            .draw_series(LineSeries::new(s.points.iter().copied(), style))
            .map_err(plot_err)?;
        if !s.label.is_empty() {
            labelled = true;
            let dot = if markers {
                color.filled()
            } else {
                color.mix(0.0).filled()
            };
            anno.label(s.label.clone()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (20, 0)], color.stroke_width(3))
                    + Circle::new((10, 0), 4, dot)
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

/// The chart corner whose legend box (a quarter of the width, a fifth of the height of the
/// range `(x0, x1, y0, y1)`) covers the fewest points of the series: the legend hides no curve
/// when some corner is free.
fn emptiest_corner(
    series: &[Series],
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> (SeriesLabelPosition, usize) {
    let labelled = series.iter().filter(|s| !s.label.is_empty()).count();
    let (w, h) = (
        0.25 * (x1 - x0),
        (0.07 * labelled as f64 + 0.06) * (y1 - y0),
    );
    let corners = [
        (SeriesLabelPosition::UpperRight, x1 - w, x1, y1 - h, y1),
        (SeriesLabelPosition::UpperLeft, x0, x0 + w, y1 - h, y1),
        (SeriesLabelPosition::LowerRight, x1 - w, x1, y0, y0 + h),
        (SeriesLabelPosition::LowerLeft, x0, x0 + w, y0, y0 + h),
    ];
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, a, b, c, d) in corners {
        // Points of each polyline densified so a segment crossing the box counts.
        let mut hits = 0;
        for s in series {
            for pair in s.points.windows(2) {
                for k in 0..=8 {
                    let t = k as f64 / 8.0;
                    let (x, y) = (
                        pair[0].0 + t * (pair[1].0 - pair[0].0),
                        pair[0].1 + t * (pair[1].1 - pair[0].1),
                    );
                    if x >= a && x <= b && y >= c && y <= d {
                        hits += 1;
                    }
                }
            }
        }
        if hits < best.0 {
            best = (hits, pos);
        }
    }
    (best.1, best.0)
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
    chart_with(
        path,
        (title, x_label, y_label),
        series,
        (equal_aspect, min_y_span, false),
    )
}

/// As [`line_chart`], each series also marked at its points, in shapes and sizes that differ
/// from series to series (curves lying on each other stay visible): few points, each one a
/// computed case (a design study).
pub fn line_chart_marked(
    path: &Path,
    (title, x_label, y_label): (&str, &str, &str),
    series: &[Series],
) -> Result<(), OutputError> {
    chart_with(path, (title, x_label, y_label), series, (false, 0.0, true))
}

/// The line chart of [`line_chart_spanned`] and [`line_chart_marked`].
fn chart_with(
    path: &Path,
    (title, x_label, y_label): (&str, &str, &str),
    series: &[Series],
    (equal_aspect, min_y_span, markers): (bool, f64, bool),
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
    // Legend in a free corner; if every corner has curve under it, headroom on top for it.
    let (mut corner, hits) = emptiest_corner(series, (x0, x1, y0, y1));
    if hits > 0 && !equal_aspect {
        let labelled = series.iter().filter(|s| !s.label.is_empty()).count();
        y1 += (0.07 * labelled as f64 + 0.08) * (y1 - y0);
        corner = SeriesLabelPosition::UpperRight;
    }
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
            .caption(title, ("sans-serif", caption_size(title, width, 22)))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_err)?;
        let (fx, fy) = (AxisFormat::of(x0, x1), AxisFormat::of(y0, y1));
        chart
            .configure_mesh()
            .x_label_formatter(&|v| fx.label(*v))
            .y_label_formatter(&|v| fy.label(*v))
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(plot_err)?;
        draw_series_with_legend(&mut chart, series, (corner, markers))?;
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

/// Short tick label: up to three decimals without trailing zeros ("800", "0.25"), scientific
/// notation for very large or very small magnitudes.
pub fn tick_label(v: f64) -> String {
    tick_label_with(v, 3)
}

/// Decimals that tell apart the ticks of an axis spanning `span` (plotters puts about ten
/// ticks on it): at least three, more when the ticks are closer than 0.001.
pub fn tick_decimals(span: f64) -> usize {
    let step = span.abs() / 10.0;
    if step > 0.0 && step.is_finite() {
        ((-step.log10().floor()) as i64 + 1).clamp(3, 9) as usize
    } else {
        3
    }
}

/// A caption's font size, px: `size`, or smaller for a title that would not fit in `width` px
/// (a sans-serif character is about half its size wide), at least 12 (issue 59: the worn
/// friction map's title was cut at both ends).
pub fn caption_size(title: &str, width: u32, size: u32) -> u32 {
    let chars = title.chars().count().max(1) as f64;
    let fits = (f64::from(width) - 24.0) / (0.52 * chars);
    (fits.floor().max(0.0) as u32).clamp(12, size)
}

/// `text` in lines of at most `width` pixels at a `size` px font (about 0.52 size a
/// character), broken between words; a word longer than a line stands alone.
pub fn wrapped(text: &str, width: u32, size: u32) -> Vec<String> {
    let chars = ((f64::from(width) / (0.52 * f64::from(size))).floor() as usize).max(1);
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= chars => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// How the ticks of one axis are written: all in scientific notation when the axis reaches
/// beyond [1e-3, 1e5) in magnitude, else all plain with the decimals that tell them apart, so
/// that one axis never mixes "80000" with "1.00e5".
#[derive(Debug, Clone, Copy)]
pub struct AxisFormat {
    scientific: bool,
    decimals: usize,
}

impl AxisFormat {
    /// The format of an axis from `lo` to `hi`.
    pub fn of(lo: f64, hi: f64) -> Self {
        let largest = lo.abs().max(hi.abs());
        Self {
            scientific: largest >= 1e5 || (largest > 0.0 && largest < 1e-3),
            decimals: tick_decimals(hi - lo),
        }
    }

    /// The label of the tick at `v`.
    pub fn label(&self, v: f64) -> String {
        match (self.scientific, v == 0.0) {
            (true, true) => "0".into(),
            (true, false) => format!("{v:.2e}"),
            (false, _) => {
                let s = format!("{v:.*}", self.decimals);
                let s = s.trim_end_matches('0').trim_end_matches('.');
                if s == "-0" {
                    "0".into()
                } else {
                    s.into()
                }
            }
        }
    }
}

/// [`tick_label`] with up to `decimals` decimals.
pub fn tick_label_with(v: f64, decimals: usize) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let s = format!("{v:.decimals$}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Values on a structured grid of chart points for iso-lines: `rows` x `cols` points stored
/// column by column (index `col * rows + row`), NaN where there is no value.
#[derive(Debug, Clone)]
pub struct IsoGrid {
    pub rows: usize,
    pub cols: usize,
    pub points: Vec<(f64, f64)>,
    pub values: Vec<f64>,
}

impl IsoGrid {
    /// Segments of the iso-line `value = level` by marching squares with linear interpolation
    /// along the edges; squares with a NaN corner are skipped. Saddles are split by the mean of
    /// the four corners.
    pub fn iso_segments(&self, level: f64) -> Vec<Segment> {
        let mut segments = Vec::new();
        if self.rows < 2 || self.cols < 2 {
            return segments;
        }
        let at = |row: usize, col: usize| col * self.rows + row;
        for col in 0..self.cols - 1 {
            for row in 0..self.rows - 1 {
                // Corners counter-clockwise in (row, col): 0 (r, c), 1 (r+1, c), 2 (r+1, c+1),
                // 3 (r, c+1); edge e joins corners e and e+1.
                let idx = [
                    at(row, col),
                    at(row + 1, col),
                    at(row + 1, col + 1),
                    at(row, col + 1),
                ];
                let v = idx.map(|k| self.values[k]);
                if v.iter().any(|x| !x.is_finite()) {
                    continue;
                }
                let above = v.map(|x| x >= level);
                let crossing = |e: usize| -> Option<(f64, f64)> {
                    let (a, b) = (e, (e + 1) % 4);
                    if above[a] == above[b] {
                        return None;
                    }
                    let t = (level - v[a]) / (v[b] - v[a]);
                    let (pa, pb) = (self.points[idx[a]], self.points[idx[b]]);
                    Some((pa.0 + t * (pb.0 - pa.0), pa.1 + t * (pb.1 - pa.1)))
                };
                let cuts: Vec<(usize, (f64, f64))> =
                    (0..4).filter_map(|e| crossing(e).map(|p| (e, p))).collect();
                match cuts.len() {
                    2 => segments.push((cuts[0].1, cuts[1].1)),
                    4 => {
                        // Saddle: corners 0 and 2 on one side, 1 and 3 on the other. If the
                        // centre is on corner 0's side, corners 1 and 3 are cut off (edges
                        // 0-1 and 2-3), otherwise corners 0 and 2 (edges 3-0 and 1-2).
                        let centre_above = v.iter().sum::<f64>() / 4.0 >= level;
                        let p = |e: usize| cuts[e].1;
                        if centre_above == above[0] {
                            segments.push((p(0), p(1)));
                            segments.push((p(2), p(3)));
                        } else {
                            segments.push((p(3), p(0)));
                            segments.push((p(1), p(2)));
                        }
                    }
                    _ => {}
                }
            }
        }
        segments
    }
}

/// The segments of the connected pieces of an iso-line (segments sharing end points) whose
/// total length is at least `min_length`: drops the small closed loops that noise of one or two
/// cells draws around itself.
pub fn without_short_pieces(segments: Vec<Segment>, min_length: f64) -> Vec<Segment> {
    let n = segments.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    // End points are shared exactly by the squares that computed them (same edge, same
    // interpolation), up to rounding: key them on a fine lattice.
    let key = |p: (f64, f64)| ((p.0 * 1e7).round() as i64, (p.1 * 1e7).round() as i64);
    let mut first_at: std::collections::HashMap<(i64, i64), usize> =
        std::collections::HashMap::new();
    for (k, (a, b)) in segments.iter().enumerate() {
        for p in [a, b] {
            match first_at.entry(key(*p)) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    let (ra, rb) = (root(&mut parent, k), root(&mut parent, *e.get()));
                    parent[ra] = rb;
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(k);
                }
            }
        }
    }
    let length = |(a, b): &Segment| ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let mut total = vec![0.0; n];
    for (k, segment) in segments.iter().enumerate() {
        let r = root(&mut parent, k);
        total[r] += length(segment);
    }
    let keep: Vec<bool> = (0..n)
        .map(|k| total[root(&mut parent, k)] >= min_length)
        .collect();
    segments
        .into_iter()
        .zip(keep)
        .filter_map(|(s, k)| k.then_some(s))
        .collect()
}

/// About `target` round levels (1, 2 or 5 times a power of ten apart) strictly inside
/// (lo, hi); empty for an empty or non-finite range.
pub fn nice_levels(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && hi > lo) || target == 0 {
        return Vec::new();
    }
    let raw = (hi - lo) / (target + 1) as f64;
    let power = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * power)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * power);
    let first = (lo / step).floor() as i64 + 1;
    (first..)
        .map(|k| k as f64 * step)
        .take_while(|&x| x < hi - 1e-9 * step)
        .filter(|&x| x > lo + 1e-9 * step)
        .collect()
}

/// Colour map of cells (e.g. the wheel flank in (z, r) mm) with a colour bar, overlay curves
/// and overlay segments (e.g. a pattern outline). Values are clipped to `range`. With `iso`,
/// iso-lines at round levels are drawn over the map and marked on the colour bar.
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
    iso: Option<&IsoGrid>,
) -> Result<(), OutputError> {
    let (x0, x1, y0, y1) = bounds(cells.iter().flat_map(|c| c.corners.iter().copied()));
    let (px, py) = (0.03 * (x1 - x0), 0.05 * (y1 - y0));
    let (width, height) = (1100u32, 620u32);
    let mut svg = String::new();
    let cell_paths;
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (main, bar) = root.split_horizontally(width - 150);
        let mut chart = ChartBuilder::on(&main)
            .caption(title, ("sans-serif", caption_size(title, width - 150, 21)))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0 - px..x1 + px, y0 - py..y1 + py)
            .map_err(plot_err)?;
        let y_label = stretched(
            y_label,
            (x1 - x0 + 2.0 * px, y1 - y0 + 2.0 * py),
            chart.plotting_area().dim_in_pixel(),
        );
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
        let cell_color = |c: &MapCell| cell_colour(c.value, (lo, span));
        // The cells go in after rendering, one path per colour, where this marker stands.
        chart
            .draw_series(std::iter::once(Text::new(
                CELLS_MARKER,
                (x0, y0),
                ("sans-serif", 1),
            )))
            .map_err(plot_err)?;
        cell_paths = cell_paths_svg(cells, |p| chart.backend_coord(&p), cell_color);
        let levels = iso.map_or_else(Vec::new, |_| nice_levels(lo, hi, 6));
        if let Some(grid) = iso {
            draw_iso_lines(&mut chart, grid, &levels, (x1 - x0, y1 - y0))?;
        }
        chart
            .draw_series(
                segments
                    .iter()
                    .map(|&(a, b)| PathElement::new(vec![a, b], BLACK.stroke_width(2))),
            )
            .map_err(plot_err)?;
        draw_series_with_legend(
            &mut chart,
            overlays,
            (SeriesLabelPosition::UpperMiddle, false),
        )?;
        colour_bar(&bar, bar_label, (lo, span), &levels)?;
        root.present().map_err(plot_err)?;
    }
    write_atomic(path, with_cells(&svg, &cell_paths).as_bytes())
}

/// A map cell's colour: the scale at its value within (lo, lo + span), grey without a value.
fn cell_colour(value: f64, (lo, span): (f64, f64)) -> RGBColor {
    if value.is_finite() {
        scale_color((value - lo) / span)
    } else {
        RGBColor(220, 220, 220)
    }
}

/// The y label of a map of extent `size` (x, y) drawn on `pixels` (width, height): a band much
/// narrower than it is long is drawn stretched, and the label says by how much.
fn stretched(y_label: &str, size: (f64, f64), pixels: (u32, u32)) -> String {
    let stretch = size.0 / size.1 * pixels.1 as f64 / pixels.0 as f64;
    if stretch > 3.0 {
        format!("{y_label}, drawn {stretch:.0} x the x scale")
    } else {
        y_label.to_string()
    }
}

/// Text drawn where the cells of a flank map go ([`with_cells`]).
const CELLS_MARKER: &str = "wormwear-cells-here";

/// The cells as SVG paths, one per colour (fill and a same-colour 1 px outline that hides the
/// anti-aliasing seams between neighbours), in pixel coordinates from `pixel`.
fn cell_paths_svg(
    cells: &[MapCell],
    pixel: impl Fn((f64, f64)) -> (i32, i32),
    color: impl Fn(&MapCell) -> RGBColor,
) -> String {
    use std::fmt::Write as _;
    let mut by_color: Vec<(RGBColor, String)> = Vec::new();
    for c in cells {
        let rgb = color(c);
        let k = match by_color.iter().position(|(col, _)| *col == rgb) {
            Some(k) => k,
            None => {
                by_color.push((rgb, String::new()));
                by_color.len() - 1
            }
        };
        let d = &mut by_color[k].1;
        for (i, &p) in c.corners.iter().enumerate() {
            let (x, y) = pixel(p);
            let _ = write!(d, "{}{x} {y}", if i == 0 { "M" } else { "L" });
        }
        d.push('Z');
    }
    let mut out = String::new();
    for (RGBColor(r, g, b), d) in by_color {
        let _ = writeln!(
            out,
            "<path fill=\"#{r:02X}{g:02X}{b:02X}\" stroke=\"#{r:02X}{g:02X}{b:02X}\" \
             stroke-width=\"1\" stroke-linejoin=\"round\" d=\"{d}\"/>"
        );
    }
    out
}

/// `svg` with the marker's text element replaced by `cells`.
fn with_cells(svg: &str, cells: &str) -> String {
    let Some(at) = svg.find(CELLS_MARKER) else {
        return svg.to_string();
    };
    let start = svg[..at].rfind("<text").unwrap_or(at);
    let end = svg[at..]
        .find("</text>")
        .map_or(at, |k| at + k + "</text>".len());
    format!("{}{}{}", &svg[..start], cells, &svg[end..])
}

/// Iso-lines of `grid` at `levels` over a map whose extent is `size` (x, y); pieces shorter
/// than 6 % of the map's diagonal are noise, not a level line, and are left out.
fn draw_iso_lines<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    grid: &IsoGrid,
    levels: &[f64],
    size: (f64, f64),
) -> Result<(), OutputError>
where
    DB::ErrorType: 'static,
{
    let iso_style = RGBColor(25, 25, 25).mix(0.7).stroke_width(1);
    let min_length = 0.06 * (size.0.powi(2) + size.1.powi(2)).sqrt();
    for &level in levels {
        chart
            .draw_series(
                without_short_pieces(grid.iso_segments(level), min_length)
                    .into_iter()
                    .map(|(a, b)| PathElement::new(vec![a, b], iso_style)),
            )
            .map_err(plot_err)?;
    }
    Ok(())
}

/// The colour bar of [`flank_map`] on `bar`: the scale from `lo` over `span`, labelled, with
/// the iso-line `levels` as ticks across it.
fn colour_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, plotters::coord::Shift>,
    bar_label: &str,
    (lo, span): (f64, f64),
    levels: &[f64],
) -> Result<(), OutputError>
where
    DB::ErrorType: 'static,
{
    // The label over the bar, wrapped to the bar's width (one line cut "friction power
    // (MW/m^2)" at both ends).
    let width = bar.dim_in_pixel().0;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let style =
        TextStyle::from(("sans-serif", 15).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for (k, line) in wrapped(bar_label, width.saturating_sub(10), 15)
        .iter()
        .enumerate()
    {
        bar.draw_text(line, &style, (width as i32 / 2, 10 + 18 * k as i32))
            .map_err(plot_err)?;
    }
    let mut bar_chart = ChartBuilder::on(bar)
        .margin_top(60)
        .margin_bottom(70)
        .margin_right(70)
        .y_label_area_size(0)
        .right_y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, lo..lo + span)
        .map_err(plot_err)?;
    bar_chart
        .configure_mesh()
        .disable_x_axis()
        .disable_mesh()
        .y_label_formatter(&|v| tick_label(*v))
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
    // The iso-line levels as ticks across the bar.
    bar_chart
        .draw_series(levels.iter().map(|&y| {
            PathElement::new(
                vec![(0.0, y), (1.0, y)],
                RGBColor(25, 25, 25).stroke_width(1),
            )
        }))
        .map_err(plot_err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_colour_bar_label_is_wrapped_to_the_bar_between_words() {
        // 140 px at 15 px: 17 characters a line.
        assert_eq!(
            wrapped("friction power (MW/m^2)", 140, 15),
            vec!["friction power", "(MW/m^2)"]
        );
        assert_eq!(wrapped("wear (um)", 140, 15), vec!["wear (um)"]);
        // A word longer than a line stands alone, whole.
        assert_eq!(
            wrapped("a verylongwordthatdoesnotfit b", 60, 15),
            vec!["a", "verylongwordthatdoesnotfit", "b"]
        );
    }

    #[test]
    fn a_flank_map_draws_each_cell_once_in_one_path_per_colour() {
        // A 4 x 3 grid of unit cells in two values (two colours) and one without a value.
        let mut cells = Vec::new();
        for i in 0..4 {
            for j in 0..3 {
                let (x, y) = (i as f64, j as f64);
                cells.push(MapCell {
                    corners: [(x, y), (x + 1.0, y), (x + 1.0, y + 1.0), (x, y + 1.0)],
                    value: if (i, j) == (0, 0) {
                        f64::NAN
                    } else {
                        (i % 2) as f64
                    },
                });
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.svg");
        let drawn_map = |cells: &[MapCell]| {
            let none: &[Series] = &[];
            flank_map(
                &path,
                "t",
                "x",
                "y",
                cells,
                (0.0, 1.0),
                "v",
                none,
                &[],
                None,
            )
            .unwrap();
            std::fs::read_to_string(&path).unwrap()
        };
        let svg = drawn_map(&cells);
        assert!(!svg.contains(CELLS_MARKER));
        let paths: Vec<&str> = svg.split("<path fill=").skip(1).collect();
        assert_eq!(paths.len(), 3, "two colours and the grey of no value");
        let drawn: usize = paths.iter().map(|p| p.matches('M').count()).sum();
        assert_eq!(drawn, cells.len());
        // The cells come before the colour bar's and the axes' text, under everything else.
        assert!(svg.find("<path").unwrap() < svg.rfind("<text").unwrap());
        // A 4 x 3 map is drawn near true scale: no stretch noted.
        assert!(!svg.contains("x the x scale"));
        // A band 40 long and 1 high is drawn stretched, and says by how much.
        let band: Vec<MapCell> = (0..40)
            .map(|i| MapCell {
                corners: [
                    (i as f64, 0.0),
                    (i as f64 + 1.0, 0.0),
                    (i as f64 + 1.0, 1.0),
                    (i as f64, 1.0),
                ],
                value: 0.5,
            })
            .collect();
        let svg = drawn_map(&band);
        let stretch: f64 = svg
            .split(", drawn ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|t| t.parse().ok())
            .expect("the stretch stated");
        assert!((15.0..40.0).contains(&stretch), "{stretch}");
    }

    /// Grid of `n` x `n` points on [-1, 1]^2 with values f(x, y).
    fn grid(n: usize, f: impl Fn(f64, f64) -> f64) -> IsoGrid {
        let mut points = Vec::new();
        let mut values = Vec::new();
        for col in 0..n {
            for row in 0..n {
                let (x, y) = (
                    -1.0 + 2.0 * col as f64 / (n - 1) as f64,
                    -1.0 + 2.0 * row as f64 / (n - 1) as f64,
                );
                points.push((x, y));
                values.push(f(x, y));
            }
        }
        IsoGrid {
            rows: n,
            cols: n,
            points,
            values,
        }
    }

    #[test]
    fn iso_lines_of_a_linear_field_are_exact_straight_lines() {
        let g = grid(9, |x, y| 2.0 * x + 0.5 * y);
        let level = 0.3;
        let segs = g.iso_segments(level);
        assert!(!segs.is_empty());
        for (a, b) in segs {
            for p in [a, b] {
                assert!((2.0 * p.0 + 0.5 * p.1 - level).abs() < 1e-12, "{p:?}");
            }
        }
    }

    #[test]
    fn iso_line_of_a_paraboloid_is_a_closed_circle_converging_with_the_grid() {
        // A level no grid point sits on (a vertex on the level makes degenerate segments).
        let level: f64 = 0.47;
        let mut errors = Vec::new();
        for n in [11, 21, 41] {
            let segs = grid(n, |x, y| x * x + y * y).iso_segments(level);
            // Closed curve: every end point is shared by exactly two segment ends.
            let key = |p: (f64, f64)| ((p.0 * 1e9).round() as i64, (p.1 * 1e9).round() as i64);
            let mut count = std::collections::HashMap::new();
            for (a, b) in &segs {
                *count.entry(key(*a)).or_insert(0) += 1;
                *count.entry(key(*b)).or_insert(0) += 1;
            }
            assert!(count.values().all(|&c| c == 2), "open iso-line at n = {n}");
            let err = segs
                .iter()
                .flat_map(|(a, b)| [a, b])
                .map(|p| ((p.0 * p.0 + p.1 * p.1).sqrt() - level.sqrt()).abs())
                .fold(0.0, f64::max);
            errors.push(err);
        }
        // Linear interpolation on the edges: error O(h^2), a quarter per halving of h.
        assert!(
            errors[1] < 0.35 * errors[0] && errors[2] < 0.35 * errors[1],
            "{errors:?}"
        );
    }

    #[test]
    fn iso_lines_skip_missing_values_and_split_saddles() {
        // A square with NaN: nothing drawn there.
        let mut g = grid(2, |x, _| x);
        g.values[0] = f64::NAN;
        assert!(g.iso_segments(0.0).is_empty());
        // Saddle x*y on one square: two segments that do not cross the centre.
        let g = grid(2, |x, y| x * y + 0.1);
        let segs = g.iso_segments(0.0);
        assert_eq!(segs.len(), 2);
        // Centre value 0.1 is above the level: the two "below" corners (x*y = -1) are cut off,
        // so each segment stays in one half-plane x > 0 or x < 0.
        for (a, b) in segs {
            assert!(a.0 * b.0 > 0.0, "{a:?} {b:?}");
        }
    }

    #[test]
    fn short_iso_pieces_are_dropped_and_long_ones_kept() {
        // A field with a small bump (a loop of one cell) and a ramp crossing the whole grid.
        let mut g = grid(21, |x, _| x);
        let level = 0.5;
        let bump = 5 * 21 + 5; // point (col 5, row 5), x = -0.5: far below the level
        g.values[bump] = 1.0;
        let all = g.iso_segments(level);
        let kept = without_short_pieces(all.clone(), 1.0);
        // The ramp's line x = 0.5 (length 2) stays whole; the loop around the bump (length
        // about 0.2) goes.
        assert!(kept.len() < all.len());
        assert!(kept
            .iter()
            .all(|(a, b)| (a.0 - 0.5).abs() < 1e-12 && (b.0 - 0.5).abs() < 1e-12));
        let length: f64 = kept
            .iter()
            .map(|(a, b)| ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt())
            .sum();
        assert!((length - 2.0).abs() < 1e-9, "{length}");
    }

    #[test]
    fn close_ticks_get_the_decimals_that_tell_them_apart() {
        // The design case's stiffness axis: 0.4285 to 0.4331 MN m/rad.
        let d = tick_decimals(0.4331 - 0.4285);
        let ticks: Vec<String> = (0..10)
            .map(|k| tick_label_with(0.4285 + 0.0005 * k as f64, d))
            .collect();
        let mut unique = ticks.clone();
        unique.dedup();
        assert_eq!(unique.len(), ticks.len(), "{ticks:?}");
        assert_eq!(tick_decimals(1000.0), 3);
    }

    #[test]
    fn a_long_caption_gets_a_smaller_font_that_fits() {
        assert_eq!(caption_size("Backlash increase", 900, 22), 22);
        let long = "Local friction coefficient over the cycle at 180 000 cycles (load-weighted; \
                    mean 0.0226, oil 59.9 C); grey: no contact";
        let size = caption_size(long, 950, 21);
        assert!((12..21).contains(&size), "{size}");
        assert!(0.52 * f64::from(size) * long.chars().count() as f64 <= 950.0 - 24.0);
    }

    #[test]
    fn one_axis_writes_all_its_ticks_alike() {
        // Issue 59: an axis over cycles read "80000" beside "1.00e5".
        let f = AxisFormat::of(0.0, 180_000.0);
        assert_eq!(f.label(80_000.0), "8.00e4");
        assert_eq!(f.label(100_000.0), "1.00e5");
        assert_eq!(f.label(0.0), "0");
        let g = AxisFormat::of(0.0, 90.0);
        assert_eq!(g.label(80.0), "80");
        assert_eq!(g.label(12.5), "12.5");
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(800.0), "800");
        assert_eq!(tick_label(0.25), "0.25");
        assert_eq!(tick_label(0.0), "0");
        assert_eq!(tick_label(-0.0001), "-1.00e-4");
        assert_eq!(tick_label(2.5e6), "2.50e6");
        assert_eq!(tick_label(-1.5), "-1.5");
    }

    #[test]
    fn nice_levels_are_round_and_inside_the_range() {
        assert_eq!(
            nice_levels(0.0, 1000.0, 6),
            vec![200.0, 400.0, 600.0, 800.0]
        );
        assert_eq!(nice_levels(0.0, 4.0, 6), vec![1.0, 2.0, 3.0]);
        let l = nice_levels(-0.35, 0.35, 6);
        let expected = [-0.3, -0.2, -0.1, 0.0, 0.1, 0.2, 0.3];
        assert_eq!(l.len(), expected.len(), "{l:?}");
        assert!(
            l.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-12),
            "{l:?}"
        );
        assert!(nice_levels(1.0, 1.0, 6).is_empty());
        assert!(nice_levels(0.0, f64::NAN, 6).is_empty());
    }
}
