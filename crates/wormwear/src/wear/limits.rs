//! The wear limits a life is checked against (MODEL §9 (a), (d)): the mean flank loss from the
//! backlash increase, and the tooth left behind each node (a pointed tip).

use super::{
    cycles_label, node_lever, node_pattern_pressure, LifeStop, StepControl, StepRecord, WearError,
    WearPlan,
};
use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::GearSet;
use crate::kinematics::Tca;
use std::f64::consts::PI;

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
        let (backlash, per) = Self::backlash_limit(gear, &rating, plan);
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

    /// The backlash increase limit (the plan's, or the standard's (d) as a tangential
    /// backlash), m, and the flank loss per unit of backlash increase, cos(alpha_n) cos(gamma).
    pub fn backlash_limit(
        gear: &GearSet,
        rating: &crate::rating::Rating,
        plan: &WearPlan,
    ) -> (f64, f64) {
        let per = gear.worm.normal_pressure_angle.cos() * rating.lead_angle_deg.to_radians().cos();
        let backlash = plan
            .backlash_limit
            .unwrap_or(rating.wear_limit_backlash_m / per);
        (backlash, per)
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
