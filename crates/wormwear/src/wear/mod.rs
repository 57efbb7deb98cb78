//! Stage 5 — wear of the bronze wheel over life (MODEL §7): Archard wear per mesh cycle on the
//! global flank grid, wear steps with the geometry updated, backlash.
//!
//! Per-cycle wear (MODEL §7.2). A wheel point M is swept once per wheel revolution by the
//! loaded band; the depth worn in that passage is (k/H) |vg| integral(p dt). On each node
//! column the loaded analysis gives, at every (position, tooth), the pressure profile across
//! the line; tooth k at wheel rotation theta2 is the reference tooth at theta2 + sigma k tau,
//! so these profiles are the history of the reference tooth over its whole engagement. Between
//! consecutive instants the band is moved continuously from one centroid to the next (its
//! shape blended), and the time integral of the pressure at each node is taken by quadrature:
//! the passage is resolved whatever the number of positions (sampling p only at the positions
//! would alias, MODEL §7.2), and since the profiles come from the loaded analysis on the worn
//! flank, the band follows the wear. |vg| is the node's sliding speed at its contact moment
//! (TCA), the film and k(lambda) come from [`crate::lubrication`].

use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::{FilmLoad, GearSet, PitDepth};
use crate::kinematics::{GapEvaluator, Tca};
use crate::ltca::passage::Passage;
use crate::ltca::{stats, Ltca};
use crate::lubrication::{self, LineContact};
use rayon::prelude::*;
use std::f64::consts::PI;

pub mod forecast;

/// Wear of one mesh cycle (one passage of the contact over every point of the reference
/// tooth) on the loaded wheel flank's nodes.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CycleWear {
    /// Depth worn normal to the flank per cycle, m.
    pub depth: FlankField,
    /// Film ratio lambda at the passage (the smallest if swept more than once; NaN where the
    /// loaded line never passes).
    pub lambda: FlankField,
    /// Film thickness h_min Phi_T at the passage, m (NaN where not swept).
    pub film: FlankField,
    /// Line load at the passage, N/m (the largest if swept more than once; 0 where not
    /// swept).
    pub line_load: FlankField,
    /// Relative radius of curvature across the line at that passage, m (0 where not swept).
    pub contact_radius: FlankField,
    /// Half-width of the loaded band when it passes (the largest), m (0 where not swept).
    pub half_width: FlankField,
    /// Hertz half-width of the line contact at that passage, a = sqrt(4 w R / (pi E*)) with
    /// its line load w and relative radius R (MODEL §12 g), m (0 where not swept).
    pub hertz_half_width: FlankField,
}

/// Rolling velocities of every node of the loaded flank (u1, u2; m/s); where the TCA has
/// none (nodes at the border of the region the worm flank reaches, whose surface gradient is
/// undefined), the nearest node of the same column that has them.
fn rolling_velocities(wf: &WheelFlank, tca: &Tca) -> Vec<(f64, f64)> {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    (0..=nj)
        .flat_map(|j| {
            let column: Vec<usize> = (0..=ni).map(|i| j * (ni + 1) + i).collect();
            let valid: Vec<usize> = column
                .iter()
                .copied()
                .filter(|&k| tca.node_contact[k].u2.is_finite())
                .collect();
            column
                .iter()
                .map(|&k| {
                    let src = valid
                        .iter()
                        .copied()
                        .min_by_key(|&v| (v as isize - k as isize).unsigned_abs())
                        .unwrap_or(k);
                    let c = &tca.node_contact[src];
                    (c.u1, c.u2)
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// What the wear of one cycle reads at every passage of the band over a node ([`per_cycle`]):
/// the gear, the flank, the TCA's sliding, the rolling velocities, the time between positions
/// (rad of wheel rotation) and the wheel speed (rad/s), E' (Pa), the dry wear coefficient,
/// the hardness (Pa) and the film load's reading.
struct PassageWear<'a> {
    gear: &'a GearSet,
    wf: &'a WheelFlank,
    tca: &'a Tca,
    rolling: Vec<(f64, f64)>,
    dt: f64,
    wheel_speed: f64,
    e_prime: f64,
    k_dry: f64,
    hardness: f64,
    film_load: FilmLoad,
}

impl PassageWear<'_> {
    /// Per node of column j, from the band's instants on it: depth per cycle, lambda, film,
    /// line load, band half-width, and the relative radius at the passage of the largest line
    /// load (MODEL §7.2, §6).
    fn column(&self, j: usize, samples: &mut [crate::ltca::passage::Sample]) -> Vec<[f64; 6]> {
        let ni = self.wf.cells_height;
        let mut out = vec![[0.0, f64::NAN, f64::NAN, 0.0, 0.0, 0.0]; ni + 1];
        samples.sort_by(|a, b| a.time.total_cmp(&b.time));
        for pair in samples.windows(2) {
            // Consecutive instants of the same engagement only.
            let Some(passage) = Passage::between(&pair[0], &pair[1], self.dt) else {
                continue;
            };
            for (i, o) in out.iter_mut().enumerate() {
                self.node(j * (ni + 1) + i, &passage, o);
            }
        }
        out
    }

    /// Adds one passage over node k to its entry `o` ([`Self::column`]).
    fn node(&self, k: usize, passage: &Passage, o: &mut [f64; 6]) {
        let (a, b) = (passage.a, passage.b);
        let duration = (b.time - a.time) / self.wheel_speed;
        let (lo, hi, steps) = (passage.lo, passage.hi, passage.steps);
        let w = 0.5 * (a.line_load + b.line_load);
        let fill = |x: f64, y: f64| {
            if !x.is_finite() {
                y
            } else if !y.is_finite() {
                x
            } else {
                0.5 * (x + y)
            }
        };
        let node = &self.wf.nodes[k];
        if node.r < lo || node.r > hi {
            return;
        }
        let nc = &self.tca.node_contact[k];
        let (u1, u2) = self.rolling[k];
        let mut integral = 0.0;
        for m in 0..steps {
            integral += passage.pressure(node.r, (m as f64 + 0.5) / steps as f64);
        }
        integral *= duration / steps as f64;
        if integral <= 0.0 {
            return;
        }
        // The film of the line contact with the local line load (MODEL §6, §12 h), or, as a
        // refinement, with at least the Hertz load of the band's peak pressure
        // (w = 2 pi R p0^2 / E').
        let radius = fill(a.radius, b.radius);
        let peak = a.pressure.max(b.pressure);
        let film_line_load = match self.film_load {
            FilmLoad::LoadedAnalysis => w,
            FilmLoad::HertzPeakFloor => w.max(2.0 * PI * radius * peak * peak / self.e_prime),
        };
        let contact = LineContact {
            radius,
            u1,
            u2,
            line_load: film_line_load,
            pressure: peak,
        };
        let fl = lubrication::film(&self.gear.lubricant, self.e_prime, &contact);
        let kw = lubrication::wear_coefficient(self.k_dry, fl.lambda);
        o[0] += kw / self.hardness * nc.sliding_speed * integral;
        if o[1].is_nan() || fl.lambda < o[1] {
            o[1] = fl.lambda;
            o[2] = fl.h_min * fl.thermal_factor;
        }
        if w > o[3] {
            o[3] = w;
            o[5] = radius;
        }
        o[4] = o[4].max(a.half_width.max(b.half_width));
    }
}

/// Wear of one mesh cycle from the loaded analysis (MODEL §7.1-7.2), on the loaded flank.
///
/// Between two consecutive instants a, b of the reference tooth on a node column, the loaded
/// band is taken to translate from its centroid c_a to c_b while its shape blends from p_a to
/// p_b; the time integral of the pressure at every node follows by quadrature over the
/// interval (sub-steps of at most a tenth of the band width). The passage is thus resolved
/// whatever the number of positions (no aliasing), and the band follows the worn geometry
/// (the profiles are the loaded analysis on it). Depth = (k(lambda)/H) |vg| integral(p dt),
/// |vg| of the node at its contact moment, lambda from the interpolated line load (floored at
/// the Hertz load of the peak pressure with [`FilmLoad::HertzPeakFloor`]).
pub fn per_cycle(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    ltca: &Ltca,
    film_load: FilmLoad,
) -> CycleWear {
    let wf = geo.wheel_flank(tca.loaded_flank);
    let ni = wf.cells_height;
    let tau = 2.0 * PI / geo.teeth as f64;
    let np = tca.positions.len();
    let dt = tau / np as f64;
    // Wheel speed, rad/s: converts wheel rotation into time.
    let wheel_speed = gear.conditions.worm_speed / gear.ratio();
    let mut columns = crate::ltca::passage::band_samples(wf, tca, &ltca.positions, tau);
    let e_prime = lubrication::reduced_modulus(
        gear.worm_material.youngs_modulus,
        gear.worm_material.poisson_ratio,
        gear.wheel_material.youngs_modulus,
        gear.wheel_material.poisson_ratio,
    );
    // E* of the Hertz half-width: 1/E* = (1-v1^2)/E1 + (1-v2^2)/E2 = 2/E'.
    let e_star = 0.5 * e_prime;
    let k_dry = gear.wheel_material.wear_coefficient;
    let hardness = gear.wheel_material.hardness;
    let mut depth = FlankField::zeros(wf);
    let mut lambda = FlankField::zeros(wf);
    let mut film = FlankField::zeros(wf);
    let mut line_load = FlankField::zeros(wf);
    let mut half_width = FlankField::zeros(wf);
    let mut hertz_half_width = FlankField::zeros(wf);
    let mut contact_radius = FlankField::zeros(wf);
    lambda.values.fill(f64::NAN);
    film.values.fill(f64::NAN);
    let context = PassageWear {
        gear,
        wf,
        tca,
        rolling: rolling_velocities(wf, tca),
        dt,
        wheel_speed,
        e_prime,
        k_dry,
        hardness,
        film_load,
    };
    // Node columns are independent (each writes its own nodes): in parallel, then gathered.
    let per_column: Vec<Vec<[f64; 6]>> = columns
        .par_iter_mut()
        .enumerate()
        .map(|(j, samples)| context.column(j, samples))
        .collect();
    for (j, out) in per_column.iter().enumerate() {
        for (i, o) in out.iter().enumerate() {
            let k = j * (ni + 1) + i;
            depth.values[k] = o[0];
            lambda.values[k] = o[1];
            film.values[k] = o[2];
            line_load.values[k] = o[3];
            half_width.values[k] = o[4];
            contact_radius.values[k] = o[5];
            hertz_half_width.values[k] = crate::contact::hertz_half_width(o[3], o[5], e_star);
        }
    }
    CycleWear {
        depth,
        lambda,
        film,
        line_load,
        half_width,
        contact_radius,
        hertz_half_width,
    }
}

/// Lever |(P x n)_z| of node k of a flank (rotation invariant about the wheel axis), m.
fn node_lever(wf: &WheelFlank, k: usize) -> f64 {
    let n = &wf.nodes[k];
    GapEvaluator::lever(&n.position(), &n.normal_vec())
}

/// Backlash with the worm blocked (MODEL §7.6): at each position the wheel turns both ways
/// until a flank of any studied tooth touches the worm; the loaded flank's gaps grow with the
/// material worn off it.
#[derive(Debug, Clone)]
pub struct Backlash {
    /// Smallest angular gap of the unloaded opposite flank per position, rad.
    opposite: Vec<f64>,
    /// Loaded flank: angular gaps per (position, tooth, node) (TCA), rad.
    loaded: Vec<f64>,
    levers: Vec<f64>,
    teeth: usize,
    nodes: usize,
    /// Wheel reference radius r2 for the linear (tangential) value, m.
    pub reference_radius: f64,
}

/// Backlash over the positions.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BacklashStats {
    /// Angular backlash, rad: mean, min, max over positions.
    pub mean_rad: f64,
    pub min_rad: f64,
    pub max_rad: f64,
    /// Linear (tangential at r2) mean backlash, m.
    pub linear_mean_m: f64,
}

impl Backlash {
    /// Gaps of both flanks over the TCA's positions and teeth.
    pub fn new(gear: &GearSet, geo: &Geometry, tca: &Tca) -> Self {
        let other = match tca.loaded_flank {
            crate::geometry::Flank::Left => crate::geometry::Flank::Right,
            crate::geometry::Flank::Right => crate::geometry::Flank::Left,
        };
        let ev = GapEvaluator::for_flank(gear, geo, other);
        let wf = geo.wheel_flank(other);
        let tau = 2.0 * PI / geo.teeth as f64;
        let opposite: Vec<f64> = tca
            .positions
            .par_iter()
            .map(|pos| {
                let mut best = f64::INFINITY;
                for &k in &tca.teeth {
                    let offset = tca.sigma * k as f64 * tau;
                    for p in &wf.nodes {
                        best = best.min(ev.angular(
                            p.r,
                            p.theta + offset,
                            p.z,
                            pos.theta2,
                            pos.theta1,
                        ));
                    }
                }
                best
            })
            .collect();
        let lwf = geo.wheel_flank(tca.loaded_flank);
        Self {
            opposite,
            loaded: tca.node_gaps.clone(),
            levers: (0..lwf.nodes.len()).map(|k| node_lever(lwf, k)).collect(),
            teeth: tca.teeth.len(),
            nodes: lwf.nodes.len(),
            reference_radius: gear.wheel_reference_radius(),
        }
    }

    /// Backlash per position with `removal` (m, normal) worn off the loaded flank, rad.
    pub fn per_position(&self, removal: &FlankField) -> Vec<f64> {
        self.opposite
            .iter()
            .enumerate()
            .map(|(n, opp)| {
                let mut best = f64::INFINITY;
                for t in 0..self.teeth {
                    let base = (n * self.teeth + t) * self.nodes;
                    for k in 0..self.nodes {
                        let g = self.loaded[base + k] + removal.values[k] / self.levers[k];
                        best = best.min(g);
                    }
                }
                best + opp
            })
            .collect()
    }

    /// Mean, min, max over positions and the linear mean at r2.
    pub fn stats(&self, removal: &FlankField) -> BacklashStats {
        let v = self.per_position(removal);
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        BacklashStats {
            mean_rad: mean,
            min_rad: v.iter().copied().fold(f64::INFINITY, f64::min),
            max_rad: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            linear_mean_m: mean * self.reference_radius,
        }
    }
}

pub use crate::input::StepControl;

pub use crate::input::{LifeStop, Phase, Pitting, WearPlan};

/// The wear limits a life is checked against (MODEL §9 (a), (d)). The standard's limits are
/// on the mean flank loss in the normal section, which the backlash increase gives:
/// delta_Wn = Delta j_t cos(alpha_n) cos(gamma) (tangential backlash at r2, mean over
/// positions, MODEL §7.6). Besides, the local form of the pointed tip, reported per state:
/// the tooth left behind each node (the loaded flank receding past the opposite one at the
/// same r, z is a tooth worn through there).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WearLimits {
    /// Flank loss per unit of tangential backlash increase, cos(alpha_n) cos(gamma).
    pub flank_loss_per_backlash: f64,
    /// (a) tip not pointed: flank loss, m, and the backlash increase that gives it, m.
    pub pointed_tip_flank_loss_m: f64,
    pub pointed_tip_backlash_increase_m: f64,
    /// Backlash limit (the plan's, or the standard's (d) 0.3 m_x cos(gamma)): flank loss
    /// and backlash increase, m.
    pub backlash_flank_loss_m: f64,
    pub backlash_increase_limit_m: f64,
    /// Whether the backlash limit is the standard's (d) (false: the plan's own).
    pub backlash_limit_is_standard: bool,
    pub stop_at: LifeStop,
    /// Unworn thickness of the wheel tooth behind each node of the loaded flank, as the
    /// normal wear depth that reaches the opposite flank, m (infinite where the opposite
    /// flank does not cover the node's r, z).
    #[serde(skip)]
    pub node_thickness: Vec<f64>,
}

impl WearLimits {
    /// The limits of this gear and plan.
    pub fn new(gear: &GearSet, geo: &Geometry, tca: &Tca, plan: &WearPlan) -> Self {
        let rating = crate::rating::rate(gear);
        let per = gear.worm.normal_pressure_angle.cos() * rating.lead_angle_deg.to_radians().cos();
        let backlash = plan
            .backlash_limit
            .unwrap_or(rating.wear_limit_backlash_m / per);
        Self {
            flank_loss_per_backlash: per,
            pointed_tip_flank_loss_m: rating.wear_limit_pointed_tip_m,
            pointed_tip_backlash_increase_m: rating.wear_limit_pointed_tip_m / per,
            backlash_flank_loss_m: backlash * per,
            backlash_increase_limit_m: backlash,
            backlash_limit_is_standard: plan.backlash_limit.is_none(),
            stop_at: plan.stop_at,
            node_thickness: tooth_thickness(geo, tca.loaded_flank),
        }
    }

    /// Thinnest tooth left with `removal` worn off the loaded flank: the thickness, m
    /// (negative: worn through), and the node.
    pub fn thinnest(&self, removal: &FlankField) -> (f64, usize) {
        self.node_thickness
            .iter()
            .zip(&removal.values)
            .map(|(t, h)| t - h)
            .enumerate()
            .map(|(k, left)| (left, k))
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
    }

    /// Nodes of the loaded flank worn through (thickness left <= 0), as a share of the nodes
    /// with material behind them.
    pub fn worn_through_share(&self, removal: &FlankField) -> f64 {
        let (mut through, mut all) = (0usize, 0usize);
        for (t, h) in self.node_thickness.iter().zip(&removal.values) {
            if t.is_finite() {
                all += 1;
                through += usize::from(h >= t);
            }
        }
        through as f64 / all.max(1) as f64
    }

    /// A node of the loaded pattern (per cell, Pa) whose tooth is worn through by `removal`:
    /// contact computed on material that is gone (the model's flank there is the worn one,
    /// behind the opposite flank). Reported, not a stop: the standard's limits are on the
    /// mean flank loss, and a worn-away tip corner leaves the rest of the flank working.
    pub fn worn_through_loaded(
        &self,
        removal: &FlankField,
        pattern: &[f64],
        wf: &WheelFlank,
    ) -> Option<usize> {
        (0..wf.nodes.len()).find(|&k| {
            removal.values[k] >= self.node_thickness[k]
                && node_pattern_pressure(wf, pattern, k) > 0.0
        })
    }

    /// Why the life ends at this state (its record), if a limit it stops at is passed.
    pub fn passed(&self, record: &StepRecord) -> Option<String> {
        let end = format!("the life ends at {} cycles", cycles_label(record.cycles));
        let loss = record.backlash_increase_m * self.flank_loss_per_backlash;
        let at = |what: &str, limit: f64| {
            format!(
                "{what}: the flank loss {:.3} mm (backlash +{:.3} mm) has reached {:.3} mm; {end}",
                loss * 1e3,
                record.backlash_increase_m * 1e3,
                limit * 1e3,
            )
        };
        if loss >= self.pointed_tip_flank_loss_m {
            return Some(at(
                "the wheel tooth's tip is pointed (MODEL §9 (a))",
                self.pointed_tip_flank_loss_m,
            ));
        }
        let source = if self.backlash_limit_is_standard {
            "MODEL §9 (d)"
        } else {
            "wear.backlash_limit_um"
        };
        (self.stop_at == LifeStop::BacklashLimit && loss >= self.backlash_flank_loss_m).then(|| {
            at(
                &format!("backlash limit ({source})"),
                self.backlash_flank_loss_m,
            )
        })
    }

    /// Cycles at which the backlash increase first reaches `limit` (m), linear between the
    /// two states around it; None: not reached.
    pub fn cycles_reached(records: &[StepRecord], limit: f64) -> Option<f64> {
        let k = records
            .iter()
            .position(|r| r.backlash_increase_m >= limit)?;
        if k == 0 {
            return Some(records[0].cycles);
        }
        let (a, b) = (&records[k - 1], &records[k]);
        let t = (limit - a.backlash_increase_m) / (b.backlash_increase_m - a.backlash_increase_m);
        Some(a.cycles + t * (b.cycles - a.cycles))
    }
}

/// Unworn tooth thickness behind each node of `loaded`, as a normal depth, m: the angle
/// Delta theta through the material (against the outward normal) to the opposite flank at the
/// same r, z (modulo the pitch), times the node's lever |(P x n)_z| (a normal depth h moves
/// the flank by h / lever in theta at fixed r, z). Infinite where the opposite flank does not
/// cover r, z.
fn tooth_thickness(geo: &Geometry, loaded: crate::geometry::Flank) -> Vec<f64> {
    use crate::geometry::Flank;
    let wf = geo.wheel_flank(loaded);
    let other = geo.wheel_flank(match loaded {
        Flank::Left => Flank::Right,
        Flank::Right => Flank::Left,
    });
    let tau = 2.0 * PI / geo.teeth as f64;
    let (z_lo, z_hi) = (other.z[0], other.z[other.z.len() - 1]);
    (0..wf.nodes.len())
        .map(|k| {
            let n = &wf.nodes[k];
            let (r_lo, r_hi) = other.radial_range_at(n.z);
            if n.z < z_lo || n.z > z_hi || n.r < r_lo || n.r > r_hi {
                return f64::INFINITY;
            }
            // x = r cos(theta), y = -r sin(theta): d P / d theta = r (-sin, -cos, 0).
            let (sin, cos) = n.theta.sin_cos();
            let s = (-n.normal[0] * sin - n.normal[1] * cos).signum();
            let delta = (s * (n.theta - other.theta_at(n.r, n.z).0)).rem_euclid(tau);
            delta * node_lever(wf, k)
        })
        .collect()
}

/// A number of cycles for titles and messages: "180 000" below a million (thin groups of
/// three digits), "1.25 million" above.
pub fn cycles_label(cycles: f64) -> String {
    if !cycles.is_finite() {
        return format!("{cycles}");
    }
    if cycles.abs() >= 1e6 {
        let m = cycles / 1e6;
        let s = format!("{m:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return format!("{s} million");
    }
    let digits = format!("{}", cycles.round().abs() as u64);
    let mut out = String::new();
    for (k, ch) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(' ');
        }
        out.push(ch);
    }
    if cycles < 0.0 {
        out.insert(0, '-');
    }
    out
}

/// Backlash increase of the records at `cycles`, linear between records (m); None beyond them.
pub fn backlash_at(records: &[StepRecord], cycles: f64) -> Option<f64> {
    let k = records.iter().position(|r| r.cycles >= cycles)?;
    if k == 0 {
        return Some(records[0].backlash_increase_m);
    }
    let (a, b) = (&records[k - 1], &records[k]);
    let t = if b.cycles > a.cycles {
        (cycles - a.cycles) / (b.cycles - a.cycles)
    } else {
        1.0
    };
    Some(a.backlash_increase_m + t * (b.backlash_increase_m - a.backlash_increase_m))
}

/// State of a life run after a completed step: what a checkpoint holds.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WearState {
    /// Completed wear steps.
    pub step: usize,
    /// Wheel cycles run.
    pub cycles: f64,
    /// Depth worn off the loaded flank so far, normal to it, m.
    pub removal: FlankField,
    /// Plastic set of the loaded flank so far (running-in, MODEL §5.7): the permanent
    /// indentation where the contact reached the flow pressure, normal to the flank, m
    /// (empty: none yet).
    #[serde(default)]
    pub plastic_set: FlankField,
    /// Records of the states so far (the initial one and one per completed step).
    pub records: Vec<StepRecord>,
    /// Pitting phases (indices in the schedule) whose pits have been cut.
    #[serde(default)]
    pub pitted_phases: Vec<usize>,
    /// Pitted nodes of the loaded flank (empty: none).
    #[serde(default)]
    pub pitted: Vec<bool>,
    /// Band factor of the local contact meshes for this state's loaded analysis, reached by
    /// the widenings so far (None: the settings' own).
    #[serde(default)]
    pub band_factor: Option<f64>,
    /// Loads the solver of this state's loaded analysis starts from (the previous analysis';
    /// None: a cold start). Kept with the state so a resumed run repeats the analysis exactly.
    #[serde(default)]
    pub warm: Option<crate::ltca::WarmStart>,
    /// Why the life ended before its cycles: the wear limit passed ([`WearLimits::passed`]).
    #[serde(default)]
    pub stopped: Option<String>,
    /// Fatigue damage of every node of the loaded flank ([`forecast`]; empty: none yet).
    #[serde(default)]
    pub damage: Vec<f64>,
    /// The schedule a pitting forecast has found so far (empty without a forecast).
    #[serde(default)]
    pub found_phases: Vec<Phase>,
}

impl WearState {
    /// Unworn start.
    pub fn new(wf: &WheelFlank) -> Self {
        Self {
            step: 0,
            cycles: 0.0,
            removal: FlankField::zeros(wf),
            plastic_set: FlankField::zeros(wf),
            records: Vec::new(),
            pitted_phases: Vec::new(),
            pitted: Vec::new(),
            band_factor: None,
            warm: None,
            stopped: None,
            damage: vec![0.0; wf.nodes.len()],
            found_phases: Vec::new(),
        }
    }

    /// The loaded flank's change so far on the grid's nodes, normal to it, m: the wear and the
    /// plastic set (MODEL §7.5, §5.7), what the backlash sees.
    pub fn flank_change(&self) -> FlankField {
        let mut change = self.removal.clone();
        let set = self.plastic_set.with_rows(change.cells_height);
        for (h, s) in change.values.iter_mut().zip(&set.values) {
            *h += s;
        }
        change
    }

    /// The plastic set once the loaded analysis `l` of this state's flank has run in
    /// (MODEL §5.7): the set plus the analysis' plastic indentation, m, on the rows of the
    /// indentation (finer than the grid's, [`crate::ltca::Ltca::plastic_indentation`]).
    pub fn plastic_set_after(&self, l: &Ltca) -> FlankField {
        let add = &l.plastic_indentation;
        let mut set = self.plastic_set.with_rows(add.cells_height);
        if set.values.len() != add.values.len() {
            return add.clone();
        }
        for (s, d) in set.values.iter_mut().zip(&add.values) {
            *s += d;
        }
        set
    }

    /// [`Self::plastic_set_after`] on the grid's nodes, m.
    pub fn plastic_set_nodes_after(&self, l: &Ltca) -> FlankField {
        self.plastic_set_after(l)
            .with_rows(self.removal.cells_height)
    }

    /// Running-in (MODEL §5.7): the plastic indentation of a loaded analysis on this state's
    /// flank becomes part of its plastic set.
    pub fn run_in(&mut self, l: &Ltca) {
        self.plastic_set = self.plastic_set_after(l);
    }
}

/// The gear's state at some cycles: wear so far and the loaded analysis on that geometry
/// (units in the names; MODEL §7.7).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepRecord {
    /// Completed steps (0: the unworn gear).
    pub step: usize,
    pub cycles: f64,
    /// Cycles of the step that led here (0 for the start).
    pub step_cycles: f64,
    /// Sub-steps that step was split into by the stability guard (1: not split).
    pub substeps: usize,
    /// Phase of the schedule at these cycles: "wear" or "pitting".
    pub phase: String,
    /// Share of the active flank area pitted so far (pits cut at the starts of pitting
    /// phases).
    pub pitted_area_fraction: f64,
    /// Largest depth worn, m, and where on the flank (node radius and face position), m.
    pub max_wear_m: f64,
    #[serde(default)]
    pub max_wear_r_m: f64,
    #[serde(default)]
    pub max_wear_z_m: f64,
    /// Largest mean wear depth over a patch of the pressure patch's size (`[analysis]
    /// pressure_patch_*`, default 0.5 mm along the profile by 1 mm along the face), m: the
    /// peak wear that converges with the mesh (`max_wear_m`, one node, follows a band
    /// narrower than a grid row at the worm-tip trace; [`FlankField::patch_mean_max`]).
    #[serde(default)]
    pub wear_patch_max_m: f64,
    /// Worn volume / active flank area (mean depth over the flank), m.
    pub mean_wear_m: f64,
    /// Worn volume of one tooth flank, m^3.
    pub worn_volume_m3: f64,
    /// Tangential backlash at r2, mean over positions, m; and its increase since the start.
    pub backlash_m: f64,
    pub backlash_increase_m: f64,
    pub backlash_min_rad: f64,
    pub backlash_max_rad: f64,
    /// Largest pressure of the loaded pattern and the centre of its cell, m.
    pub max_pressure_pa: f64,
    #[serde(default)]
    pub max_pressure_r_m: f64,
    #[serde(default)]
    pub max_pressure_z_m: f64,
    pub mean_pressure_pa: f64,
    pub contact_area_fraction: f64,
    pub s1: f64,
    pub s2: f64,
    pub te_mean_rad: f64,
    pub te_p2p_rad: f64,
    pub mesh_stiffness_mean_nm_per_rad: f64,
    /// Wear per cycle on this geometry (the rate of the next step), largest, m.
    pub max_wear_per_cycle_m: f64,
    /// Film ratio range over the swept nodes.
    pub lambda_min: f64,
    pub lambda_max: f64,
    /// Largest mean pressure over a patch of stated size (`[analysis] pressure_patch_*`,
    /// default 0.5 mm across the line by 1 mm along the face), Pa: unlike the maximum
    /// (`max_pressure_pa`, one cell, grows with refinement at a sharp edge) it converges with
    /// the mesh.
    #[serde(default)]
    pub pressure_patch_max_pa: f64,
    /// Rigid lag that the wear adds, mean over positions: the growth of the loaded flank's
    /// smallest angular gap (the worn flank's kinematic lag, part of the backlash), rad
    /// (MODEL §12 j).
    #[serde(default)]
    pub rigid_lag_rad: f64,
    /// Loaded TE relative to the rigid lag (TE + lag at each position): mean and
    /// peak-to-peak, rad.
    #[serde(default)]
    pub te_mean_relative_rad: f64,
    #[serde(default)]
    pub te_p2p_relative_rad: f64,
    /// Rank's cycles to first pitting N_LI with the model's mean pressure of the loaded
    /// pattern in place of sigma_Hm (MODEL §12 k); None where the formula is out of range.
    #[serde(default)]
    pub n_li_model_cycles: Option<f64>,
    /// Loaded analyses run so far (this state's included): a step split by the stability
    /// guard costs one per sub-step (MODEL §7.3: the geometry is frozen within one).
    #[serde(default)]
    pub loaded_analyses: usize,
    /// Thinnest wheel tooth left anywhere on the flank (the normal wear depth that would go
    /// through it; negative: worn through), m ([`WearLimits::thinnest`]).
    #[serde(default)]
    pub thinnest_tooth_m: f64,
    /// Whether a node of this state's loaded pattern is worn through
    /// ([`WearLimits::worn_through_loaded`]).
    #[serde(default)]
    pub worn_through_loaded: bool,
    /// Frictionless power balance of this state's loaded analysis (`Ltca::power_balance`).
    #[serde(default)]
    pub power_balance: f64,
    /// Largest fatigue damage of the loaded flank's nodes (1: a node's life on the
    /// pressure-life curve is spent; [`forecast`]).
    #[serde(default)]
    pub max_damage: f64,
    /// Largest plastic set of the flank once this state's analysis has run in (MODEL §5.7),
    /// m, and the largest indentation this state's analysis added, m.
    #[serde(default)]
    pub max_plastic_set_m: f64,
    #[serde(default)]
    pub max_plastic_indentation_m: f64,
    /// Share of the active flank area where this state's contact reached the flow pressure.
    #[serde(default)]
    pub yielded_area_fraction: f64,
    /// Largest equivalent pressure below the flank over the pattern (MODEL §8.1), Pa (0 in
    /// records of earlier versions).
    #[serde(default)]
    pub equivalent_pressure_max_pa: f64,
    /// Per position: TE, TE relative to the rigid lag, load per tooth (not in summary.json;
    /// `wear_positions.csv`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub positions: Vec<PositionState>,
}

/// One position of a state's loaded analysis (MODEL §7.7: load sharing and TE over life).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PositionState {
    /// Loaded transmission error, rad (negative = lag).
    pub te_rad: f64,
    /// TE + the rigid lag of the wear at this position, rad.
    pub te_relative_rad: f64,
    /// Normal force per studied tooth (TCA tooth order), N.
    pub tooth_load_n: Vec<f64>,
    pub max_pressure_pa: f64,
}

/// Why a life run stopped.
#[derive(Debug, thiserror::Error)]
pub enum WearError {
    // The cause is the source (not repeated here: `{:#}` prints the chain once).
    #[error("at {cycles} cycles (step {step})")]
    Ltca {
        step: usize,
        cycles: f64,
        #[source]
        source: crate::ltca::LtcaError,
    },
    #[error("the checkpoint does not match this gear's flank grid ({0})")]
    Checkpoint(String),
    /// A plan that could not end in a practical number of loaded analyses.
    #[error("{0}")]
    Plan(String),
    #[error("{0}")]
    Output(String),
}

/// What the life loop hands out after each completed state: the state (to checkpoint), the
/// loaded analysis and the per-cycle wear on that geometry.
pub struct StepView<'a> {
    pub state: &'a WearState,
    pub ltca: &'a Ltca,
    pub cycle: &'a CycleWear,
    /// The last state of the run (the life is reached).
    pub last: bool,
    /// A state whose maps are written (`map_cycles`, or 0, 1, 2, 4, ... by default).
    pub map: bool,
}

/// Runs the life (MODEL §7.3-7.7, §8) from `state` (unworn, or a checkpoint): at each state
/// the loaded analysis on the worn geometry, the wear of one cycle, a record; then, in a wear
/// phase, a step of C_k cycles (fixed, or removing at most the given depth; never across a
/// phase end or a map cycle) with the geometry frozen; at the start of a pitting phase the
/// pits are cut (every node whose loaded-pattern pressure exceeds the phase's limit loses
/// 0.78 a, a the local Hertz half-width there, MODEL §12 g), then the phase passes without
/// wear. Until the life is reached, or a wear limit is ([`WearLimits`]: the pointed tip, or the
/// backlash limit if the plan stops there; the state's `stopped` says which). `on_state` is
/// called after every record (checkpoint, files); an error from it stops the run.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    settings: &crate::ltca::LtcaSettings,
    bending: Option<&dyn crate::ltca::BendingModel>,
    life: &WearPlan,
    mut state: WearState,
    on_state: &mut dyn FnMut(&StepView) -> Result<(), WearError>,
) -> Result<WearState, WearError> {
    let wf = geo.wheel_flank(tca.loaded_flank);
    if state.removal.values.len() != wf.nodes.len() || state.removal.cells_height != wf.cells_height
    {
        return Err(WearError::Checkpoint(format!(
            "{} x {} cells, the gear has {} x {}",
            state.removal.cells_height, state.removal.cells_face, wf.cells_height, wf.cells_face
        )));
    }
    if state.pitted.len() != wf.nodes.len() {
        state.pitted = vec![false; wf.nodes.len()];
    }
    if state.damage.len() != wf.nodes.len() {
        state.damage = vec![0.0; wf.nodes.len()];
    }
    if !state.plastic_set.fits(wf) {
        state.plastic_set = FlankField::zeros(wf);
    }
    check_plan_can_end(gear, life)?;
    let life_loop = LifeLoop::new(gear, geo, tca, settings, bending, life);
    let mut step_cycles = state.records.last().map_or(0.0, |r| r.step_cycles);
    let mut substeps = state.records.last().map_or(0, |r| r.substeps);
    let mut stalled = 0;
    loop {
        let (l, band) = life_loop.analyse(&state)?;
        let cw = per_cycle(gear, geo, tca, &l, life.film_load);
        let loads = forecast::NodeLoads::new(
            wf,
            &l,
            &cw,
            &life.endurance,
            life.pit_depth,
            life.pitting_stress,
        );
        life_loop.start_forecast_phase(&mut state, &loads);
        let phase = life_loop.phase_at(&state, state.cycles);
        let record = life_loop.record(&state, &l, &cw, phase, step_cycles, substeps);
        // A resumed run recomputes the state it stopped at: keep one record per step.
        state.records.retain(|r| r.step < state.step);
        state.stopped = life_loop.limits.passed(&record);
        state.records.push(record);
        let left = life.life_cycles - state.cycles;
        let last = left <= 1e-9 * life.life_cycles.max(1.0) || state.stopped.is_some();
        on_state(&StepView {
            state: &state,
            ltca: &l,
            cycle: &cw,
            last,
            map: life_loop.is_map_state(&state),
        })?;
        if last {
            break;
        }
        // What the next analysis starts from (after the checkpoint, which keeps what this
        // state's analysis used).
        state.band_factor = band;
        state.warm = Some(l.warm_start());
        state.run_in(&l);
        let before = state.cycles;
        (step_cycles, substeps) = life_loop.step(&mut state, &l, cw, &loads, phase, left)?;
        state.step += 1;
        stalled = stalled_steps(stalled, before, &state)?;
    }
    Ok(state)
}

/// The count of consecutive steps that left the cycles where they were, with the one that
/// brought `state` from `before` cycles: a life that stops advancing would run for ever, a
/// defect reported as such after [`MAX_STALLED_STEPS`].
fn stalled_steps(stalled: usize, before: f64, state: &WearState) -> Result<usize, WearError> {
    let stalled = if state.cycles > before {
        0
    } else {
        stalled + 1
    };
    if stalled >= MAX_STALLED_STEPS {
        return Err(WearError::Plan(format!(
            "the life did not advance beyond {} cycles in {MAX_STALLED_STEPS} steps (step {}): \
             stopped rather than run for ever; please report it with the gear file",
            state.cycles, state.step
        )));
    }
    Ok(stalled)
}

/// Consecutive steps that may leave the cycles where they were (a pitting phase's cut pits
/// take none) before a life is stopped as stalled.
const MAX_STALLED_STEPS: usize = 50;

/// Most loaded analyses a life plan may need (a case B life needs ~2 700).
pub const MAX_ANALYSES: f64 = 200_000.0;

/// Refuses a plan whose step count has no practical bound: fixed steps of `life / step`
/// states, or adaptive steps and sub-steps so small that wearing down to the standard's
/// pointed-tip limit (MODEL §9 (a)), which no life passes, would take more than
/// [`MAX_ANALYSES`] loaded analyses.
pub fn check_plan_can_end(gear: &GearSet, life: &WearPlan) -> Result<(), WearError> {
    let limit = crate::rating::rate(gear).wear_limit_pointed_tip_m;
    let (what, count) = match life.step {
        StepControl::Cycles(c) => (
            format!(
                "fixed steps of {c:e} cycles over {:e} cycles",
                life.life_cycles
            ),
            life.life_cycles / c,
        ),
        StepControl::MaxRemoval(d) => (
            format!(
                "adaptive steps of {:e} um up to the pointed-tip wear limit of {:.3} mm",
                d * 1e6,
                limit * 1e3
            ),
            limit / d,
        ),
    };
    let guard = life.max_substep_removal;
    let (what, count) = if guard > 0.0 && limit / guard > count {
        (
            format!(
                "sub-steps of at most {:e} um (max_substep_wear_um) up to the pointed-tip wear \
                 limit of {:.3} mm",
                guard * 1e6,
                limit * 1e3
            ),
            limit / guard,
        )
    } else {
        (what, count)
    };
    if count > MAX_ANALYSES {
        return Err(WearError::Plan(format!(
            "up to {count:.3e} loaded analyses could be needed ({what}), more than \
             {MAX_ANALYSES:e}: use larger steps or a shorter life"
        )));
    }
    Ok(())
}

/// What the life loop of [`simulate`] works with, and its named steps.
struct LifeLoop<'a> {
    gear: &'a GearSet,
    geo: &'a Geometry,
    tca: &'a Tca,
    settings: &'a crate::ltca::LtcaSettings,
    bending: Option<&'a dyn crate::ltca::BendingModel>,
    life: &'a WearPlan,
    wf: &'a WheelFlank,
    backlash: Backlash,
    /// Backlash per position of the unworn flank, rad.
    initial_backlash: Vec<f64>,
    active_area: f64,
    /// Sliding speed at the reference diameter (the standard's v_gm) and sigma_Hlim, for
    /// Rank's N_LI from the model's mean pressure.
    sliding_speed: f64,
    pitting_limit: f64,
    limits: WearLimits,
}

impl<'a> LifeLoop<'a> {
    fn new(
        gear: &'a GearSet,
        geo: &'a Geometry,
        tca: &'a Tca,
        settings: &'a crate::ltca::LtcaSettings,
        bending: Option<&'a dyn crate::ltca::BendingModel>,
        life: &'a WearPlan,
    ) -> Self {
        let wf = geo.wheel_flank(tca.loaded_flank);
        let backlash = Backlash::new(gear, geo, tca);
        let initial_backlash = backlash.per_position(&FlankField::zeros(wf));
        Self {
            gear,
            geo,
            tca,
            settings,
            bending,
            life,
            wf,
            backlash,
            initial_backlash,
            active_area: wf.active_area(),
            sliding_speed: crate::rating::rate(gear).sliding_speed_m_s,
            pitting_limit: gear.wheel_material.pitting_limit,
            limits: WearLimits::new(gear, geo, tca, life),
        }
    }

    /// The schedule of this life: the plan's, or the one its forecast has found so far.
    fn schedule<'s>(&'s self, state: &'s WearState) -> &'s [Phase] {
        match self.life.pitting {
            Pitting::Forecast => &state.found_phases,
            _ => &self.life.phases,
        }
    }

    /// Whether the pits come from the damage (`wear::forecast`).
    fn pits_from_damage(&self) -> bool {
        matches!(self.life.pitting, Pitting::Damage | Pitting::Forecast)
    }

    /// A forecast starts a pitting phase at a state of a wear phase (after its first state)
    /// where loaded nodes whose damage has reached 1 make up the onset share of the flank
    /// (default 2 %; 0: the first such node; `wear::forecast`). The phase lasts the life on
    /// the pressure–life curve of its least loaded pit.
    fn start_forecast_phase(&self, state: &mut WearState, loads: &forecast::NodeLoads) {
        if self.life.pitting != Pitting::Forecast {
            return;
        }
        let cycles = state.cycles;
        if let Some((_, Phase::Pitting { .. }, _)) = self.phase_at(state, cycles) {
            return;
        }
        let wear_start = state.found_phases.last().map_or(0.0, phase_end);
        let Some(pressure) = loads.median_due_pressure(&state.damage) else {
            return;
        };
        let onset = self.life.pitting_onset_share;
        if cycles > wear_start && loads.due_share(&state.damage) >= onset {
            state.found_phases.push(Phase::Wear { until: cycles });
            state.found_phases.push(Phase::Pitting {
                until: cycles + self.life.endurance.life(pressure),
                pressure_limit: None,
                margin: 0.0,
            });
        }
    }

    /// The step from a state (`left`: cycles to the life's end): in a pitting phase, its pits
    /// or its passing without wear ([`Self::pitting_step`]); in a wear phase, a wear step,
    /// which with pits from the damage ends where the nodes due make up the onset share. The damage advances
    /// over a wear step and holds in a pitting phase (`wear::forecast`). Returns the step's cycles
    /// and sub-steps.
    fn step(
        &self,
        state: &mut WearState,
        l: &Ltca,
        cw: CycleWear,
        loads: &forecast::NodeLoads,
        phase: Option<(usize, Phase, f64)>,
        left: f64,
    ) -> Result<(f64, usize), WearError> {
        let end = match phase {
            Some((k, Phase::Pitting { .. }, end)) => {
                let advanced = self.pitting_step(state, l, &cw, loads, k, end);
                return Ok((advanced, 1));
            }
            Some((_, Phase::Wear { .. }, end)) => end,
            None => self.life.life_cycles,
        };
        let mut left = left
            .min(end - state.cycles)
            .min(self.next_map_cycles(state.cycles) - state.cycles);
        if self.pits_from_damage() {
            // Steps end where the nodes due to pit make up the onset share: a forecast starts
            // its phases there, and a schedule with pits from the damage resolves the same
            // states (the phases a forecast found repeat it).
            let onset = self.life.pitting_onset_share;
            if let Some(n) = loads.cycles_to_onset(&state.damage, onset) {
                left = left.min(n);
            }
        }
        let rate = cw.depth.max();
        let step_cycles = match self.life.step {
            StepControl::Cycles(c) => c.min(left),
            StepControl::MaxRemoval(d) if rate > 0.0 => (d / rate).min(left),
            StepControl::MaxRemoval(_) => left,
        };
        let target = state.cycles + step_cycles;
        let substeps = self.wear_step(state, cw, step_cycles)?;
        // The sub-steps' sum lands on the step's end, and a step to a phase's end on that
        // end, exactly: a schedule's phases then start at the cycles they were found at.
        state.cycles = if (end - target).abs() <= 1e-9 * end {
            end
        } else {
            target
        };
        loads.advance(&mut state.damage, step_cycles, true);
        Ok((step_cycles, substeps))
    }

    /// Phase at some cycles: (index, phase, end); None after the schedule (wear).
    fn phase_at(&self, state: &WearState, cycles: f64) -> Option<(usize, Phase, f64)> {
        let mut start = 0.0;
        for (k, p) in self.schedule(state).iter().enumerate() {
            let end = phase_end(p);
            if cycles < end * (1.0 - 1e-12) && cycles >= start * (1.0 - 1e-12) {
                return Some((k, *p, end));
            }
            start = end;
        }
        None
    }

    /// The first map cycle beyond `cycles` (infinite: none).
    fn next_map_cycles(&self, cycles: f64) -> f64 {
        self.life
            .map_cycles
            .iter()
            .flatten()
            .copied()
            .find(|&c| c > cycles * (1.0 + 1e-12) + 1e-9)
            .unwrap_or(f64::INFINITY)
    }

    /// Whether the maps of this state are written: at the map cycles, or by default at the
    /// states 0, 1, 2, 4, 8, ...
    fn is_map_state(&self, state: &WearState) -> bool {
        match &self.life.map_cycles {
            None => state.step == 0 || state.step.is_power_of_two(),
            Some(list) => list
                .iter()
                .any(|&c| (c - state.cycles).abs() <= 1e-9 * c.max(1.0)),
        }
    }

    /// Loaded analysis on the worn geometry. The worn contact widens: the band of the local
    /// meshes starts as wide as the last analysis needed (no repeated widenings), carried in
    /// the state for an exact resume. An unworn flank is analysed as the LTCA stage does.
    fn analyse(&self, state: &WearState) -> Result<(Ltca, Option<f64>), WearError> {
        let mut local = *self.settings;
        local.band_factor = state.band_factor.unwrap_or(self.settings.band_factor);
        let changed = |f: &FlankField| f.values.iter().any(|&h| h != 0.0);
        let change = crate::ltca::FlankChange {
            removal: Some(&state.removal).filter(|f| changed(f)),
            plastic_set: Some(&state.plastic_set).filter(|f| changed(f)),
        };
        let l = crate::ltca::analyse_changed(
            self.gear,
            self.geo,
            self.tca,
            &local,
            self.bending,
            change,
            state.warm.as_ref(),
        )
        .map_err(|source| WearError::Ltca {
            step: state.step,
            cycles: state.cycles,
            source,
        })?;
        let widenings = l
            .positions
            .iter()
            .map(|p| p.band_widenings)
            .max()
            .unwrap_or(0);
        let band = (widenings > 0)
            .then(|| (local.band_factor * 1.6f64.powi(widenings as i32)).min(50.0))
            .or(state.band_factor);
        Ok((l, band))
    }

    /// The rigid lag the flank change `change` adds at each position (rad, MODEL §12 j) and
    /// each position's TE, TE relative to that lag, tooth loads and largest pressure.
    fn position_states(&self, l: &Ltca, change: &FlankField) -> (Vec<f64>, Vec<PositionState>) {
        let per_position = self.backlash.per_position(change);
        let lag: Vec<f64> = per_position
            .iter()
            .zip(&self.initial_backlash)
            .map(|(b, b0)| b - b0)
            .collect();
        let positions: Vec<PositionState> = l
            .positions
            .iter()
            .map(|p| PositionState {
                te_rad: p.transmission_error,
                te_relative_rad: p.transmission_error + lag[p.position],
                tooth_load_n: p.tooth_load.clone(),
                max_pressure_pa: p.max_pressure,
            })
            .collect();
        (lag, positions)
    }

    /// The record of a state (MODEL §7.7, §12 j, §12 k).
    fn record(
        &self,
        state: &WearState,
        l: &Ltca,
        cw: &CycleWear,
        phase: Option<(usize, Phase, f64)>,
        step_cycles: f64,
        substeps: usize,
    ) -> StepRecord {
        let wf = self.wf;
        let change = state.flank_change();
        let (lag, positions) = self.position_states(l, &change);
        let b = self.backlash.stats(&change);
        let initial = self.initial_backlash.iter().sum::<f64>()
            / self.initial_backlash.len().max(1) as f64
            * self.backlash.reference_radius;
        let (te_mean, te_p2p) = l.te_stats();
        let (te_rel_mean, te_rel_p2p) = stats(positions.iter().map(|p| p.te_relative_rad));
        let lambdas = cw.lambda.values.iter().copied().filter(|v| v.is_finite());
        let volume = state.removal.integral(wf);
        let worst_node = argmax(&state.removal.values).map(|k| &wf.nodes[k]);
        let worst_cell = argmax(&l.pattern).map(|k| &wf.cells[k]);
        let previous = state
            .records
            .iter()
            .rev()
            .find(|r| r.step < state.step)
            .map_or(0, |r| r.loaded_analyses);
        StepRecord {
            step: state.step,
            cycles: state.cycles,
            step_cycles,
            substeps,
            phase: match phase {
                Some((_, Phase::Pitting { .. }, _)) => "pitting".into(),
                _ => "wear".into(),
            },
            pitted_area_fraction: pitted_fraction(wf, &state.pitted),
            max_wear_m: state.removal.max(),
            max_wear_r_m: worst_node.map_or(f64::NAN, |n| n.r),
            max_wear_z_m: worst_node.map_or(f64::NAN, |n| n.z),
            wear_patch_max_m: state.removal.patch_mean_max(
                wf,
                self.settings.patch_across,
                self.settings.patch_along,
            ),
            mean_wear_m: volume / self.active_area,
            worn_volume_m3: volume,
            backlash_m: b.linear_mean_m,
            backlash_increase_m: b.linear_mean_m - initial,
            backlash_min_rad: b.min_rad,
            backlash_max_rad: b.max_rad,
            max_pressure_pa: l.max_pressure,
            max_pressure_r_m: worst_cell.map_or(f64::NAN, |c| c.r),
            max_pressure_z_m: worst_cell.map_or(f64::NAN, |c| c.z),
            mean_pressure_pa: l.mean_pressure,
            contact_area_fraction: l.s0,
            s1: l.s1,
            s2: l.s2,
            te_mean_rad: te_mean,
            te_p2p_rad: te_p2p,
            mesh_stiffness_mean_nm_per_rad: l.stiffness_mean(),
            max_wear_per_cycle_m: cw.depth.max(),
            lambda_min: lambdas.clone().fold(f64::INFINITY, f64::min),
            lambda_max: lambdas.fold(0.0, f64::max),
            pressure_patch_max_pa: l.pressure_patch_max,
            rigid_lag_rad: lag.iter().sum::<f64>() / lag.len().max(1) as f64,
            te_mean_relative_rad: te_rel_mean,
            te_p2p_relative_rad: te_rel_p2p,
            n_li_model_cycles: crate::rating::rank_first_pitting_cycles(
                self.sliding_speed,
                l.mean_pressure * 1e-6,
                self.pitting_limit * 1e-6,
            ),
            loaded_analyses: previous + substeps.max(1),
            thinnest_tooth_m: self.limits.thinnest(&state.removal).0,
            worn_through_loaded: self
                .limits
                .worn_through_loaded(&state.removal, &l.pattern, wf)
                .is_some(),
            power_balance: l.power_balance,
            max_damage: state.damage.iter().copied().fold(0.0, f64::max),
            max_plastic_set_m: state.plastic_set_after(l).max(),
            max_plastic_indentation_m: l.plastic_indentation.max(),
            yielded_area_fraction: l.yielded_area_fraction,
            equivalent_pressure_max_pa: l.equivalent_pattern.iter().copied().fold(0.0, f64::max),
            positions,
        }
    }

    /// A state in pitting phase k (ending at `end`): at its start the pits are cut (same
    /// cycles; the next record shows the new pressures): above the phase's limit (published
    /// coupling) or where the damage has reached 1 ([`forecast`]; the cut nodes start
    /// again undamaged). Then the phase passes without wear up to its end (or the life's, if
    /// first). Returns the cycles advanced.
    fn pitting_step(
        &self,
        state: &mut WearState,
        l: &Ltca,
        cw: &CycleWear,
        loads: &forecast::NodeLoads,
        k: usize,
        end: f64,
    ) -> f64 {
        let Phase::Pitting {
            pressure_limit,
            margin,
            ..
        } = self.schedule(state)[k]
        else {
            return 0.0;
        };
        if !state.pitted_phases.contains(&k) && self.pits_from_damage() {
            loads.cut_due(&mut state.damage, &mut state.removal, &mut state.pitted);
            state.pitted_phases.push(k);
            return 0.0;
        }
        if !state.pitted_phases.contains(&k) {
            let duration = end - state.cycles;
            let limit = pressure_limit
                .unwrap_or_else(|| self.life.endurance.pressure(duration) * (1.0 + margin));
            let depth = pit_depths(cw, self.life.pit_depth);
            for k in cut_pits(
                self.wf,
                &l.pattern,
                limit,
                &depth,
                &mut state.removal,
                &mut state.pitted,
            ) {
                state.damage[k] = 0.0;
            }
            state.pitted_phases.push(k);
            return 0.0;
        }
        let end = end.min(self.life.life_cycles);
        let advanced = end - state.cycles;
        state.cycles = end;
        advanced
    }

    /// Advances the state by `step_cycles` of wear at the rates of `rate_map`, in equal
    /// sub-steps with the pressures recomputed when the stability guard asks for them
    /// (MODEL §7.3). Returns the number of sub-steps.
    fn wear_step(
        &self,
        state: &mut WearState,
        mut rate_map: CycleWear,
        step_cycles: f64,
    ) -> Result<usize, WearError> {
        let mut remaining = step_cycles;
        let mut substeps = 0;
        loop {
            let rate = rate_map.depth.max();
            let cap = self.life.max_substep_removal;
            let dc = if cap > 0.0 && rate * remaining > cap * (1.0 + 1e-9) {
                // Equal sub-steps over what is left of the step.
                let n = (rate * remaining / cap).ceil();
                remaining / n
            } else {
                remaining
            };
            for (h, dh) in state.removal.values.iter_mut().zip(&rate_map.depth.values) {
                *h += dc * dh;
            }
            state.cycles += dc;
            remaining -= dc;
            substeps += 1;
            if remaining <= 1e-9 * step_cycles {
                return Ok(substeps);
            }
            let (l, band) = self.analyse(state)?;
            state.band_factor = band;
            state.warm = Some(l.warm_start());
            state.run_in(&l);
            rate_map = per_cycle(self.gear, self.geo, self.tca, &l, self.life.film_load);
        }
    }
}

/// The cycles a phase lasts until.
fn phase_end(p: &Phase) -> f64 {
    match *p {
        Phase::Wear { until } | Phase::Pitting { until, .. } => until,
    }
}

/// Index of the largest value (None when empty or all NaN).
fn argmax(values: &[f64]) -> Option<usize> {
    values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, _)| k)
}

impl WearState {
    /// What an engineer must see about this life at its last state (summary.json, stderr, the
    /// top of report.html): why it stopped early, loaded analyses off the power balance,
    /// contact on worn-through teeth, flank nodes whose fatigue damage has reached 1 (MODEL
    /// §8.1), and pressures at the flow pressure (MODEL §5.7).
    pub fn warnings(&self, wf: &WheelFlank) -> Vec<String> {
        let mut w = Vec::new();
        if let Some(why) = &self.stopped {
            w.push(format!("wear limit: {why}"));
        }
        let balance = self
            .records
            .iter()
            .find(|r| r.power_balance.abs() > crate::ltca::POWER_BALANCE_LIMIT);
        if let Some(r) = balance {
            w.push(format!(
                "wear: from {} cycles the loaded analyses depart from the frictionless power \
                 balance by {:+.1} % (more than {} %): the load sits at non-conjugate points (the \
                 wheel's face edge under a misalignment) and the model's torques, TE and wear \
                 there are unreliable (power_balance in wear_steps.csv)",
                cycles_label(r.cycles),
                100.0 * r.power_balance,
                100.0 * crate::ltca::POWER_BALANCE_LIMIT
            ));
        }
        if let Some(r) = self.records.iter().find(|r| r.worn_through_loaded) {
            w.push(format!(
                "wear: from {} cycles the loaded pattern reaches flank nodes whose tooth is worn \
                 through (contact computed on material that is gone; see wear.limits)",
                cycles_label(r.cycles)
            ));
        }
        w.extend(self.damage_warning(wf));
        if let Some(r) = self
            .records
            .last()
            .filter(|r| r.yielded_area_fraction > 0.0)
        {
            w.push(format!(
                "contact: at {} cycles {:.2} % of the active flank reaches the flow pressure (MODEL \
                 §5.7): \
                 the pressures there are the bronze's plastic limit, and the flank takes a \
                 plastic set",
                cycles_label(r.cycles),
                100.0 * r.yielded_area_fraction
            ));
        }
        w
    }

    /// Flank nodes whose fatigue damage has reached 1 at the last state (MODEL §8.1): how
    /// many, their share of the active flank, the largest damage.
    fn damage_warning(&self, wf: &WheelFlank) -> Option<String> {
        let due: Vec<usize> = (0..self.damage.len())
            .filter(|&k| self.damage[k] >= forecast::REACHED)
            .collect();
        if due.is_empty() || self.damage.len() != wf.nodes.len() {
            return None;
        }
        let mut pitted = vec![false; wf.nodes.len()];
        for &k in &due {
            pitted[k] = true;
        }
        let largest = due.iter().map(|&k| self.damage[k]).fold(0.0, f64::max);
        Some(format!(
            "pitting: {} flank nodes (about {:.2} % of the active flank) have reached a fatigue \
             damage of 1 at {} cycles (largest {:.3}): the model expects pits there (damage map; MODEL \
             §8.1)",
            due.len(),
            100.0 * pitted_fraction(wf, &pitted),
            cycles_label(self.cycles),
            largest
        ))
    }
}

/// Depth of the pits at every node (MODEL §8, §12 g): 0.78 a, a the local Hertz half-width
/// (published) or the loaded band's half-width (refinement), m.
pub fn pit_depths(cw: &CycleWear, rule: PitDepth) -> FlankField {
    let half_width = match rule {
        PitDepth::Hertz => &cw.hertz_half_width,
        PitDepth::LoadedBand => &cw.half_width,
    };
    FlankField {
        values: half_width.values.iter().map(|a| 0.78 * a).collect(),
        ..half_width.clone()
    }
}

/// Share of the active flank area around pitted nodes (cells with a pitted corner).
fn pitted_fraction(wf: &WheelFlank, pitted: &[bool]) -> f64 {
    let ni = wf.cells_height;
    let mut area = 0.0;
    for j in 0..wf.cells_face {
        for i in 0..ni {
            let corners = [
                j * (ni + 1) + i,
                j * (ni + 1) + i + 1,
                (j + 1) * (ni + 1) + i,
                (j + 1) * (ni + 1) + i + 1,
            ];
            if corners.iter().any(|&k| pitted[k]) {
                area += wf.cell_area[j * ni + i];
            }
        }
    }
    area / wf.active_area()
}

/// Cuts the pits of a pitting phase (MODEL §8): every node whose loaded-pattern pressure (the
/// largest of its cells) exceeds `limit` (Pa) and that the contact passes (depth > 0) loses
/// `depth` more (m; [`pit_depths`]: 0.78 a, the depth of the largest shear stress under a
/// line contact). Returns the nodes cut.
pub fn cut_pits(
    wf: &WheelFlank,
    pattern: &[f64],
    limit: f64,
    depth: &FlankField,
    removal: &mut FlankField,
    pitted: &mut [bool],
) -> Vec<usize> {
    let mut cut = Vec::new();
    for (k, pit) in pitted.iter_mut().enumerate() {
        if node_pattern_pressure(wf, pattern, k) > limit && depth.values[k] > 0.0 {
            removal.values[k] += depth.values[k];
            *pit = true;
            cut.push(k);
        }
    }
    cut
}

/// The (up to four) cells of the flank grid around node k, as indices of a cell pattern.
fn node_cells(wf: &WheelFlank, k: usize) -> impl Iterator<Item = usize> {
    let (ni, nj) = (wf.cells_height, wf.cells_face);
    let (i, j) = (k % (ni + 1), k / (ni + 1));
    [
        (i, j),
        (i.wrapping_sub(1), j),
        (i, j.wrapping_sub(1)),
        (i.wrapping_sub(1), j.wrapping_sub(1)),
    ]
    .into_iter()
    .filter(move |&(ci, cj)| ci < ni && cj < nj)
    .map(move |(ci, cj)| cj * ni + ci)
}

/// Loaded-pattern pressure at node k of the flank grid: the largest of the (up to four)
/// cells around it, Pa.
fn node_pattern_pressure(wf: &WheelFlank, pattern: &[f64], k: usize) -> f64 {
    node_cells(wf, k).map(|c| pattern[c]).fold(0.0, f64::max)
}
