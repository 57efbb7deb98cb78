//! The rows of the global flank grid (MODEL §3.3): where each node column's rows lie between
//! the flank's foot r_low(z) and the blank top r_high(z).
//!
//! The worm's tip reaches the wheel flank along the worm-tip trace, above the foot the hob's
//! larger tip cuts. Below the trace the worm never touches; above it the flank wears. The wear
//! therefore has a step at the trace, and with a broken tip edge (or a tip relief) a ramp over
//! the strip the edge sweeps, a few tenths of a millimetre wide: the plastic set, the largest
//! equivalent pressures and the pitting damage sit on the first rows above it. Evenly spaced
//! rows of the default grid (0.31 mm on the design gear) smear the step over the row that
//! straddles the trace and resolve the edge's ramp with one node, a ledge whose pressure moved
//! from state to state (VALIDATION.md, session 57).
//!
//! Each column is therefore split into three runs of evenly spaced rows: from the foot to the
//! trace (a node row on the trace), a band from the trace over the edge's strip and
//! [`BAND_ROWS`] nominal rows above it, `refinement` times finer, and the rest to the top. The
//! runs' row counts are the same in every column (a structured grid) and on both flanks; a
//! nominal row is (r_high - r_low) / I. Refinement 0 keeps the evenly spaced rows of before.

/// Nominal rows above the edge's strip that the band refines: the damage of a sharp edge sits on
/// the first three or four rows above the trace (VALIDATION.md, session 57).
pub const BAND_ROWS: f64 = 4.0;

/// How far above the worm-tip trace its node row lies, in band rows: just inside the worm's
/// reach. A node exactly on the trace reads the gap at the worm tip's very corner, where it
/// has a kink: an edge break of a micrometre moved the unworn design's P_patch by 4 %.
pub const TRACE_CLEARANCE: f64 = 0.02;

/// Where one node column's runs of rows begin and end, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnKnots {
    /// The flank's foot r_low.
    pub foot: f64,
    /// The worm-tip trace (the foot where the grid is evenly spaced).
    pub trace: f64,
    /// The band's top (the foot where the grid is evenly spaced).
    pub band_top: f64,
    /// The blank top r_high.
    pub top: f64,
}

/// Where the worm reaches a node column: the worm-tip trace and the top of the strip its
/// broken tip edge (or tip relief) sweeps, wheel radii in m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WormReach {
    pub trace: f64,
    pub strip_top: f64,
}

impl ColumnKnots {
    /// The knots of a column from the foot to the top with `nominal` rows (I), the worm's reach
    /// on it and the band's refinement (0: evenly spaced).
    pub fn new(
        foot: f64,
        top: f64,
        reach: Option<WormReach>,
        nominal: usize,
        refinement: usize,
    ) -> Self {
        let even = Self {
            foot,
            trace: foot,
            band_top: foot,
            top,
        };
        let Some(reach) = reach.filter(|_| refinement > 0) else {
            return even;
        };
        let row = (top - foot) / nominal.max(1) as f64;
        let trace = (reach.trace + TRACE_CLEARANCE * row / refinement as f64).clamp(foot, top);
        // Whole nominal rows from the trace (a strip under a hundredth of a row, an edge of a
        // few micrometres, leaves the sharp edge's band: R -> 0 gives the sharp grid).
        let strip_rows = ((reach.strip_top.max(trace) - trace) / row - 0.01)
            .ceil()
            .max(0.0);
        let band_top = (trace + (strip_rows + BAND_ROWS) * row).min(top - row);
        if band_top <= trace + 0.5 * row {
            return even;
        }
        Self {
            foot,
            trace,
            band_top,
            top,
        }
    }

    /// A nominal row, m.
    fn row(&self, nominal: usize) -> f64 {
        (self.top - self.foot) / nominal.max(1) as f64
    }
}

/// How many rows each run has, the same in every column: below the trace, in the band and
/// above it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowPlan {
    pub below: usize,
    pub band: usize,
    pub above: usize,
}

impl RowPlan {
    /// The runs' row counts for columns `knots` of a grid of `nominal` rows with the band
    /// `refinement` times finer: the band and the run above it as many rows as their longest
    /// column needs, the run below the trace rows up to two nominal rows high (evenly spaced
    /// rows where no column has a band).
    pub fn of(knots: &[ColumnKnots], nominal: usize, refinement: usize) -> Self {
        let banded: Vec<&ColumnKnots> = knots.iter().filter(|k| k.band_top > k.foot).collect();
        if banded.is_empty() || refinement == 0 {
            return Self {
                below: 0,
                band: 0,
                above: nominal,
            };
        }
        let most =
            |f: &dyn Fn(&ColumnKnots) -> f64| banded.iter().map(|k| f(k)).fold(0.0f64, f64::max);
        let fine = refinement as f64;
        // Below the trace the worm never touches: rows up to two nominal rows high (the face
        // ends, where the trace climbs many rows above the foot, set the count).
        // (none where the trace lies within half a band row of the foot in every column).
        let reach = most(&|k| (k.trace - k.foot) / k.row(nominal));
        let below = if reach * fine <= 0.5 {
            0
        } else {
            ((reach / 2.0 - 0.01).ceil() as usize).max(1)
        };
        let band = most(&|k| ((k.band_top - k.trace) * fine / k.row(nominal) - 0.01).ceil());
        let above = most(&|k| ((k.top - k.band_top) / k.row(nominal)).round()).max(1.0);
        Self {
            below,
            band: (band as usize).max(1),
            above: above as usize,
        }
    }

    /// Rows of the grid (I plus the band's extra rows).
    pub fn rows(&self) -> usize {
        self.below + self.band + self.above
    }

    /// The knots this plan places on a column: without rows below the trace the trace is the
    /// foot; with them it stays at least a tenth of a nominal row above it; without a band the
    /// column is evenly spaced.
    pub fn fit(&self, k: &ColumnKnots, nominal: usize) -> ColumnKnots {
        if self.band == 0 || k.band_top <= k.foot {
            return ColumnKnots {
                trace: k.foot,
                band_top: k.foot,
                ..*k
            };
        }
        let trace = if self.below == 0 {
            k.foot
        } else {
            k.trace.max(k.foot + 0.1 * k.row(nominal))
        };
        ColumnKnots {
            trace,
            band_top: k.band_top.max(trace + 0.1 * k.row(nominal)),
            ..*k
        }
    }

    /// Radius at height parameter g (0..=rows; row i at g = i) of a column with knots `k`
    /// (fitted, [`Self::fit`]), m: evenly spaced within each run.
    pub fn radius(&self, k: &ColumnKnots, g: f64) -> f64 {
        if self.band == 0 || k.band_top <= k.foot {
            // Evenly spaced from the foot (the same expression as the grid of before).
            let rows = self.rows();
            return k.foot + (k.top - k.foot) * g / rows as f64;
        }
        let (b, m) = (self.below as f64, (self.below + self.band) as f64);
        if self.below > 0 && g <= b {
            run(k.foot, k.trace, g, self.below)
        } else if g <= m {
            run(k.trace, k.band_top, g - b, self.band)
        } else {
            run(k.band_top, k.top, g - m, self.above)
        }
    }
}

/// The radius at t (0..=n) of n evenly spaced rows from `lo` to `hi`, m: each end exact (the
/// foot must stay a generated point, the trace and the band's top knots).
fn run(lo: f64, hi: f64, t: f64, n: usize) -> f64 {
    let n = n as f64;
    if t <= 0.5 * n {
        lo + (hi - lo) * t / n
    } else {
        hi - (hi - lo) * (n - t) / n
    }
}

/// The height parameter of radius `r` (m) on one node column whose nodes' radii ascend
/// (`radius` reads a node's): the row index, fractional between two nodes (linear in r, since
/// the rows are evenly spaced only within each run), extended with the end rows beyond the
/// column (MODEL §3.3).
pub fn row_parameter_on<T>(column: &[T], radius: impl Fn(&T) -> f64, r: f64) -> f64 {
    let rows = column.len() - 1;
    let i = column
        .partition_point(|p| radius(p) <= r)
        .saturating_sub(1)
        .min(rows - 1);
    let (lo, hi) = (radius(&column[i]), radius(&column[i + 1]));
    i as f64 + (r - lo) / (hi - lo)
}

/// The node of a column (as [`row_parameter_on`]) nearest radius `r`: the lower of two equally
/// near, the end node beyond the column.
pub fn nearest_node_on<T>(column: &[T], radius: impl Fn(&T) -> f64, r: f64) -> usize {
    let rows = column.len() - 1;
    let g = row_parameter_on(column, radius, r);
    if g <= 0.0 {
        return 0;
    }
    let i = (g.floor() as usize).min(rows);
    if i < rows && g - i as f64 > 0.5 {
        i + 1
    } else {
        i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_radius_reads_its_row_between_uneven_nodes_and_its_nearest_node() {
        let radii = [1.0, 2.0, 2.5, 4.5];
        let at = |r| row_parameter_on(&radii, |&x| x, r);
        let near = |r| nearest_node_on(&radii, |&x| x, r);
        assert_eq!(at(1.0), 0.0);
        assert_eq!(at(2.25), 1.5);
        assert_eq!(at(3.5), 2.5);
        assert_eq!(at(4.5), 3.0);
        // Beyond the column, its end rows extended.
        assert_eq!(at(0.5), -0.5);
        assert_eq!(at(5.5), 3.5);
        // Nearest: the lower of two equally near, the end nodes beyond.
        assert_eq!(
            [
                near(0.0),
                near(1.5),
                near(1.6),
                near(2.2),
                near(3.6),
                near(9.0)
            ],
            [0, 0, 1, 1, 3, 3]
        );
    }

    fn column(trace: f64, strip_top: f64) -> ColumnKnots {
        let reach = WormReach { trace, strip_top };
        ColumnKnots::new(0.0, 40.0, Some(reach), 40, 4)
    }

    #[test]
    fn refinement_zero_spaces_the_rows_evenly_as_before() {
        let k = ColumnKnots::new(
            0.0,
            40.0,
            Some(WormReach {
                trace: 3.3,
                strip_top: 3.3,
            }),
            40,
            0,
        );
        let plan = RowPlan::of(&[k], 40, 0);
        assert_eq!(plan.rows(), 40);
        let k = plan.fit(&k, 40);
        for i in 0..=40 {
            assert_eq!(
                plan.radius(&k, i as f64),
                0.0 + (40.0 - 0.0) * i as f64 / 40.0
            );
        }
    }

    #[test]
    fn a_node_row_lies_on_the_trace_and_the_band_is_refinement_times_finer() {
        let k = column(3.3, 3.3);
        let plan = RowPlan::of(&[k], 40, 4);
        let k = plan.fit(&k, 40);
        assert_eq!(
            plan.below, 2,
            "rows up to two nominal rows high below the trace"
        );
        assert_eq!(
            plan.band, 16,
            "four nominal rows above the trace, four times finer"
        );
        // (a fiftieth of a band row above the trace: inside the worm's reach)
        assert_eq!(plan.radius(&k, plan.below as f64), 3.3 + 0.02 * 0.25);
        let band_row = plan.radius(&k, 4.0) - plan.radius(&k, 3.0);
        assert!((band_row - 0.25).abs() < 1e-12, "{band_row}");
        assert_eq!(plan.radius(&k, plan.rows() as f64), 40.0);
        // Ascending everywhere.
        for i in 0..plan.rows() {
            assert!(plan.radius(&k, (i + 1) as f64) > plan.radius(&k, i as f64));
        }
    }

    #[test]
    fn the_band_covers_the_edge_strip_and_every_column_gets_the_same_counts() {
        let (a, b) = (column(2.0, 2.7), column(3.6, 3.6));
        let plan = RowPlan::of(&[a, b], 40, 4);
        assert_eq!(plan.below, 2);
        assert_eq!(
            plan.band, 20,
            "the 0.7-row strip as a whole row, and 4 rows, at a quarter row"
        );
        for k in [a, b] {
            let k = plan.fit(&k, 40);
            assert_eq!(plan.radius(&k, plan.below as f64), k.trace);
            assert!(k.trace > 2.0);
            assert_eq!(plan.radius(&k, (plan.below + plan.band) as f64), k.band_top);
        }
    }

    #[test]
    fn a_strip_of_a_hundredth_of_a_row_leaves_the_sharp_band() {
        let sharp = column(3.3, 3.3);
        let edge = column(3.3, 3.3 + 0.005);
        assert_eq!(sharp, edge);
    }

    #[test]
    fn a_trace_at_the_foot_starts_the_band_there() {
        let k = column(0.05, 0.05);
        let plan = RowPlan::of(&[k], 40, 4);
        assert_eq!(plan.below, 0);
        let k = plan.fit(&k, 40);
        assert_eq!(k.trace, 0.0);
        assert_eq!(plan.radius(&k, 0.0), 0.0);
    }
}
