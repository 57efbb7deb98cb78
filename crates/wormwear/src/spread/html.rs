//! `spread.html` of a spread (MODEL §17): the percentiles of each key result, its histogram
//! over the samples, a tornado chart of its sensitivities (rank correlations; with the Sobol
//! sampler the first-order and total indices beside them), and with lives the fan chart of
//! the backlash over the cycles (the samples' P10-P90 band and median). Charts are SVG files
//! in `plots/` beside the page.

use super::{Sampler, Spread, SpreadResults, RESULTS};
use crate::output::text::{escape, human};
use crate::output::OutputError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Chart size, px.
const WIDTH: f64 = 760.0;
const HEIGHT: f64 = 360.0;
/// Histogram bins.
const BINS: usize = 16;

/// Writes `dir/spread.html` and its charts in `dir/plots`; returns the page's path.
pub fn write_html(
    dir: &Path,
    spread: &Spread,
    out: &SpreadResults,
) -> Result<PathBuf, OutputError> {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots).map_err(|source| OutputError::Io {
        path: plots.clone(),
        source,
    })?;
    let summary = super::summary(spread, out);
    let mut h =
        crate::sweep::html::page_head(&format!("wormwear spread — {}", spread.sweep.base_file));
    introduction(&mut h, spread, out);
    percentile_table(&mut h, &summary);
    if let Some(file) = fan_chart(&plots, &out.curves)? {
        h.push_str("<h2>Backlash over the life</h2>\n");
        let _ = writeln!(
            h,
            "<figure><img src=\"plots/{file}\" alt=\"backlash band\"></figure>"
        );
    }
    for (k, (name, _)) in RESULTS.iter().enumerate() {
        let values = independent_values(spread, out, k);
        if values.len() < 2 || values.iter().all(|v| *v == values[0]) {
            continue;
        }
        let (label, unit, _) = human(name, 0.0);
        let _ = writeln!(
            h,
            "<h2>{} <small>({})</small></h2>",
            escape(&label),
            escape(name)
        );
        let histogram = format!("{name}_histogram.svg");
        write_svg(
            &plots.join(&histogram),
            &histogram_svg(&label, &unit, name, &values),
        )?;
        let tornado = format!("{name}_sensitivity.svg");
        write_svg(
            &plots.join(&tornado),
            &tornado_svg(&label, &summary, name, spread),
        )?;
        let _ = writeln!(
            h,
            "<figure><img src=\"plots/{histogram}\" alt=\"histogram\"><img src=\"plots/{tornado}\" \
             alt=\"sensitivities\"></figure>"
        );
    }
    h.push_str("</body></html>\n");
    let path = dir.join("spread.html");
    crate::output::write_atomic(&path, h.as_bytes())?;
    Ok(path)
}

/// The page's heading and what was run.
fn introduction(h: &mut String, spread: &Spread, out: &SpreadResults) {
    let _ = write!(
        h,
        "<h1>Spread of {base}</h1>\n<p>{runs} runs ({failed} failed) of {samples} samples, \
         sampler {sampler}, seed {seed}; stages: {stages}. Inputs: {inputs}. Every sample's \
         output is in <code>variants/NAME/</code>; the numbers are in \
         <a href=\"spread.csv\">spread.csv</a> and <a href=\"spread.json\">spread.json</a>.</p>\n",
        base = escape(&spread.sweep.base_file),
        runs = out.rows.len(),
        failed = out.rows.iter().filter(|r| !r.ok).count(),
        samples = spread.samples,
        sampler = spread.sampler.name(),
        seed = spread.seed,
        stages = spread
            .sweep
            .settings
            .stages
            .iter()
            .map(|s| s.name())
            .collect::<Vec<_>>()
            .join(", "),
        inputs = escape(
            &spread
                .inputs
                .iter()
                .map(|i| i.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    );
}

/// The finite values of result `k` over the independent runs (all of a Latin hypercube, the
/// A and B rows of Saltelli's design).
fn independent_values(spread: &Spread, out: &SpreadResults, k: usize) -> Vec<f64> {
    let rows = match spread.sampler {
        Sampler::LatinHypercube => out.results.len(),
        Sampler::Sobol => 2 * spread.samples,
    };
    out.results
        .iter()
        .take(rows)
        .map(|r| r[k])
        .filter(|v| v.is_finite())
        .collect()
}

/// The table of each result's min / P10 / P50 / P90 / max, in the units an engineer reads.
fn percentile_table(h: &mut String, summary: &serde_json::Value) {
    h.push_str(
        "<table><tr><th>result</th><th>unit</th><th>min</th><th>P10</th><th>P50</th>\
         <th>P90</th><th>max</th><th>runs</th></tr>\n",
    );
    for (name, _) in RESULTS {
        let r = &summary["results"][name];
        if !r.is_object() {
            continue;
        }
        let (label, unit, _) = human(name, 0.0);
        let _ = write!(
            h,
            "<tr><td title=\"{name}\">{}</td><td>{}</td>",
            escape(&label),
            escape(&unit)
        );
        for q in ["min", "p10", "p50", "p90", "max"] {
            let v = r[q].as_f64().map_or(f64::NAN, |v| human(name, v).2);
            let _ = write!(h, "<td class=\"n\">{}</td>", significant(v));
        }
        let _ = writeln!(h, "<td class=\"n\">{}</td></tr>", r["count"]);
    }
    h.push_str("</table>\n");
}

/// Four significant digits.
fn significant(v: f64) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    let digits = (3 - v.abs().max(1e-300).log10().floor() as i32).clamp(0, 9) as usize;
    format!("{v:.digits$}")
}

/// Writes an SVG file atomically.
fn write_svg(path: &Path, svg: &str) -> Result<(), OutputError> {
    crate::output::write_atomic(path, svg.as_bytes())
}

/// The opening of a chart: white ground and the title.
fn chart_head(title: &str) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" \
         viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"sans-serif\">\n<rect width=\"100%\" \
         height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"24\" font-size=\"16\" \
         text-anchor=\"middle\">{}</text>\n",
        WIDTH / 2.0,
        escape(title)
    )
}

/// The histogram of a result's values ([`BINS`] equal bins between its extremes), in its
/// display unit.
fn histogram_svg(label: &str, unit: &str, name: &str, values: &[f64]) -> String {
    let shown: Vec<f64> = values.iter().map(|v| human(name, *v).2).collect();
    let (lo, hi) = shown
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let width = (hi - lo).max(1e-300) / BINS as f64;
    let mut counts = [0usize; BINS];
    for v in &shown {
        counts[(((v - lo) / width) as usize).min(BINS - 1)] += 1;
    }
    let most = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let (left, right, top, bottom) = (60.0, 20.0, 40.0, 50.0);
    let (plot_w, plot_h) = (WIDTH - left - right, HEIGHT - top - bottom);
    let mut svg = chart_head(&format!("{label}: histogram of {} runs", shown.len()));
    let c = crate::plot::COLORS[0];
    for (k, n) in counts.iter().enumerate() {
        let bar_h = plot_h * *n as f64 / most;
        let _ = writeln!(
            svg,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bar_h:.1}\" \
             fill=\"rgb({},{},{})\"><title>{n}</title></rect>",
            left + plot_w * k as f64 / BINS as f64,
            top + plot_h - bar_h,
            plot_w / BINS as f64 - 1.0,
            c.0,
            c.1,
            c.2
        );
    }
    let _ = writeln!(
        svg,
        "<line x1=\"{left}\" x2=\"{}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\"/>\n\
         <text x=\"{left}\" y=\"{:.1}\" font-size=\"13\">{}</text>\n<text x=\"{}\" y=\"{:.1}\" \
         font-size=\"13\" text-anchor=\"end\">{}</text>\n<text x=\"{}\" y=\"{:.1}\" \
         font-size=\"14\" text-anchor=\"middle\">{}</text>\n<text x=\"{}\" y=\"{:.1}\" \
         font-size=\"13\" text-anchor=\"end\">{}</text>",
        WIDTH - right,
        top + plot_h,
        top + plot_h,
        top + plot_h + 18.0,
        significant(lo),
        WIDTH - right,
        top + plot_h + 18.0,
        significant(hi),
        left + plot_w / 2.0,
        top + plot_h + 40.0,
        escape(&format!("{label} ({unit})")),
        left - 6.0,
        top + 12.0,
        most
    );
    svg.push_str("</svg>\n");
    svg
}

/// The tornado chart of a result's sensitivities: per input (largest first) its rank
/// correlation, and with the Sobol sampler its first-order and total indices, as bars on
/// [-1, 1].
fn tornado_svg(label: &str, summary: &serde_json::Value, name: &str, spread: &Spread) -> String {
    let rho = |input: &str| summary["rank_correlation"][name][input].as_f64();
    let sobol = |input: &str, which: &str| summary["sobol_indices"][name][input][which].as_f64();
    let mut inputs: Vec<&str> = spread.inputs.iter().map(|i| i.name.as_str()).collect();
    inputs.sort_by(|a, b| {
        let m = |i: &str| {
            rho(i)
                .map_or(0.0, f64::abs)
                .max(sobol(i, "total").unwrap_or(0.0))
        };
        m(b).total_cmp(&m(a))
    });
    let (left, right, top, bottom) = (260.0, 30.0, 60.0, 40.0);
    let (plot_w, plot_h) = (WIDTH - left - right, HEIGHT - top - bottom);
    let row = plot_h / inputs.len().max(1) as f64;
    let x = |v: f64| left + plot_w * (v.clamp(-1.0, 1.0) + 1.0) / 2.0;
    let mut svg = chart_head(&format!("{label}: sensitivity to each input"));
    let bars: Vec<(&str, usize)> = match spread.sampler {
        Sampler::LatinHypercube => vec![("rank correlation", 0)],
        Sampler::Sobol => vec![
            ("rank correlation", 0),
            ("first-order Sobol", 1),
            ("total Sobol", 2),
        ],
    };
    for (m, (what, color)) in bars.iter().enumerate() {
        let c = crate::plot::COLORS[*color];
        let _ = writeln!(
            svg,
            "<rect x=\"{:.1}\" y=\"36\" width=\"12\" height=\"12\" fill=\"rgb({},{},{})\"/>\
             <text x=\"{:.1}\" y=\"47\" font-size=\"13\">{what}</text>",
            left + 170.0 * m as f64,
            c.0,
            c.1,
            c.2,
            left + 170.0 * m as f64 + 16.0
        );
    }
    for v in [-1.0, -0.5, 0.0, 0.5, 1.0] {
        let _ = writeln!(
            svg,
            "<line x1=\"{0:.1}\" x2=\"{0:.1}\" y1=\"{top}\" y2=\"{1:.1}\" stroke=\"{2}\"/>\
             <text x=\"{0:.1}\" y=\"{3:.1}\" font-size=\"12\" text-anchor=\"middle\">{v}</text>",
            x(v),
            top + plot_h,
            if v == 0.0 { "black" } else { "#ddd" },
            top + plot_h + 16.0
        );
    }
    for (k, input) in inputs.iter().enumerate() {
        let y0 = top + row * k as f64;
        let _ = writeln!(
            svg,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"13\" text-anchor=\"end\">{}</text>",
            left - 8.0,
            y0 + row / 2.0 + 4.0,
            escape(input)
        );
        let values = [rho(input), sobol(input, "first"), sobol(input, "total")];
        let bar_h = 0.8 * row / bars.len() as f64;
        for (m, (_, color)) in bars.iter().enumerate() {
            let Some(v) = values[*color] else { continue };
            let c = crate::plot::COLORS[*color];
            let (a, b) = (x(0.0).min(x(v)), x(0.0).max(x(v)));
            let _ = writeln!(
                svg,
                "<rect x=\"{a:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{bar_h:.1}\" \
                 fill=\"rgb({},{},{})\"><title>{v:.3}</title></rect>",
                y0 + 0.1 * row + bar_h * m as f64,
                (b - a).max(0.5),
                c.0,
                c.1,
                c.2
            );
        }
    }
    svg.push_str("</svg>\n");
    svg
}

/// The fan chart of the samples' backlash increase over the cycles (None without lives):
/// each sample's curve in grey, the P10-P90 band and the median on 60 cycles from 0 to the
/// shortest life reached. Returns the file name in `plots`.
fn fan_chart(plots: &Path, curves: &[Vec<(f64, f64)>]) -> Result<Option<String>, OutputError> {
    let lives: Vec<&Vec<(f64, f64)>> = curves.iter().filter(|c| c.len() >= 2).collect();
    if lives.len() < 2 {
        return Ok(None);
    }
    let end = lives
        .iter()
        .map(|c| c.last().map_or(0.0, |p| p.0))
        .fold(f64::INFINITY, f64::min);
    if end <= 0.0 {
        return Ok(None);
    }
    let (grid, band) = percentile_band(&lives, end);
    let top_value = lives
        .iter()
        .flat_map(|c| c.iter().filter(|p| p.0 <= end).map(|p| p.1))
        .fold(0.0, f64::max)
        .max(1e-12);
    let (left, right, top, bottom) = (70.0, 20.0, 40.0, 50.0);
    let (plot_w, plot_h) = (WIDTH - left - right, HEIGHT - top - bottom);
    let px = |n: f64| left + plot_w * n / end;
    let py = |b: f64| top + plot_h * (1.0 - b / top_value);
    let mut svg = chart_head(&format!(
        "Backlash increase over the life: {} samples, P10-P90 band and median",
        lives.len()
    ));
    for c in &lives {
        let points: Vec<String> = c
            .iter()
            .filter(|p| p.0 <= end)
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        let _ = writeln!(
            svg,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"#ccc\"/>",
            points.join(" ")
        );
    }
    let upper = grid
        .iter()
        .zip(&band)
        .map(|(n, b)| format!("{:.1},{:.1}", px(*n), py(b[2])));
    let lower = grid
        .iter()
        .zip(&band)
        .rev()
        .map(|(n, b)| format!("{:.1},{:.1}", px(*n), py(b[0])));
    let outline: Vec<String> = upper.chain(lower).collect();
    let median: Vec<String> = grid
        .iter()
        .zip(&band)
        .map(|(n, b)| format!("{:.1},{:.1}", px(*n), py(b[1])))
        .collect();
    let _ = writeln!(
        svg,
        "<polygon points=\"{}\" fill=\"rgba(31,119,180,0.3)\"/>\n<polyline points=\"{}\" \
         fill=\"none\" stroke=\"rgb(31,119,180)\" stroke-width=\"2.5\"/>",
        outline.join(" "),
        median.join(" ")
    );
    fan_axes(&mut svg, (left, right, top, plot_w, plot_h), end, top_value);
    svg.push_str("</svg>\n");
    let file = "backlash_band.svg".to_string();
    write_svg(&plots.join(&file), &svg)?;
    Ok(Some(file))
}

/// The fan chart's axes and labels: the plot's (left, right, top, width, height), px, its last
/// cycles and its largest backlash, m.
fn fan_axes(svg: &mut String, frame: (f64, f64, f64, f64, f64), end: f64, top_value: f64) {
    let (left, right, top, plot_w, plot_h) = frame;
    let _ = writeln!(
        svg,
        "<line x1=\"{left}\" x2=\"{0:.1}\" y1=\"{1:.1}\" y2=\"{1:.1}\" stroke=\"black\"/>\
         <line x1=\"{left}\" x2=\"{left}\" y1=\"{top}\" y2=\"{1:.1}\" stroke=\"black\"/>\n\
         <text x=\"{0:.1}\" y=\"{2:.1}\" font-size=\"13\" text-anchor=\"end\">{3} cycles</text>\n\
         <text x=\"{4:.1}\" y=\"{5:.1}\" font-size=\"13\" text-anchor=\"end\">{6} um</text>\n\
         <text x=\"{7:.1}\" y=\"{2:.1}\" font-size=\"14\" text-anchor=\"middle\">wheel cycles</text>",
        WIDTH - right,
        top + plot_h,
        top + plot_h + 18.0,
        crate::output::text::number(end),
        left - 6.0,
        top + 12.0,
        significant(top_value * 1e6),
        left + plot_w / 2.0
    );
}

/// The P10, P50 and P90 of the curves on 61 cycles from 0 to `end`: (cycles, band).
fn percentile_band(lives: &[&Vec<(f64, f64)>], end: f64) -> (Vec<f64>, Vec<[f64; 3]>) {
    let grid: Vec<f64> = (0..=60).map(|k| end * k as f64 / 60.0).collect();
    let band = grid
        .iter()
        .map(|&n| {
            let at: Vec<f64> = lives.iter().map(|c| interpolate(c, n)).collect();
            [0.1, 0.5, 0.9].map(|q| super::stats::percentile(&at, q).unwrap_or(f64::NAN))
        })
        .collect();
    (grid, band)
}

/// A curve's value at `n` by linear interpolation (its ends beyond them).
fn interpolate(curve: &[(f64, f64)], n: f64) -> f64 {
    match curve.iter().position(|p| p.0 >= n) {
        Some(0) => curve[0].1,
        Some(k) => {
            let (a, b) = (curve[k - 1], curve[k]);
            let t = if b.0 > a.0 {
                (n - a.0) / (b.0 - a.0)
            } else {
                1.0
            };
            a.1 + t * (b.1 - a.1)
        }
        None => curve.last().map_or(f64::NAN, |p| p.1),
    }
}
