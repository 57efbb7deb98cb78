//! The loaded band's passage over the wheel flank (MODEL §5.6, §7.2): on each node column of
//! the global grid, the pressure profiles across the contact line of every (position, tooth),
//! as instants of the reference tooth's engagement (tooth k at wheel rotation theta2 is the
//! reference tooth at theta2 + sigma k tau). Between consecutive instants each instant's band
//! moves with the contact line, their shapes blended: the per-cycle wear
//! integrates the pressure over that passage, the loaded pattern takes its maximum, so neither
//! depends on where the positions happen to fall.

use super::PositionResult;
use crate::geometry::WheelFlank;
use crate::kinematics::Tca;

/// One instant of the contact band's passage over a node column: the pressure profile across
/// the line (cell centres' radii, ascending, and pressures), its line crossing, line load and the
/// band's curvature.
#[derive(Debug, Clone)]
pub(crate) struct Sample {
    /// Time of the reference tooth, as driven wheel rotation (sigma theta2_ref), rad.
    pub(crate) time: f64,
    /// The contact line's crossing of the node column (the band's middle), m.
    pub(crate) line: f64,
    pub(crate) profile: Vec<(f64, f64)>,
    /// Plastic indentation of the profile's cells (MODEL §5.7), m.
    pub(crate) plastic: Vec<f64>,
    /// Equivalent pressure of the profile's cells (Pa) and the depth of its maximum (m),
    /// MODEL §8.1 ([`crate::subsurface`]).
    pub(crate) equivalent: Vec<(f64, f64)>,
    /// How far below the first and above the last cell centre the end pressures hold: half a
    /// cell, or, where the band was cut by the flank's edge (worm-tip trace, blank top), up to
    /// that edge. m.
    pub(crate) extend_low: f64,
    pub(crate) extend_high: f64,
    pub(crate) line_load: f64,
    pub(crate) pressure: f64,
    pub(crate) radius: f64,
    /// Half of the loaded width across the line (cells with pressure), m.
    pub(crate) half_width: f64,
}

impl Sample {
    /// Pressure at radius r of the profile shifted by `shift`, Pa: linear between cell
    /// centres, the end cells' values over their outer halves, zero beyond.
    pub(crate) fn pressure_at(&self, r: f64, shift: f64) -> f64 {
        self.value_at(r, shift, |k| self.profile[k].1)
    }

    /// Plastic indentation (MODEL §5.7) at radius r of the profile shifted by `shift`, m, as
    /// [`Sample::pressure_at`].
    pub(crate) fn plastic_at(&self, r: f64, shift: f64) -> f64 {
        self.value_at(r, shift, |k| self.plastic.get(k).copied().unwrap_or(0.0))
    }

    /// Equivalent pressure (Pa) and its depth (m) at radius r of the profile shifted, as
    /// [`Sample::pressure_at`].
    pub(crate) fn equivalent_at(&self, r: f64, shift: f64) -> (f64, f64) {
        let cell = |k: usize| self.equivalent.get(k).copied().unwrap_or_default();
        let at = self.locate(r - shift);
        (at.read(|k| cell(k).0), at.read(|k| cell(k).1))
    }

    /// The value of the profile's cell k (`value(k)`) read at radius r, shifted.
    fn value_at(&self, r: f64, shift: f64, value: impl Fn(usize) -> f64) -> f64 {
        self.locate(r - shift).read(value)
    }

    /// Where radius x (m) falls on the profile: which cells a value there reads and how.
    fn locate(&self, x: f64) -> Located {
        let p = &self.profile;
        let (Some(first), Some(last)) = (p.first(), p.last()) else {
            return Located::Outside;
        };
        if x < first.0 {
            return if x >= first.0 - self.extend_low {
                Located::Cell(0)
            } else {
                Located::Outside
            };
        }
        if x > last.0 {
            return if x <= last.0 + self.extend_high {
                Located::Cell(p.len() - 1)
            } else {
                Located::Outside
            };
        }
        if p.len() == 1 {
            // x is the one cell's centre.
            return Located::Cell(0);
        }
        let k = p.partition_point(|q| q.0 <= x).clamp(1, p.len() - 1);
        let (a, b) = (p[k - 1].0, p[k].0);
        if b == a {
            return Located::Coincident(k);
        }
        Located::Between(k, x - a, b - a)
    }

    /// The radii where the profile's reading changes its slope or jumps (its ends, first -
    /// extend_low and last + extend_high, and its cell centres), ascending, m: between two
    /// consecutive ones [`Sample::pressure_at`] and its kin are linear in r.
    fn knots(&self) -> impl Iterator<Item = f64> + '_ {
        let ends = match (self.profile.first(), self.profile.last()) {
            (Some(a), Some(b)) => [Some(a.0 - self.extend_low), Some(b.0 + self.extend_high)],
            _ => [None, None],
        };
        ends[0]
            .into_iter()
            .chain(self.profile.iter().map(|p| p.0))
            .chain(ends[1])
    }

    /// Half extent of the profile (cells included) around the radius `centre`, m.
    pub(crate) fn reach_about(&self, centre: f64) -> f64 {
        match (self.profile.first(), self.profile.last()) {
            (Some(a), Some(b)) => (centre - a.0 + self.extend_low)
                .abs()
                .max((b.0 + self.extend_high - centre).abs()),
            _ => 0.0,
        }
    }
}

/// Where a radius falls on a [`Sample`]'s profile ([`Sample::locate`]).
#[derive(Debug, Clone, Copy)]
enum Located {
    /// Beyond the profile's ends: zero.
    Outside,
    /// Cell k's value (an end cell's outer half, or the one cell).
    Cell(usize),
    /// Between cells k - 1 and k at the same radius: the larger value.
    Coincident(usize),
    /// Between cells k - 1 and k: linear, at dx from k - 1 of their spacing (m).
    Between(usize, f64, f64),
}

impl Located {
    /// The value there of the profile's cell values `value(k)`.
    fn read(self, value: impl Fn(usize) -> f64) -> f64 {
        match self {
            Located::Outside => 0.0,
            Located::Cell(k) => value(k),
            Located::Coincident(k) => value(k - 1).max(value(k)),
            Located::Between(k, dx, spacing) => {
                let (a, b) = (value(k - 1), value(k));
                a + (b - a) * dx / spacing
            }
        }
    }
}

/// The band's instants on each node column of the loaded flank `wf` (index j = 0..=nj), from
/// the loaded analysis' positions: unsorted; `tau` is the wheel's tooth pitch angle, rad.
///
/// With `slice_step` > 1 only every `slice_step`-th node column is a slice of the local
/// meshes (MODEL §5.1), its cells `slice_step` columns long; a column between slices reads
/// the slice whose cells cover it ([`covering_slice`]), its profile moved across the line by
/// the contact line's shift from the slice's column to its own (the band keeps its offset
/// from its line), so that every column has its passages.
pub(crate) fn band_samples(
    wf: &WheelFlank,
    tca: &Tca,
    positions: &[PositionResult],
    tau: f64,
    slice_step: usize,
) -> Vec<Vec<Sample>> {
    use rayon::prelude::*;
    let runs = CellRuns::index(
        positions,
        tca.positions.len(),
        tca.teeth.len(),
        wf.cells_face,
    );
    // Each node column from its own lines, in their order: columns in parallel (on many
    // cores this part would otherwise wait for one thread, issue 55).
    let mut lines_of: Vec<Vec<&crate::kinematics::SliceContact>> =
        vec![Vec::new(); wf.cells_face + 1];
    // The lines' crossings by (position, tooth, column), read only where slices skip columns.
    let mut line_at = std::collections::HashMap::new();
    for line in &tca.contact_lines {
        lines_of[line.slice].push(line);
        if slice_step > 1 {
            line_at
                .entry((line.position, line.tooth, line.slice))
                .or_insert(line.r);
        }
    }
    lines_of
        .par_iter()
        .map(|lines| {
            // A key's profile goes to its first line only (keys hold their column).
            let mut taken = Vec::new();
            let mut samples: Vec<Sample> = lines
                .iter()
                .map(|line| {
                    let theta2 =
                        tca.positions[line.position].theta2 + tca.sigma * line.tooth as f64 * tau;
                    let tooth = tca.teeth.iter().position(|&k| k == line.tooth);
                    let slice = covering_slice(line.slice, slice_step, wf.cells_face);
                    // The slice's line where the column borrows its cells (none: no profile).
                    let shift = if slice == line.slice {
                        Some(0.0)
                    } else {
                        line_at
                            .get(&(line.position, line.tooth, slice))
                            .map(|r| line.r - r)
                    };
                    let key = tooth
                        .zip(shift)
                        .map(|(t, _)| runs.key(line.position, t, slice));
                    let mut cells = match key.filter(|k| !taken.contains(k)) {
                        Some(k) => {
                            taken.push(k);
                            runs.profile(positions, k)
                        }
                        None => Vec::new(),
                    };
                    let shift = shift.unwrap_or(0.0);
                    if shift != 0.0 {
                        cells.iter_mut().for_each(|c| c.r += shift);
                    }
                    cells.sort_by(|a, b| a.r.total_cmp(&b.r));
                    let time = tca.sigma * theta2;
                    sample_of(cells, line, time, wf, tca)
                })
                .collect();
            samples.sort_by(|a, b| a.time.total_cmp(&b.time));
            samples
        })
        .collect()
}

/// The slice whose cells cover node column `column` when every `slice_step`-th column of
/// 0..=`last` is a slice (MODEL §5.1; `local_mesh`): the nearest such column, the lower one
/// where two are as near (an even step's boundary column).
pub(crate) fn covering_slice(column: usize, slice_step: usize, last: usize) -> usize {
    let step = slice_step.max(1);
    let below = column - column % step;
    let slice = if column - below > step / 2 {
        below + step
    } else {
        below
    };
    if slice > last {
        below
    } else {
        slice
    }
}

/// Pressure profiles per (position, tooth, slice) from the local cells. A slice's cells are
/// consecutive in a position's list, so each (position, tooth, slice) is a list of runs of
/// cells (one, in practice), kept in order in a table indexed by position, tooth index and
/// node column (no hashing: this part runs on one thread between two parallel analyses).
struct CellRuns {
    /// (index in positions, first cell, end, next run of the same key).
    runs: Vec<(usize, usize, usize, usize)>,
    /// First and last run of each key (NONE: none, or taken).
    head: Vec<usize>,
    tail: Vec<usize>,
    teeth: usize,
    columns: usize,
}

impl CellRuns {
    const NONE: usize = usize::MAX;

    fn key(&self, position: usize, tooth_index: usize, slice: usize) -> usize {
        (position * self.teeth + tooth_index) * self.columns + slice
    }

    /// The runs of the positions' cells, for `np` positions, `teeth` teeth and `nj` + 1 node
    /// columns.
    fn index(positions: &[PositionResult], np: usize, teeth: usize, nj: usize) -> Self {
        let mut table = Self {
            runs: Vec::new(),
            head: vec![Self::NONE; np * teeth * (nj + 1)],
            tail: vec![Self::NONE; np * teeth * (nj + 1)],
            teeth,
            columns: nj + 1,
        };
        for (at, pr) in positions.iter().enumerate() {
            let cells = &pr.cells;
            let mut k = 0;
            while k < cells.len() {
                let c = &cells[k];
                let mut end = k + 1;
                while end < cells.len()
                    && cells[end].tooth_index == c.tooth_index
                    && cells[end].slice == c.slice
                {
                    end += 1;
                }
                let key = table.key(pr.position, c.tooth_index, c.slice);
                table.runs.push((at, k, end, Self::NONE));
                let run = table.runs.len() - 1;
                match table.tail[key] {
                    Self::NONE => table.head[key] = run,
                    t => table.runs[t].3 = run,
                }
                table.tail[key] = run;
                k = end;
            }
        }
        table
    }

    /// The profile of a key (`key`).
    fn profile(&self, positions: &[PositionResult], key: usize) -> Vec<ProfileCell> {
        let mut profile = Vec::new();
        let mut run = self.head[key];
        while run != Self::NONE {
            let (at, start, end, next) = self.runs[run];
            let pr = &positions[at];
            for (i, c) in (start..end).zip(&pr.cells[start..end]) {
                profile.push(ProfileCell {
                    r: c.r,
                    pressure: pr.pressure[i],
                    width: 2.0 * c.cell.half_nu,
                    column: c.column,
                    band: (c.band_first, c.band_last),
                    plastic: pr.plastic_depth.get(i).copied().unwrap_or(0.0),
                    equivalent: pr
                        .equivalent
                        .get(i)
                        .map_or((0.0, 0.0), |e| (e.pressure, e.depth)),
                });
            }
            run = next;
        }
        profile
    }
}

/// A cell of a band's profile across the line: radius (m), pressure (Pa), width across the
/// line (m), column, plastic depth (m), equivalent pressure (Pa) and its depth (m).
struct ProfileCell {
    r: f64,
    pressure: f64,
    width: f64,
    column: usize,
    /// The first and last column of its slice's band.
    band: (usize, usize),
    plastic: f64,
    equivalent: (f64, f64),
}

/// One instant of the band on a node column from its cells across the line (ascending radii)
/// at the contact line `line` of the reference tooth's time `time` (rad).
fn sample_of(
    cells: Vec<ProfileCell>,
    line: &crate::kinematics::SliceContact,
    time: f64,
    wf: &WheelFlank,
    tca: &Tca,
) -> Sample {
    let load: f64 = cells.iter().map(|c| c.pressure * c.width).sum();
    let (_, extend_low, extend_high) = match (cells.first(), cells.last()) {
        (Some(a), Some(b)) => {
            let spacing = if b.column > a.column {
                (b.r - a.r) / (b.column - a.column) as f64
            } else {
                a.width
            };
            let j = line.slice;
            let floor = tca.tip_trace[j].1.max(wf.r_low[j]);
            let low = if a.column > a.band.0 {
                (a.r - floor).max(0.5 * spacing)
            } else {
                0.5 * spacing
            };
            let high = if b.column < b.band.1 {
                (wf.r_high[j] - b.r).max(0.5 * spacing)
            } else {
                0.5 * spacing
            };
            (spacing, low, high)
        }
        _ => (0.0, 0.0, 0.0),
    };
    let loaded = cells.iter().filter(|c| c.pressure > 0.0).count() as f64;
    let half_width = 0.5 * loaded * cells.first().map_or(0.0, |c| c.width);
    Sample {
        half_width,
        time,
        line: line.r,
        extend_low,
        extend_high,
        line_load: load,
        pressure: cells.iter().map(|c| c.pressure).fold(0.0, f64::max),
        plastic: cells.iter().map(|c| c.plastic).collect(),
        equivalent: cells.iter().map(|c| c.equivalent).collect(),
        profile: cells.into_iter().map(|c| (c.r, c.pressure)).collect(),
        radius: line.curvature_radius,
    }
}

/// The band's passage between two instants a, b of one engagement on a node column: each
/// instant's band moves with the contact line, from its crossing c_a to c_b, while the shape
/// blends from a's to b's. A band keeps its offset from its line: an edge contact below the line
/// (the worm's tip edge at the end of an engagement) stays near the edge, where moving it from
/// one pressure centroid to the next swept it over the rows between (BENCHMARKS.md session 41).
///
/// At a radius r the passage's value at the fraction s is (1 - s) A(r - s d) + s B(r + (1 - s)
/// d), d = c_b - c_a, with A and B the instants' profiles, linear between their knots: a
/// quadratic in s between the fractions where a knot passes r ([`Passage::pieces`]). Its
/// maximum and its integral over the passage are taken exactly on those pieces, so neither
/// depends on a sub-step count (which jumped with the lines' positions, and with it the
/// pattern by up to 7 % at a node: session 56).
pub(crate) struct Passage<'a> {
    pub(crate) a: &'a Sample,
    pub(crate) b: &'a Sample,
    /// The instants' contact line crossings, m.
    ca: f64,
    cb: f64,
    /// The radii the band covers on the way, m.
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl<'a> Passage<'a> {
    /// The passage between consecutive instants (sorted by time) a and b, when they are of one
    /// engagement (at most 1.5 `dt` apart, rad of wheel rotation) and one of them is loaded.
    pub(crate) fn between(a: &'a Sample, b: &'a Sample, dt: f64) -> Option<Self> {
        if b.time - a.time > 1.5 * dt || (a.line_load <= 0.0 && b.line_load <= 0.0) {
            return None;
        }
        let (ca, cb) = (a.line, b.line);
        let reach = a.reach_about(ca).max(b.reach_about(cb));
        Some(Passage {
            a,
            b,
            ca,
            cb,
            lo: ca.min(cb) - reach,
            hi: ca.max(cb) + reach,
        })
    }

    /// Pressure at radius r at the fraction s of the passage (0: a, 1: b), Pa.
    pub(crate) fn pressure(&self, r: f64, s: f64) -> f64 {
        let (a, b, ca, cb) = (self.a, self.b, self.ca, self.cb);
        let c = ca + s * (cb - ca);
        blend(a.pressure_at(r, c - ca), b.pressure_at(r, c - cb), s)
    }

    /// Plastic indentation at radius r at the fraction s of the passage, m.
    fn plastic(&self, r: f64, s: f64) -> f64 {
        let (a, b, ca, cb) = (self.a, self.b, self.ca, self.cb);
        let c = ca + s * (cb - ca);
        blend(a.plastic_at(r, c - ca), b.plastic_at(r, c - cb), s)
    }

    /// The fractions of the passage where, at radius r, a knot of a's profile (moving as r - s d)
    /// or of b's (r + (1 - s) d) passes r, with 0 and 1, ascending, into `out`: between two
    /// consecutive ones the passage's values at r are quadratics in s.
    pub(crate) fn pieces(&self, r: f64, out: &mut Vec<f64>) {
        out.clear();
        out.push(0.0);
        let d = self.cb - self.ca;
        if d != 0.0 {
            let inside = |s: f64| s > 0.0 && s < 1.0;
            out.extend(self.a.knots().map(|x| (r - x) / d).filter(|&s| inside(s)));
            out.extend(
                self.b
                    .knots()
                    .map(|x| 1.0 - (x - r) / d)
                    .filter(|&s| inside(s)),
            );
            out.sort_unstable_by(f64::total_cmp);
        }
        out.push(1.0);
    }

    /// The integral over the passage (s from 0 to 1) of the pressure at radius r, Pa: two-point
    /// Gauss on each piece, exact for its quadratic.
    pub(crate) fn pressure_integral(&self, r: f64, pieces: &mut Vec<f64>) -> f64 {
        self.pieces(r, pieces);
        let g = 0.5 / 3f64.sqrt();
        pieces
            .windows(2)
            .map(|w| {
                let (mid, width) = (0.5 * (w[0] + w[1]), w[1] - w[0]);
                0.5 * width
                    * (self.pressure(r, mid - g * width) + self.pressure(r, mid + g * width))
            })
            .sum()
    }

    /// The largest first member of `value(r, s)` over the passage at radius r, with the second
    /// read at the same fraction: on each piece, its quadratic through its values at a quarter,
    /// a half and three quarters of it is largest at an end or at its vertex, where `value` is
    /// read (an end a billionth of the piece inside).
    fn piece_max(
        &self,
        r: f64,
        pieces: &mut Vec<f64>,
        value: impl Fn(f64, f64) -> (f64, f64),
    ) -> (f64, f64) {
        self.pieces(r, pieces);
        let mut best = (f64::NEG_INFINITY, 0.0);
        for w in pieces.windows(2) {
            let (mid, width) = (0.5 * (w[0] + w[1]), w[1] - w[0]);
            let at = |u: f64| value(r, mid + u * width);
            // The quadratic places the maximum; the value is read there (a hair inside the
            // piece at its ends, where the profile may jump), never extrapolated.
            let u = Quadratic::through(at(-0.25).0, at(0.0).0, at(0.25).0).argmax();
            let found = at(u.clamp(-0.5 + 1e-9, 0.5 - 1e-9));
            if found.0 > best.0 {
                best = found;
            }
        }
        best
    }
}

/// A quadratic in u on [-1/2, 1/2], q(u) = c + b u + a u^2, from its values at u = -1/4, 0,
/// 1/4.
struct Quadratic {
    a: f64,
    b: f64,
    c: f64,
}

impl Quadratic {
    fn through(y1: f64, y2: f64, y3: f64) -> Self {
        Self {
            a: 8.0 * (y1 + y3 - 2.0 * y2),
            b: 2.0 * (y3 - y1),
            c: y2,
        }
    }

    fn at(&self, u: f64) -> f64 {
        self.c + u * (self.b + u * self.a)
    }

    /// Where it is largest on [-1/2, 1/2].
    fn argmax(&self) -> f64 {
        let vertex = if self.a < 0.0 {
            (-self.b / (2.0 * self.a)).clamp(-0.5, 0.5)
        } else {
            0.5
        };
        [-0.5, 0.5, vertex]
            .into_iter()
            .max_by(|&x, &y| self.at(x).total_cmp(&self.at(y)))
            .unwrap_or(0.5)
    }
}

impl Passage<'_> {
    /// Equivalent pressure (Pa) and its depth (m) at radius r at the fraction s of the
    /// passage, as [`Passage::pressure`].
    fn equivalent(&self, r: f64, s: f64) -> (f64, f64) {
        let (a, b, ca, cb) = (self.a, self.b, self.ca, self.cb);
        let c = ca + s * (cb - ca);
        let (pa, da) = a.equivalent_at(r, c - ca);
        let (pb, db) = b.equivalent_at(r, c - cb);
        (blend(pa, pb, s), blend(da, db, s))
    }
}

/// (1 - s) x + s y for s in [0, 1], never beyond x and y by rounding (a pressure at the flow
/// pressure blended with itself stays at it).
fn blend(x: f64, y: f64, s: f64) -> f64 {
    ((1.0 - s) * x + s * y).clamp(x.min(y), x.max(y))
}

/// The largest equivalent pressure over the band's whole passage at the radii `radii` of one
/// node column (Pa) and the depth where it is reached (m), as [`swept_max`] (MODEL §8.1).
pub(crate) fn swept_equivalent(samples: &[Sample], radii: &[f64], dt: f64) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0f64, 0.0f64); radii.len()];
    let keep = |o: &mut (f64, f64), v: (f64, f64)| {
        if v.0 > o.0 {
            *o = v;
        }
    };
    if !samples
        .iter()
        .any(|s| s.equivalent.iter().any(|e| e.0 > 0.0))
    {
        return out;
    }
    let mut pieces = Vec::new();
    for sample in samples {
        for (o, &r) in out.iter_mut().zip(radii) {
            keep(o, sample.equivalent_at(r, 0.0));
        }
    }
    for pair in samples.windows(2) {
        let Some(passage) = Passage::between(&pair[0], &pair[1], dt) else {
            continue;
        };
        for (o, &r) in out.iter_mut().zip(radii) {
            if r < passage.lo || r > passage.hi {
                continue;
            }
            keep(
                o,
                passage.piece_max(r, &mut pieces, |r, s| passage.equivalent(r, s)),
            );
        }
    }
    out
}

/// What [`swept_max`] takes the largest of.
#[derive(Clone, Copy)]
pub(crate) enum Swept {
    Pressure,
    Plastic,
}

/// The largest pressure or plastic indentation over the band's whole passage (the instants
/// and, exactly, the passages between them, [`Passage`]) at the radii `radii` of one node column, from
/// its instants sorted by time; `dt` the wheel rotation between positions, rad.
pub(crate) fn swept_max(samples: &[Sample], radii: &[f64], dt: f64, what: Swept) -> Vec<f64> {
    let mut out = vec![0.0f64; radii.len()];
    let yielded = |s: &Sample| s.plastic.iter().any(|&d| d > 0.0);
    if matches!(what, Swept::Plastic) && !samples.iter().any(yielded) {
        return out;
    }
    let value = |passage: &Passage, r: f64, s: f64| match what {
        Swept::Pressure => (passage.pressure(r, s), 0.0),
        Swept::Plastic => (passage.plastic(r, s), 0.0),
    };
    let mut pieces = Vec::new();
    for sample in samples {
        for (o, &r) in out.iter_mut().zip(radii) {
            let v = match what {
                Swept::Pressure => sample.pressure_at(r, 0.0),
                Swept::Plastic => sample.plastic_at(r, 0.0),
            };
            *o = o.max(v);
        }
    }
    for pair in samples.windows(2) {
        let Some(passage) = Passage::between(&pair[0], &pair[1], dt) else {
            continue;
        };
        if matches!(what, Swept::Plastic) && !yielded(passage.a) && !yielded(passage.b) {
            continue;
        }
        for (o, &r) in out.iter_mut().zip(radii) {
            if r < passage.lo || r > passage.hi {
                continue;
            }
            let (v, _) = passage.piece_max(r, &mut pieces, |r, s| value(&passage, r, s));
            *o = o.max(v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_between_slices_reads_the_slice_whose_cells_cover_it() {
        // Every column its own slice.
        assert!((0..=10).all(|j| covering_slice(j, 1, 10) == j));
        // Slices 0, 3, 6, 9 with cells three columns long: 0..=1, 2..=4, 5..=7, 8..=10.
        let three: Vec<usize> = (0..=10).map(|j| covering_slice(j, 3, 10)).collect();
        assert_eq!(three, [0, 0, 3, 3, 3, 6, 6, 6, 9, 9, 9]);
        // Slices 0, 2, 4 with cells two columns long: a boundary column takes the lower one;
        // the last column past the last slice takes the last slice.
        let two: Vec<usize> = (0..=5).map(|j| covering_slice(j, 2, 5)).collect();
        assert_eq!(two, [0, 0, 2, 2, 4, 4]);
        assert_eq!(covering_slice(60, 7, 60), 56);
    }

    fn sample(profile: Vec<(f64, f64)>) -> Sample {
        Sample {
            time: 0.0,
            line: 0.1,
            profile,
            plastic: Vec::new(),
            equivalent: Vec::new(),
            extend_low: 1e-4,
            extend_high: 1e-4,
            line_load: 0.0,
            pressure: 0.0,
            radius: 0.01,
            half_width: 0.0,
        }
    }

    #[test]
    fn a_band_profile_of_one_cell_holds_its_pressure_over_the_cell() {
        // A slice cut to a single cell by the flank's edges (it happens on worn flanks): its
        // pressure over its extent, zero beyond, and no panic at the centre.
        let s = sample(vec![(0.1, 5e8)]);
        assert_eq!(s.pressure_at(0.1, 0.0), 5e8);
        assert_eq!(s.pressure_at(0.1 - 0.5e-4, 0.0), 5e8);
        assert_eq!(s.pressure_at(0.1 + 0.5e-4, 0.0), 5e8);
        assert_eq!(s.pressure_at(0.1 + 2e-4, 0.0), 0.0);
        // Two cells: linear between their centres.
        let s = sample(vec![(0.1, 4e8), (0.1002, 6e8)]);
        assert!((s.pressure_at(0.1001, 0.0) - 5e8).abs() < 1e-3);
    }

    /// An instant a whose band carries `load` (a share of b's line load) on one cell at the
    /// edge, 1 mm above its line crossing at 0.1 m, followed by a loaded instant b: the time
    /// integral of the passage's pressure at each of the radii `nodes`.
    fn passage_integrals(load: f64, nodes: &[f64]) -> Vec<f64> {
        let cells: Vec<f64> = (0..11).map(|k| 0.0995 + 1e-4 * k as f64).collect();
        let width = 1e-4;
        let mut a = sample(cells.iter().map(|&r| (r, 0.0)).collect());
        let mut b = sample(
            cells
                .iter()
                .map(|&r| (r, 5e8 * (1.0 - ((r - 0.1) / 6e-4).powi(2)).max(0.0)))
                .collect(),
        );
        b.line_load = b.profile.iter().map(|p| p.1 * width).sum();
        b.time = 1.0;
        if load > 0.0 {
            a.line_load = load * b.line_load;
            a.profile[10].1 = a.line_load / width;
        }
        let passage = Passage::between(&a, &b, 1.0).expect("b is loaded");
        nodes
            .iter()
            .map(|&r| passage.pressure_integral(r, &mut Vec::new()))
            .collect()
    }

    #[test]
    fn a_passage_is_continuous_as_one_instant_s_load_vanishes() {
        // A vanishing load on the band's edge cell (0.5 mm from the line): the passage must
        // tend to the unloaded instant's as that load goes to zero, not jump with a load at
        // round-off level (the centroid of such a load sits wherever its last loaded cell is).
        let nodes: Vec<f64> = (0..21).map(|k| 0.0995 + 5e-5 * k as f64).collect();
        let unloaded = passage_integrals(0.0, &nodes);
        let scale = unloaded.iter().copied().fold(0.0, f64::max);
        for tiny in [1e-14, 1e-11] {
            let near = passage_integrals(tiny, &nodes);
            let worst = near
                .iter()
                .zip(&unloaded)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-4 * scale,
                "load {tiny:e}: {worst:e} of {scale:e}"
            );
        }
    }

    #[test]
    fn an_edge_contact_below_its_line_is_not_swept_over_the_rows_between() {
        // Instant a: a band on its line at 100 mm; instant b: the line 0.25 mm lower and the
        // load on one edge cell 2.2 mm below it (the worm's tip edge at an engagement's end).
        // Moving with the lines, b's edge load travels 0.25 mm about the edge: a row 1 mm above
        // the edge and 1 mm below a's band gets nothing; the rows the edge does pass get it.
        let cells: Vec<f64> = (0..5).map(|k| 0.0998 + 1e-4 * k as f64).collect();
        let mut a = sample(cells.iter().map(|&r| (r, 5e8)).collect());
        a.line_load = 5e8 * 5e-4;
        let mut b = sample(vec![(0.09755, 1e9), (0.0983, 0.0)]);
        b.line = 0.09975;
        b.line_load = 1e9 * 1e-4;
        b.time = 1.0;
        let passage = Passage::between(&a, &b, 1.0).expect("both loaded");
        let integral = |r: f64| passage.pressure_integral(r, &mut Vec::new());
        assert_eq!(integral(0.09875), 0.0);
        assert!(integral(0.0976) > 1e8, "{}", integral(0.0976));
        assert!(integral(0.1) > 1e8);
    }

    /// Two instants of a parabolic band, the second narrower, higher and `shift` further up
    /// the column, with an edge cell held over a wider extent.
    fn moving_band(shift: f64) -> (Sample, Sample) {
        let cells: Vec<f64> = (0..13).map(|k| 0.0994 + 1e-4 * k as f64).collect();
        let band = |centre: f64, half: f64, peak: f64| {
            cells
                .iter()
                .map(|&r| {
                    (
                        r + centre - 0.1,
                        peak * (1.0 - ((r - 0.1) / half).powi(2)).max(0.0),
                    )
                })
                .collect::<Vec<_>>()
        };
        let mut a = sample(band(0.1, 6e-4, 5e8));
        a.line_load = 1.0;
        a.extend_low = 3e-4;
        let mut b = sample(band(0.1 + shift, 4e-4, 7e8));
        b.line = 0.1 + shift;
        b.line_load = 1.0;
        b.time = 1.0;
        (a, b)
    }

    #[test]
    fn a_passage_s_maximum_and_integral_are_exact_on_its_pieces() {
        // Against a fine sampling of the passage (1e5 steps): the pieces' maximum is at least
        // every sample and at most a hair above the largest, their integral the samples' mean.
        for shift in [0.0, 3.3e-5, 2.7e-4, -1.1e-3] {
            let (a, b) = moving_band(shift);
            let passage = Passage::between(&a, &b, 1.0).unwrap();
            let mut pieces = Vec::new();
            for k in 0..40 {
                let r = passage.lo + (passage.hi - passage.lo) * (k as f64 + 0.37) / 40.0;
                let n = 100_000;
                let samples: Vec<f64> = (1..n)
                    .map(|m| passage.pressure(r, m as f64 / n as f64))
                    .collect();
                let fine_max = samples.iter().copied().fold(0.0, f64::max);
                let fine_mean = (0..n)
                    .map(|m| passage.pressure(r, (m as f64 + 0.5) / n as f64))
                    .sum::<f64>()
                    / n as f64;
                let (max, _) =
                    passage.piece_max(r, &mut pieces, |r, s| (passage.pressure(r, s), 0.0));
                let integral = passage.pressure_integral(r, &mut pieces);
                // Read a billionth of a piece inside its ends: a few 1e-9 of the peak short.
                assert!(
                    max >= fine_max * (1.0 - 1e-8) && max <= fine_max + 1e-4 * 7e8,
                    "shift {shift}, r {r}: {max} vs {fine_max}"
                );
                assert!(
                    (integral - fine_mean).abs() <= 1e-6 * 7e8,
                    "shift {shift}, r {r}: {integral} vs {fine_mean}"
                );
            }
        }
    }

    #[test]
    fn the_swept_maximum_is_the_passage_s_own_at_every_line_shift() {
        // swept_max against the instants and a fine sampling of the passage (2e4 steps), for
        // line shifts from none to several band widths: a sampled maximum (the sub-steps'
        // count jumping with the shift) fell short by several per cent and jumped with it.
        let radii: Vec<f64> = (0..60).map(|k| 0.0993 + 2.5e-5 * k as f64).collect();
        for k in 0..=30 {
            let shift = 1e-4 * k as f64 - 1.3e-3;
            let (a, b) = moving_band(shift);
            let swept = swept_max(&[a.clone(), b.clone()], &radii, 1.0, Swept::Pressure);
            let passage = Passage::between(&a, &b, 1.0).unwrap();
            for (&r, &max) in radii.iter().zip(&swept) {
                let n = 20_000;
                let fine = (0..=n)
                    .map(|m| passage.pressure(r, m as f64 / n as f64))
                    .fold(0.0, f64::max);
                assert!(
                    (max - fine).abs() <= 1e-4 * 7e8,
                    "shift {shift}, r {r}: {max} vs {fine}"
                );
            }
        }
    }
    #[test]
    fn a_passage_at_the_flow_pressure_stays_at_it() {
        // Both instants at the cap on every cell: the blend and the pieces' maximum give the
        // cap itself at every radius the band covers, never a rounding above it.
        let cap = 1e9;
        for shift in [0.0, 1.7e-5, 3.1e-4] {
            let cells: Vec<(f64, f64)> = (0..9).map(|k| (0.0996 + 1e-4 * k as f64, cap)).collect();
            let mut a = sample(cells.clone());
            a.line_load = 1.0;
            let mut b = sample(cells.iter().map(|&(r, p)| (r + shift, p)).collect());
            (b.line, b.line_load, b.time) = (0.1 + shift, 1.0, 1.0);
            let radii: Vec<f64> = (0..50).map(|k| 0.0996 + 1.9e-5 * k as f64).collect();
            for max in swept_max(&[a, b], &radii, 1.0, Swept::Pressure) {
                assert!(max <= cap, "{max}");
            }
        }
    }
}
