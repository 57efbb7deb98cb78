//! Wear of one mesh cycle (MODEL §7.2): the loaded band's passage over every node of the reference
//! tooth, the time integral of the pressure by quadrature, the film and the local wear coefficient
//! from [`crate::lubrication`], Archard's removal. Why the band is moved continuously: see the
//! module doc of [`super`].

use crate::geometry::{FlankField, Geometry, WheelFlank};
use crate::input::{FilmLoad, GearSet};
use crate::kinematics::{GapEvaluator, Tca};
use crate::ltca::passage::Passage;
use crate::ltca::Ltca;
use crate::lubrication::{self, LineContact};
use rayon::prelude::*;
use std::f64::consts::PI;

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
    /// The composite roughness on the flank's nodes (MODEL §6.1).
    roughness: lubrication::FlankRoughness<'a>,
}

impl PassageWear<'_> {
    /// Per node of column j, from the band's instants on it (sorted by time): depth per
    /// cycle, lambda, film, line load, band half-width, and the relative radius at the passage
    /// of the largest line load (MODEL §7.2, §6).
    fn column(&self, j: usize, samples: &[crate::ltca::passage::Sample]) -> Vec<[f64; 6]> {
        let ni = self.wf.cells_height;
        let mut out = vec![[0.0, f64::NAN, f64::NAN, 0.0, 0.0, 0.0]; ni + 1];
        let mut pieces = Vec::new();
        for pair in samples.windows(2) {
            // Consecutive instants of the same engagement only.
            let Some(passage) = Passage::between(&pair[0], &pair[1], self.dt) else {
                continue;
            };
            for (i, o) in out.iter_mut().enumerate() {
                self.node(j * (ni + 1) + i, &passage, o, &mut pieces);
            }
        }
        out
    }

    /// Adds one passage over node k to its entry `o` ([`Self::column`]).
    fn node(&self, k: usize, passage: &Passage, o: &mut [f64; 6], pieces: &mut Vec<f64>) {
        let (a, b) = (passage.a, passage.b);
        let duration = (b.time - a.time) / self.wheel_speed;
        let (lo, hi) = (passage.lo, passage.hi);
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
        let integral = passage.pressure_integral(node.r, pieces) * duration;
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
        let rq = self.roughness.node(k);
        let fl = lubrication::film_over(&self.gear.lubricant, self.e_prime, &contact, rq);
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
/// band of each instant moves with its contact line, from its crossing c_a to c_b, while its
/// shape blends from p_a to p_b (an edge contact off the line stays near its edge); the time integral of the pressure at every node follows by quadrature over the
/// interval (sub-steps of at most a tenth of the band width). The passage is thus resolved
/// whatever the number of positions (no aliasing), and the band follows the worn geometry
/// (the profiles are the loaded analysis on it). Depth = (k(lambda)/H) |vg| integral(p dt),
/// |vg| of the node at its contact moment, lambda from the interpolated line load (floored at
/// the Hertz load of the peak pressure with [`FilmLoad::HertzPeakFloor`]) over the roughness the
/// loaded analysis ran in (MODEL §6.1, [`Ltca::roughness`]).
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
    let columns = &ltca.passage_samples;
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
        rolling: tca.rolling_velocities(wf),
        dt,
        wheel_speed,
        e_prime,
        k_dry,
        hardness,
        film_load,
        roughness: lubrication::FlankRoughness::of(&gear.lubricant, ltca.roughness.as_ref(), wf),
    };
    // Node columns are independent (each writes its own nodes): in parallel, then gathered.
    let per_column: Vec<Vec<[f64; 6]>> = columns
        .par_iter()
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
pub(super) fn node_lever(wf: &WheelFlank, k: usize) -> f64 {
    let n = &wf.nodes[k];
    GapEvaluator::lever(&n.position(), &n.normal_vec())
}
