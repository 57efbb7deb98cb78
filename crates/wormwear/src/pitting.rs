//! Fatigue damage of the wheel flank for a pitting forecast (MODEL §8, "beyond the
//! schedule-driven version", and `wear::forecast`): the damage law of one flank cell. The life loop
//! applies it at every node of the loaded flank (`wear::forecast`).
//!
//! **Damage.** A cell loaded each cycle at the pressure p gathers 1 / N(p) of damage per cycle
//! (Miner's rule). N(p) is the life on the bronze pressure–life curve
//! p_lim(N) = p_ref (N / N_ref)^-b, inverted ([`Endurance::life`]).
//!
//! **Wear carries damage away.** The damage lives in the layer above the depth of the largest
//! sub-surface shear stress, h = 0.78 a (MODEL §12 g), and is taken as uniform over it. Wear
//! at w per cycle removes a slice w of that layer, and the layer gains w of fresh material at
//! its bottom, so the damage falls by the fraction w / h:
//!
//!   dD/dN = r - D w / h,    r = 1 / N(p).
//!
//! With r, w and h constant over a step, the exact solution is
//! D(N) = D* + (D0 - D*) exp(-N w / h), with the steady damage D* = r h / w. A cell whose
//! steady damage stays below 1 wears faster than it accumulates damage, and it never pits; the
//! published observation that wear and pitting compete. With w = 0 the damage grows
//! linearly, D0 + r N, and a cell at constant pressure pits after exactly N(p) cycles.

use crate::input::Endurance;

/// The share of the active flank whose pitting is first pitting (A_p10 = 2 %, MODEL §8.1, §9:
/// Rank's N_LI): the pitting safety reads the equivalent pressure exceeded on it, the forecast
/// starts pitting once the nodes whose damage has reached 1 make it up.
pub const FIRST_PITTING_SHARE: f64 = 0.02;

/// The value exceeded on `share` of the active flank (MODEL §8.1 "Which p_eq decides"): the
/// area-weighted quantile of the per-cell `values` of the flank grid (areas `cell_area`, m^2,
/// the cells where `active`: `WheelFlank::cell_area`, `WheelFlank::active`), the value of the
/// cell where the area of the cells at or above it reaches `share` of the active area. A
/// uniform field gives its value; cells holding less than `share` of the area above the rest
/// (a spike, a saturated edge strip) do not move it. 0 where fewer than `share` of the area
/// carries a value (or no cell is active).
pub fn exceeded_on_share(values: &[f64], cell_area: &[f64], active: &[bool], share: f64) -> f64 {
    let mut cells: Vec<(f64, f64)> = (0..values.len().min(cell_area.len()))
        .filter(|&k| active.get(k).copied().unwrap_or(false))
        .map(|k| (values[k], cell_area[k]))
        .collect();
    let active: f64 = cells.iter().map(|c| c.1).sum();
    cells.sort_by(|a, b| b.0.total_cmp(&a.0));
    let wanted = share * active;
    let mut above = 0.0;
    for (value, area) in cells {
        above += area;
        // (a share reached exactly by whole cells must not miss by the sum's rounding)
        if above >= wanted * (1.0 - 1e-12) {
            return value.max(0.0);
        }
    }
    0.0
}

impl Endurance {
    /// Life at the pressure `p` on the pressure–life curve, cycles:
    /// N = f N_ref (p / p_ref)^(-1/b), f the life factor. Infinite for p <= 0 (an unloaded
    /// cell never pits).
    pub fn life(&self, p: f64) -> f64 {
        if p <= 0.0 {
            return f64::INFINITY;
        }
        self.life_factor
            * self.reference_cycles
            * (p / self.reference_pressure).powf(-1.0 / self.exponent)
    }
}

/// The damage state of one cell over a step: the rate of damage per cycle, the wear per cycle
/// (m) and the damaged layer's thickness (m), all constant over the step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellLoad {
    /// Damage per cycle, 1 / N(p).
    pub damage_rate: f64,
    /// Wear depth per cycle, m (>= 0).
    pub wear_rate: f64,
    /// Damaged layer thickness 0.78 a, m (> 0).
    pub layer: f64,
}

impl CellLoad {
    /// The load of a cell at pressure `p` (Pa) on `curve`, wearing `wear_rate` m per cycle,
    /// with a damaged layer `layer` m thick.
    pub fn new(curve: &Endurance, p: f64, wear_rate: f64, layer: f64) -> Self {
        Self {
            damage_rate: 1.0 / curve.life(p),
            wear_rate: wear_rate.max(0.0),
            layer,
        }
    }

    /// The steady damage r h / w that wear holds the cell at (infinite without wear).
    pub fn steady_damage(&self) -> f64 {
        if self.wear_rate > 0.0 {
            self.damage_rate * self.layer / self.wear_rate
        } else {
            f64::INFINITY
        }
    }

    /// Damage after `cycles` cycles from `d0`: the exact solution of dD/dN = r - D w / h.
    pub fn damage_after(&self, d0: f64, cycles: f64) -> f64 {
        let steady = self.steady_damage();
        // No wear, or so little that the steady damage overflows: the damage only grows.
        if self.wear_rate <= 0.0 || !steady.is_finite() {
            return d0 + self.damage_rate * cycles;
        }
        // D* + (D0 - D*) e^{-x}, written with expm1 so that a short step keeps its digits.
        let x = cycles * self.wear_rate / self.layer;
        d0 - (d0 - steady) * (-(-x).exp_m1())
    }

    /// Cycles from the damage `d0` until the cell pits (damage 1): None if it never does
    /// (steady damage at or below 1, or no damage rate); 0 if it has already.
    pub fn cycles_to_pit(&self, d0: f64) -> Option<f64> {
        if d0 >= 1.0 {
            return Some(0.0);
        }
        if self.damage_rate <= 0.0 {
            return None;
        }
        if self.wear_rate <= 0.0 {
            return Some((1.0 - d0) / self.damage_rate);
        }
        let steady = self.steady_damage();
        if steady <= 1.0 {
            return None;
        }
        // e^{-N w/h} = (D* - 1) / (D* - D0) = 1 - eps. Where eps is small (a steady damage far
        // above 1: little wear) that ratio rounds towards 1 and its logarithm to 0 (a wear
        // coefficient of 1e-300 gave 0 cycles to pit, and a forecast stepped 0 cycles for
        // ever): there N = (1 - D0) / r  D* / (D* - D0)  (-ln(1 - eps) / eps), whose last
        // factor tends to 1 (the life without wear).
        let eps = (1.0 - d0) / (steady - d0);
        if eps >= 1e-3 {
            return Some(-(self.layer / self.wear_rate) * ((steady - 1.0) / (steady - d0)).ln());
        }
        let growth = match steady.is_finite() {
            true => steady / (steady - d0),
            false => 1.0,
        };
        let log_ratio = match eps > 0.0 {
            true => -(-eps).ln_1p() / eps,
            false => 1.0,
        };
        Some((1.0 - d0) / self.damage_rate * growth * log_ratio)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_share_exceeded_reads_the_load_not_a_narrow_strip_or_spike() {
        use super::FIRST_PITTING_SHARE as TWO;
        // A flank grid of 40 x 60 equal cells, every cell active.
        let n = 40 * 60;
        let (area, active) = (vec![1e-6; n], vec![true; n]);
        let exceeded_on_share =
            |v: &[f64], share: f64| super::exceeded_on_share(v, &area, &active, share);
        // A uniform Hertz-like load: p0 everywhere (any share).
        let p0 = 612e6;
        assert_eq!(exceeded_on_share(&vec![p0; n], TWO), p0);
        // Its sqrt growth with the load carries straight through.
        let scaled: Vec<f64> = vec![p0 * 4.5f64.sqrt(); n];
        assert_eq!(exceeded_on_share(&scaled, TWO), p0 * 4.5f64.sqrt());
        // A saturated strip of one row (1/40 = 2.5 % > 2 %) is read; two thirds of that row
        // (1.7 %) is not, nor a one-cell spike of 3 p0.
        let strip = |cells: usize| {
            let mut v = vec![p0; n];
            for j in 0..cells {
                v[j * 40] = 1e9;
            }
            v
        };
        assert_eq!(exceeded_on_share(&strip(60), TWO), 1e9);
        assert_eq!(exceeded_on_share(&strip(40), TWO), p0);
        let mut spike = vec![p0; n];
        spike[1234] = 3.0 * p0;
        assert_eq!(exceeded_on_share(&spike, TWO), p0);
        // A graded field: the value at the 98th area percentile. Cells k = 0..n carry k; the
        // 2 % largest are the last 48: the 48th from the top is n - 48.
        let graded: Vec<f64> = (0..n).map(|k| k as f64).collect();
        assert_eq!(exceeded_on_share(&graded, TWO), (n - 48) as f64);
        // Inactive cells do not count; a pattern on less than 2 % of the flank gives 0.
        let mut small = vec![0.0; n];
        small[7] = p0;
        assert_eq!(exceeded_on_share(&small, TWO), 0.0);
    }
    use super::*;

    #[test]
    fn a_vanishing_wear_rate_gives_the_life_without_wear() {
        // Wear rates down to the smallest subnormal: the cycles to pit tend to (1 - D0) / r,
        // never 0 (the rounded logarithm gave 0, and a forecast stalled at 0 cycles), and the
        // damage after them reaches 1; a moderate rate keeps the exact solution.
        let r = 1.0 / 2e6;
        for wear_rate in [1e-12, 1e-20, 1e-200, 1e-300, 5e-324] {
            let c = CellLoad {
                damage_rate: r,
                wear_rate,
                layer: 2e-4,
            };
            for d0 in [0.0, 0.5, 0.999] {
                let n = c.cycles_to_pit(d0).unwrap();
                let without = (1.0 - d0) / r;
                // (1e-12 m per cycle over a 0.2 mm layer adds 0.5-1 % to the life: physics.)
                let close = if wear_rate < 1e-15 { 1e-6 } else { 2e-2 };
                assert!(
                    n >= without && n / without - 1.0 < close,
                    "{wear_rate} {d0}: {n}"
                );
                assert!(
                    (c.damage_after(d0, n) - 1.0).abs() < 1e-9,
                    "{wear_rate} {d0}"
                );
            }
        }
        let c = CellLoad {
            damage_rate: r,
            wear_rate: 1e-11,
            layer: 2e-4,
        };
        let n = c.cycles_to_pit(0.2).unwrap();
        assert!((c.damage_after(0.2, n) - 1.0).abs() < 1e-12);
        // Past eps = 1e-3 the same through the series form.
        let c = CellLoad {
            wear_rate: 1e-13,
            ..c
        };
        let n = c.cycles_to_pit(0.2).unwrap();
        assert!((c.damage_after(0.2, n) - 1.0).abs() < 1e-12);
    }

    const CURVE: Endurance = Endurance::DEFAULT;

    #[test]
    fn the_life_inverts_the_pressure_life_curve() {
        for n in [1e5, 7e5, 11e6, 3e8] {
            let p = CURVE.pressure(n);
            assert!((CURVE.life(p) / n - 1.0).abs() < 1e-12, "{n}");
        }
        // The published points: 425 MPa at 11e6 cycles; higher pressure, shorter life.
        assert!((CURVE.life(425e6) / 11e6 - 1.0).abs() < 1e-12);
        assert!(CURVE.life(700e6) < CURVE.life(425e6));
        assert_eq!(CURVE.life(0.0), f64::INFINITY);
        // The life factor moves the curve along the life axis: the same pressure lasts f
        // times as long, and the pressure of a life f N is that of N on the fitted curve.
        let low = Endurance {
            life_factor: 0.4,
            ..CURVE
        };
        assert!((low.life(500e6) / CURVE.life(500e6) - 0.4).abs() < 1e-12);
        assert!((low.pressure(0.4 * 3e6) / CURVE.pressure(3e6) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_cell_at_constant_pressure_without_wear_pits_at_the_curves_life() {
        for p in [450e6, 538e6, 700e6] {
            let cell = CellLoad::new(&CURVE, p, 0.0, 50e-6);
            let n = cell.cycles_to_pit(0.0).unwrap();
            assert!((n / CURVE.life(p) - 1.0).abs() < 1e-12, "{p}");
            assert!((cell.damage_after(0.0, n) - 1.0).abs() < 1e-12);
            // Miner: half the life at this pressure leaves half the damage to go.
            let half = cell.damage_after(0.0, 0.5 * n);
            assert!((cell.cycles_to_pit(half).unwrap() / (0.5 * n) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_cell_that_wears_faster_than_it_accumulates_damage_never_pits() {
        // At 500 MPa the life is 4.37e6 cycles; a 40 um layer worn at 1e-11 m per cycle
        // (4e6 cycles to wear through it) holds the damage at r h / w = 0.92.
        let cell = CellLoad::new(&CURVE, 500e6, 1e-11, 40e-6);
        let steady = cell.steady_damage();
        assert!(steady < 1.0, "{steady}");
        assert_eq!(cell.cycles_to_pit(0.0), None);
        let mut d = 0.0;
        for _ in 0..1000 {
            d = cell.damage_after(d, 1e6);
            assert!(d < steady + 1e-15, "{d}");
        }
        assert!(
            (d - steady).abs() < 1e-12,
            "tends to the steady damage: {d}"
        );
        // Slower wear (steady damage 1.83): the cell pits, later than without wear.
        let slow = CellLoad::new(&CURVE, 500e6, 0.5e-11, 40e-6);
        let n = slow.cycles_to_pit(0.0).unwrap();
        assert!(n > CURVE.life(500e6));
        assert!((slow.damage_after(0.0, n) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn steps_compose_so_the_damage_does_not_depend_on_the_step_size() {
        let cell = CellLoad::new(&CURVE, 600e6, 2e-12, 30e-6);
        let whole = cell.damage_after(0.1, 3e6);
        let mut d = 0.1;
        for _ in 0..300 {
            d = cell.damage_after(d, 1e4);
        }
        assert!((d / whole - 1.0).abs() < 1e-12, "{d} {whole}");
        // A damaged cell that starts above its steady damage heals towards it (wear removes
        // the damaged layer faster than damage builds).
        let fast = CellLoad::new(&CURVE, 450e6, 1e-10, 30e-6);
        assert!(fast.damage_after(0.9, 1e5) < 0.9);
        assert_eq!(fast.cycles_to_pit(1.0), Some(0.0));
    }
}
