//! Back-driving and self-locking (MODEL §15): the wheel driving the worm. The same contact —
//! the loaded flank under the same normal forces — with the power flow reversed, i.e. both
//! rotations reversed and so the sliding: the normal forces' power changes sign, the friction's
//! does not (force and velocity both reverse). With W the normal forces' moment about the wheel
//! axis and M1, M2 the friction's moments about the worm and wheel axes (sum mu f t.V1 / omega1
//! and sum mu f t.V2 / omega2, t = -v_g / |v_g| the friction's direction on the wheel, MODEL
//! §5.2), u the ratio:
//!
//!   driving       eta  = (W + M2) / (W + u M1)
//!   back-driving  eta' = (W - u M1) / (W - M2)
//!
//! summed over the positions (powers at one speed). Self-locking when eta' <= 0. SI units.

use crate::geometry::Geometry;
use crate::input::GearSet;
use crate::ltca::{cell_sliding, Ltca};

/// The unit-friction moments of one position: W, and per loaded cell its normal force f (N)
/// with the moments of a unit friction force (worm arm t.V1 / omega1, wheel arm t.V2 / omega2,
/// m).
struct PositionArms {
    normal_wheel_torque: f64,
    cells: Vec<(usize, f64, f64, f64)>,
}

/// The loaded analysis' positions with their cells' friction arms, ready for any friction
/// field (MODEL §15).
pub struct FrictionArms {
    ratio: f64,
    positions: Vec<PositionArms>,
}

impl FrictionArms {
    /// The arms of every loaded cell of `ltca` at the gear's kinematics.
    pub fn new(gear: &GearSet, geo: &Geometry, ltca: &Ltca) -> Self {
        let positions = ltca
            .positions
            .iter()
            .map(|p| {
                let sliding = cell_sliding(gear, geo, &p.cells);
                PositionArms {
                    normal_wheel_torque: p.normal_wheel_torque,
                    cells: (0..p.cells.len())
                        .filter(|&k| p.pressure[k] > 0.0)
                        .map(|k| {
                            let force = p.pressure[k] * p.cells[k].cell.area();
                            (k, force, sliding[k].worm_arm, sliding[k].wheel_arm)
                        })
                        .collect(),
                }
            })
            .collect();
        Self {
            ratio: gear.ratio(),
            positions,
        }
    }

    /// (W, M1, M2) summed over the positions (N m) with the friction coefficient `mu(position,
    /// cell)` at each loaded cell.
    fn moments(&self, mu: &dyn Fn(usize, usize) -> f64) -> (f64, f64, f64) {
        self.positions
            .iter()
            .enumerate()
            .fold((0.0, 0.0, 0.0), |(w, m1, m2), (n, p)| {
                let (a, b) = p
                    .cells
                    .iter()
                    .fold((0.0, 0.0), |(a, b), &(k, f, arm1, arm2)| {
                        let friction = mu(n, k) * f;
                        (a + friction * arm1, b + friction * arm2)
                    });
                (w + p.normal_wheel_torque, m1 + a, m2 + b)
            })
    }

    /// Driving and back-driving efficiencies (eta, eta') with `mu(position, cell)`.
    pub fn efficiencies(&self, mu: &dyn Fn(usize, usize) -> f64) -> (f64, f64) {
        let (w, m1, m2) = self.moments(mu);
        let u = self.ratio;
        ((w + m2) / (w + u * m1), (w - u * m1) / (w - m2))
    }

    /// The uniform friction coefficient at which the gear self-locks (eta' = 0): W / (u M1)
    /// at unit friction; infinite where the friction cannot stop it.
    pub fn locking_friction(&self) -> f64 {
        let (w, m1, _) = self.moments(&|_, _| 1.0);
        if m1 > 0.0 {
            w / (self.ratio * m1)
        } else {
            f64::INFINITY
        }
    }
}

/// Back-driving efficiency and self-locking, static and dynamic (MODEL §15).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SelfLocking {
    /// eta' with the boundary friction mu_b on every loaded cell (at rest).
    pub static_efficiency: f64,
    pub static_self_locking: bool,
    /// eta' with the contact's running friction at the operating speed (MODEL §13).
    pub dynamic_efficiency: f64,
    pub dynamic_self_locking: bool,
    /// The boundary friction used (friction.boundary) and the uniform friction coefficient at
    /// which the gear self-locks: the margin of the static verdict is their ratio.
    pub boundary_friction: f64,
    pub locking_friction: f64,
    /// The driving mesh efficiency of the same moments with the running friction: the loaded
    /// analysis' own (T2 / (u T1)) where its pressures carry the friction (MODEL §5.2).
    pub driving_efficiency: f64,
}

impl SelfLocking {
    /// From the loaded analysis' arms, the running friction of its loaded cells `running`
    /// ((position, cell, mu, power density) as [`super::MeshFriction::cells`]) and the
    /// boundary friction `boundary`.
    pub fn new(arms: &FrictionArms, running: &[(usize, usize, f64, f64)], boundary: f64) -> Self {
        let lookup: std::collections::HashMap<(usize, usize), f64> =
            running.iter().map(|&(n, k, mu, _)| ((n, k), mu)).collect();
        let (driving, dynamic) =
            arms.efficiencies(&|n, k| lookup.get(&(n, k)).copied().unwrap_or(0.0));
        let (_, at_rest) = arms.efficiencies(&|_, _| boundary);
        Self {
            static_efficiency: at_rest,
            static_self_locking: at_rest <= 0.0,
            dynamic_efficiency: dynamic,
            dynamic_self_locking: dynamic <= 0.0,
            boundary_friction: boundary,
            locking_friction: arms.locking_friction(),
            driving_efficiency: driving,
        }
    }
}
