//! Fatigue damage of every node of the loaded wheel flank over life, the pits it makes, and
//! the pitting phases a forecast finds from them (MODEL §8, "beyond the schedule-driven version"; the law is ours, stated here).
//!
//! Each node carries the damage law of [`crate::pitting`]: its equivalent pressure from the
//! stress below the flank (MODEL §8.1, [`crate::subsurface`]; the largest of its cells'
//! patterns, or with `[wear] damage_node_reading = "interpolated"` their mean, the field at the
//! node's place: [`node_value`]) on the pressure–life curve, its wear per cycle, and a damaged layer as deep as
//! the maximum of that stress. With `[wear] pitting_stress = "surface-pressure"` the node
//! reads its loaded-pattern pressure instead (as the published pits are cut) and its layer is
//! as deep as its pit would be (0.78 a, [`super::pit_depths`]).
//!
//! Over a wear step the loads of the state that starts it hold, as the wear rates do (MODEL
//! §7.3); in a pitting phase, which the published coupling models as the incubation of the
//! pits cut at its start and nothing else, the damage holds. The damage is tracked in every
//! life (maps and records compare); it acts with pits from the damage
//! (`[wear] pitting = "damage"` or `"forecast"`): at the start of a pitting phase the pits are
//! cut where a loaded node's damage has reached 1 (its damaged layer removed; the node starts again
//! undamaged, its damaged layer gone with the flakes), not above a pressure limit.
//!
//! A forecast also finds the phases. A wear step ends where the next loaded node's damage
//! reaches 1; at a state of a wear phase (after its first) with such a node a pitting phase
//! starts. It lasts the life on the curve at the median damage-law pressure of its pits
//! ([`NodeLoads::median_due_pressure`]): the published coupling's relation between a phase's
//! duration and its limit, p_lim(D) = limit (the curve's scatter, the published +10 %, is the
//! life factor's to carry). Then wear resumes on the pitted flank.

use super::{node_cells, pit_depths, CycleWear};
use crate::geometry::WheelFlank;
use crate::input::{Endurance, NodeReading, PitDepth, PittingStress};
use crate::ltca::Ltca;
use crate::pitting::CellLoad;
use crate::wear::StepRecord;

/// Damage at or above which a node has reached its life (round-off of the exact step end).
pub const REACHED: f64 = 1.0 - 1e-9;

/// The damage loads of the loaded flank's nodes in one state.
#[derive(Debug, Clone)]
pub struct NodeLoads {
    /// The damage law's pressure of every node: the equivalent pressure (MODEL §8.1) or the
    /// loaded-pattern pressure, the largest of its cells, Pa.
    pub pressure: Vec<f64>,
    /// The damage law's load of every node the contact loads (pressure and pit depth > 0);
    /// None where it does not, whose damage stays as it is.
    pub cells: Vec<Option<CellLoad>>,
    /// Share of the active flank each node stands for (a quarter of each cell around it).
    pub share: Vec<f64>,
}

impl NodeLoads {
    /// Loads of every node from a state's loaded analysis and wear of one cycle: the stress
    /// the damage reads (`stress`, each node reading its cells as `reading` says), the depth
    /// of its maximum as the damaged layer (the pits' `rule` for the surface pressure, and
    /// where the depth is not known).
    pub fn new(
        wf: &WheelFlank,
        l: &Ltca,
        cw: &CycleWear,
        curve: &Endurance,
        (rule, stress, reading): (PitDepth, PittingStress, NodeReading),
    ) -> Self {
        let mut layer = pit_depths(cw, rule);
        let pressure: Vec<f64> = match stress {
            PittingStress::SurfacePressure => (0..wf.nodes.len())
                .map(|k| {
                    let cells = node_cells(wf, k).filter_map(|c| Some((*l.pattern.get(c)?, 0.0)));
                    node_value(cells, reading).0
                })
                .collect(),
            _ => (0..wf.nodes.len())
                .map(|k| {
                    let (p, depth) = node_equivalent(wf, l, k, reading);
                    if depth > 0.0 {
                        layer.values[k] = depth;
                    }
                    p
                })
                .collect(),
        };
        let share = node_shares(wf);
        let cells = pressure
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                let h = layer.values[k];
                (p > 0.0 && h > 0.0).then(|| CellLoad::new(curve, p, cw.depth.values[k], h))
            })
            .collect();
        Self {
            pressure,
            cells,
            share,
        }
    }

    /// Cycles until the first loaded node reaches a damage of 1 (None: no node would).
    pub fn cycles_to_first_pit(&self, damage: &[f64]) -> Option<f64> {
        self.cells
            .iter()
            .zip(damage)
            .filter(|(_, &d)| d < REACHED)
            .filter_map(|(c, &d)| c.as_ref()?.cycles_to_pit(d))
            .min_by(f64::total_cmp)
    }

    /// The same loads without wear (a pitting phase: no wear carries the damage away).
    pub fn without_wear(&self) -> Self {
        Self {
            pressure: self.pressure.clone(),
            share: self.share.clone(),
            cells: self
                .cells
                .iter()
                .map(|c| {
                    c.map(|c| CellLoad {
                        wear_rate: 0.0,
                        ..c
                    })
                })
                .collect(),
        }
    }

    /// Advances every loaded node's damage over `cycles`, with its wear (a wear step) or
    /// without.
    pub fn advance(&self, damage: &mut [f64], cycles: f64, wear: bool) {
        for (d, c) in damage.iter_mut().zip(&self.cells) {
            if let Some(c) = c {
                let load = CellLoad {
                    wear_rate: if wear { c.wear_rate } else { 0.0 },
                    ..*c
                };
                *d = load.damage_after(*d, cycles);
            }
        }
    }

    /// The nodes due to pit: loaded, with their damage at 1.
    pub fn due(&self, damage: &[f64]) -> Vec<usize> {
        (0..damage.len())
            .filter(|&k| self.cells[k].is_some() && damage[k] >= REACHED)
            .collect()
    }

    /// Share of the active flank of the nodes due to pit.
    pub fn due_share(&self, damage: &[f64]) -> f64 {
        self.due(damage).iter().map(|&k| self.share[k]).sum()
    }

    /// Cycles until the nodes due to pit make up `onset` of the active flank (and at least
    /// one node), the nodes reaching 1 in turn under these loads (None: they never would).
    pub fn cycles_to_onset(&self, damage: &[f64], onset: f64) -> Option<f64> {
        let mut due = self.due_share(damage);
        let mut next: Vec<(f64, usize)> = self
            .cells
            .iter()
            .zip(damage)
            .enumerate()
            .filter(|(_, (_, &d))| d < REACHED)
            .filter_map(|(k, (c, &d))| Some((c.as_ref()?.cycles_to_pit(d)?, k)))
            .collect();
        next.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (n, k) in next {
            due += self.share[k];
            if due >= onset {
                return Some(n);
            }
        }
        None
    }

    /// The median damage-law pressure (equivalent or pattern) of the nodes due to pit, weighted by their flank shares
    /// (Pa; None: none is due). A median, not the lowest: a damaged node that the moving
    /// pattern now barely touches does not stand for the pressure that damaged it.
    pub fn median_due_pressure(&self, damage: &[f64]) -> Option<f64> {
        let mut due: Vec<(f64, f64)> = self
            .due(damage)
            .into_iter()
            .map(|k| (self.pressure[k], self.share[k]))
            .collect();
        due.sort_by(|a, b| a.0.total_cmp(&b.0));
        let half = 0.5 * due.iter().map(|d| d.1).sum::<f64>();
        let mut sum = 0.0;
        due.into_iter().find_map(|(p, w)| {
            sum += w;
            (sum >= half).then_some(p)
        })
    }

    /// Cuts the pits of the nodes due (`wear::forecast`): each loses its damaged layer (0.78 a)
    /// and starts again undamaged. Returns the nodes cut.
    pub fn cut_due(
        &self,
        damage: &mut [f64],
        removal: &mut crate::geometry::FlankField,
        pitted: &mut [bool],
    ) -> Vec<usize> {
        let due = self.due(damage);
        for &k in &due {
            if let Some(c) = &self.cells[k] {
                removal.values[k] += c.layer;
                pitted[k] = true;
                damage[k] = 0.0;
            }
        }
        due
    }
}

/// Share of the active flank each node stands for: a quarter of each grid cell around it
/// (the nodes' shares sum to 1). The area a forecast's onset and the damage warning count.
pub fn node_shares(wf: &WheelFlank) -> Vec<f64> {
    let ni = wf.cells_height;
    let mut share = vec![0.0; wf.nodes.len()];
    let total = wf.active_area();
    for j in 0..wf.cells_face {
        for i in 0..ni {
            for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                share[(j + dj) * (ni + 1) + i + di] += 0.25 * wf.cell_area[j * ni + i] / total;
            }
        }
    }
    share
}

/// The equivalent pressure of node k from its cells' patterns as `reading` says (Pa) and the
/// depth of the largest cell's maximum (m; MODEL §8.1).
pub fn node_equivalent(wf: &WheelFlank, l: &Ltca, k: usize, reading: NodeReading) -> (f64, f64) {
    let cells = node_cells(wf, k)
        .filter_map(|c| Some((*l.equivalent_pattern.get(c)?, *l.equivalent_depth.get(c)?)));
    node_value(cells, reading)
}

/// A node's value from its cells' (value, depth) pairs: the largest value, or the cells'
/// mean (the cell-centred field interpolated to the node), with the depth of the largest
/// cell either way; (0, 0) without cells.
pub fn node_value(cells: impl Iterator<Item = (f64, f64)>, reading: NodeReading) -> (f64, f64) {
    let (mut largest, mut sum, mut count) = ((0.0, 0.0), 0.0, 0usize);
    for (value, depth) in cells {
        if value > largest.0 {
            largest = (value, depth);
        }
        sum += value;
        count += 1;
    }
    match reading {
        NodeReading::Largest => largest,
        NodeReading::Interpolated if count > 0 => (sum / count as f64, largest.1),
        NodeReading::Interpolated => (0.0, 0.0),
    }
}

/// The area reading of first pitting (MODEL §8.1: pitting is an area, the forecast reads
/// p_eq,2%): damage per cycle of the state of `record`, the life of its p_eq,2% on the
/// pressure–life curve inverted (with a duty cycle each bin's at its cycle share); zero in a
/// pitting phase, where the nodes' damage holds too.
pub fn area_damage_rate(record: &StepRecord, curve: &Endurance) -> f64 {
    if record.phase == "pitting" {
        return 0.0;
    }
    area_loads(record)
        .iter()
        .map(|&(share, p)| share / curve.life(p))
        .sum()
}

/// What the area reading reads in the state of `record`: (share of the cycles, p_eq,2% in Pa)
/// of the state's own analysis (share 1), or of each bin of a duty cycle.
fn area_loads(record: &StepRecord) -> Vec<(f64, f64)> {
    if record.bins.is_empty() {
        return vec![(1.0, record.equivalent_pressure_first_pitting_pa)];
    }
    record
        .bins
        .iter()
        .map(|b| (b.cycle_share, b.equivalent_pressure_first_pitting_pa))
        .collect()
}

/// The area reading's Miner sum at `cycles` after the state of `last` (none: the life's first
/// state, 0), whose rate holds over the step (as the nodes' loads do, MODEL §7.3).
pub fn area_damage_after(last: Option<&StepRecord>, cycles: f64, curve: &Endurance) -> f64 {
    last.map_or(0.0, |r| {
        r.area_damage + (cycles - r.cycles).max(0.0) * area_damage_rate(r, curve)
    })
}

/// Cycles at which the area reading's Miner sum reaches 1 over `records` (None: not within
/// them): within the step that crosses it, where its rate is constant.
pub fn area_first_pitting_cycles(records: &[StepRecord], curve: &Endurance) -> Option<f64> {
    records.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        (b.area_damage >= REACHED).then(|| {
            let rate = area_damage_rate(a, curve);
            a.cycles + ((1.0 - a.area_damage) / rate).clamp(0.0, b.cycles - a.cycles)
        })
    })
}

/// How much of the area reading's Miner sum (MODEL §8.1) rests on the pressure–life curve
/// beyond its data: the curve's points span lives from 0.6e6 to 11e6 cycles (MODEL §8,
/// [`Endurance::data_span`]); a p_eq,2% whose life is shorter lies above the highest pressure
/// tested, where the power law is extrapolated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaExtrapolation {
    /// The Miner sum over the wear steps up to the cycles read (the records' `area_damage`
    /// there).
    pub damage: f64,
    /// Its part from states (with a duty cycle, bins) whose p_eq,2% has a life shorter than
    /// the data's shortest.
    pub beyond: f64,
    /// The largest such p_eq,2%, Pa (0: none).
    pub highest_pa: f64,
    /// The cycles of the first state with one (None: none).
    pub first_cycles: Option<f64>,
}

impl AreaExtrapolation {
    /// The share of the sum beyond the data (0 for no sum).
    pub fn share(&self) -> f64 {
        if self.damage > 0.0 {
            self.beyond / self.damage
        } else {
            0.0
        }
    }
}

/// The area reading's Miner sum over `records` up to `until` cycles, split by where on the
/// pressure–life curve `curve` its parts lie ([`AreaExtrapolation`]): each wear step adds its
/// cycles over the life of the starting state's p_eq,2% (each bin's at its cycle share), as
/// [`area_damage_rate`] does; a pitting phase adds nothing.
pub fn area_damage_beyond_data(
    records: &[StepRecord],
    curve: &Endurance,
    until: f64,
) -> AreaExtrapolation {
    let shortest = curve.data_span().0;
    let mut out = AreaExtrapolation {
        damage: 0.0,
        beyond: 0.0,
        highest_pa: 0.0,
        first_cycles: None,
    };
    for w in records.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let span = b.cycles.min(until) - a.cycles;
        if span <= 0.0 {
            break;
        }
        if a.phase == "pitting" {
            continue;
        }
        for (share, p) in area_loads(a) {
            let life = curve.life(p);
            let damage = span * share / life;
            out.damage += damage;
            if life < shortest {
                out.beyond += damage;
                out.highest_pa = out.highest_pa.max(p);
                out.first_cycles.get_or_insert(a.cycles);
            }
        }
    }
    out
}

/// A phase of a life as it happened: kind ("wear" or "pitting"), start and end cycles, and
/// the pitted share of the active flank at its end.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PhaseSpan {
    pub kind: String,
    pub start_cycles: f64,
    pub end_cycles: f64,
    pub pitted_share_end: f64,
}

/// The phases of a life from its records (consecutive states of the same phase joined; a
/// phase ends where the next begins): what the report and summary show.
pub fn phase_spans(records: &[super::StepRecord]) -> Vec<PhaseSpan> {
    let mut spans: Vec<PhaseSpan> = Vec::new();
    for r in records {
        match spans.last_mut() {
            Some(s) if s.kind == r.phase => {
                s.end_cycles = r.cycles;
                s.pitted_share_end = r.pitted_area_fraction;
            }
            last => {
                if let Some(s) = last {
                    s.end_cycles = r.cycles;
                }
                spans.push(PhaseSpan {
                    kind: r.phase.clone(),
                    start_cycles: r.cycles,
                    end_cycles: r.cycles,
                    pitted_share_end: r.pitted_area_fraction,
                });
            }
        }
    }
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record at `cycles` in `phase` whose p_eq,2% is `p` (Pa).
    fn record(cycles: f64, phase: &str, p: f64) -> StepRecord {
        StepRecord {
            cycles,
            phase: phase.into(),
            equivalent_pressure_first_pitting_pa: p,
            ..StepRecord::default()
        }
    }

    #[test]
    fn the_area_sum_beyond_the_curve_s_data_is_its_steps_above_the_highest_tested_pressure() {
        // MODEL §8: the CuSn12 curve's points span 0.6e6 to 11e6 cycles, 709 to 425 MPa. A
        // step at 900 MPa (life 0.14e6) lies beyond them, one at 500 MPa (4.3e6) within; a
        // pitting phase adds nothing. Lives from the power law written out here.
        let curve = Endurance::DEFAULT;
        let life = |p: f64| 11e6 * (p / 425e6).powf(-1.0 / 0.176);
        let highest = 425e6 * (0.6e6f64 / 11e6).powf(-0.176);
        assert!((curve.pressure(curve.data_span().0) - highest).abs() < 1.0);
        assert!(life(900e6) < 0.6e6 && life(500e6) > 0.6e6 && highest < 900e6);
        let records = [
            record(0.0, "wear", 900e6),
            record(1e5, "wear", 500e6),
            record(3e5, "pitting", 950e6),
            record(4e5, "wear", 600e6),
            record(5e5, "wear", 600e6),
        ];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        let e = area_damage_beyond_data(&records, &curve, 5e5);
        let beyond = 1e5 / life(900e6);
        let damage = beyond + 2e5 / life(500e6) + 1e5 / life(600e6);
        assert!(close(e.beyond, beyond), "{e:?}");
        assert!(close(e.damage, damage), "{e:?}: {damage}");
        assert!(close(e.share(), beyond / damage));
        assert_eq!((e.highest_pa, e.first_cycles), (900e6, Some(0.0)));
        // Read part-way: the crossed step counts up to there.
        let e = area_damage_beyond_data(&records, &curve, 1.5e5);
        assert!(close(e.damage, beyond + 0.5e5 / life(500e6)), "{e:?}");
        // The same steps as the records' sum: each step at area_damage_rate.
        let rates: f64 = records
            .windows(2)
            .map(|w| (w[1].cycles - w[0].cycles) * area_damage_rate(&w[0], &curve))
            .sum();
        assert!(close(rates, damage));
        // Within the data throughout: nothing beyond, no place.
        let within = [record(0.0, "wear", 600e6), record(1e6, "wear", 450e6)];
        let e = area_damage_beyond_data(&within, &curve, 1e6);
        assert_eq!((e.beyond, e.highest_pa, e.first_cycles), (0.0, 0.0, None));
        assert!(close(e.damage, 1e6 / life(600e6)));
    }

    #[test]
    fn a_duty_cycle_s_bins_each_count_at_their_share() {
        let curve = Endurance::DEFAULT;
        let bin = |share: f64, p: f64| crate::wear::spectrum::BinRecord {
            cycle_share: share,
            equivalent_pressure_first_pitting_pa: p,
            ..Default::default()
        };
        let mut start = record(0.0, "wear", 0.0);
        start.bins = vec![bin(0.25, 900e6), bin(0.75, 500e6)];
        let records = [start, record(2e5, "wear", 500e6)];
        let e = area_damage_beyond_data(&records, &curve, 2e5);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(e.beyond, 2e5 * 0.25 / curve.life(900e6)), "{e:?}");
        assert!(close(
            e.damage,
            2e5 * (0.25 / curve.life(900e6) + 0.75 / curve.life(500e6))
        ));
    }

    /// The four cells around a node at (i, j) of a field f(x, y) given at cell centres
    /// (i +- 1/2, j +- 1/2), with depth 1 mm times the value's rank.
    fn around(f: impl Fn(f64, f64) -> f64, i: f64, j: f64) -> Vec<(f64, f64)> {
        [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)]
            .iter()
            .map(|(di, dj)| (f(i + di, j + dj), 1e-3 * (i + di + 2.0 * (j + dj))))
            .collect()
    }

    #[test]
    fn the_interpolated_reading_is_the_field_at_the_node_and_the_largest_half_a_cell_up() {
        // A field linear over the grid (Pa): the mean of the four cell centres is its value at
        // the node exactly; the largest reads it half a cell up each way.
        let f = |x: f64, y: f64| 500e6 + 12e6 * x - 5e6 * y;
        let (i, j) = (7.0, 3.0);
        let cells = around(f, i, j);
        let (mean, depth) = node_value(cells.iter().copied(), NodeReading::Interpolated);
        assert!(
            (mean - f(i, j)).abs() < 1e-12 * f(i, j),
            "{mean} {}",
            f(i, j)
        );
        let (largest, largest_depth) = node_value(cells.iter().copied(), NodeReading::Largest);
        assert_eq!(largest, f(i + 0.5, j - 0.5));
        // The depth is the largest cell's under either reading.
        assert_eq!(depth, largest_depth);
        assert_eq!(largest_depth, 1e-3 * (i + 0.5 + 2.0 * (j - 0.5)));
    }

    #[test]
    fn a_peak_one_cell_row_wide_reaches_two_node_rows_at_half_height_when_interpolated() {
        // Cells of row 5 at 1 GPa, the rest at 400 MPa: the nodes of rows 5 and 6 each touch
        // two peak cells and two others. The largest reads the peak on both node rows (twice
        // the peak's area); the interpolation reads the mean, the field's value on the row's
        // edges; a uniform field reads the same both ways; a node without cells reads 0.
        let f = |x: f64, _y: f64| if (x - 5.5).abs() < 0.25 { 1e9 } else { 400e6 };
        for i in [5.0, 6.0] {
            let cells = around(f, i, 10.0);
            assert_eq!(
                node_value(cells.iter().copied(), NodeReading::Largest).0,
                1e9
            );
            let mean = node_value(cells.iter().copied(), NodeReading::Interpolated).0;
            assert!((mean - 700e6).abs() < 1e-3, "{mean}");
        }
        // The largest is the published cut's reading of the pattern (the largest cell, 0 at
        // least), which the surface-pressure damage read before it went through `node_value`.
        let pattern = [3e8, f64::NAN, -1.0, 7e8];
        let published = pattern.iter().copied().fold(0.0, f64::max);
        let read = node_value(pattern.iter().map(|&p| (p, 0.0)), NodeReading::Largest).0;
        assert_eq!(read, published);
        let uniform = around(|_, _| 612e6, 3.0, 4.0);
        for reading in [NodeReading::Largest, NodeReading::Interpolated] {
            assert_eq!(node_value(uniform.iter().copied(), reading).0, 612e6);
            assert_eq!(node_value(std::iter::empty(), reading), (0.0, 0.0));
        }
    }
}
