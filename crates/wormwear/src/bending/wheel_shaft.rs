//! The wheel's shaft (MODEL §5.5, REFERENCE_GEARS: "wheel shaft fixed at one end"): the hub
//! is rigid and sits on a solid steel shaft between two bearings; the first bearing holds the
//! shaft laterally (axial sliding, tilt and rotation free), the second is the fixed end
//! (clamped: it takes the torque, the thrust and the tilt). The shaft segments between the hub
//! faces and the bearings are Timoshenko beams (one element each: exact for end loads).
//!
//! Result: the 6 x 6 compliance of the hub's rigid-body motion (translation, rotation) under a
//! wrench (force, moment) at the wheel centre, in the fixed wheel frame (z along the axis):
//! a unit normal force at a flank point M moves a flank point P along its normal by
//! g(P)^T S g(M), g = (n, M x n), which is added to the wheel's FE bending (whose web is
//! clamped at the hub).

use nalgebra::{DMatrix, Matrix6, Vector6};

/// The shaft and its supports, SI.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WheelShaft {
    /// Shaft radius (solid), m.
    pub radius: f64,
    /// Half the hub's width along the axis (the hub spans -half..half), m.
    pub hub_half_width: f64,
    /// Bearing positions along the wheel axis, m: [laterally holding, fixed end]; one on each
    /// side of the hub.
    pub bearings: [f64; 2],
    /// Young's modulus, Pa, and Poisson's ratio of the shaft (steel).
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
}

/// Stiffness of a Timoshenko beam element along z from z = 0 to z = length, 12 x 12, DOFs per
/// node (u_x, u_y, u_z, theta_x, theta_y, theta_z) in N/m, N, N m/rad. Solid circular section
/// of the given radius, shear coefficient 6 (1 + v) / (7 + 6 v) (Cowper).
pub fn beam_stiffness(
    length: f64,
    radius: f64,
    youngs_modulus: f64,
    poisson_ratio: f64,
) -> DMatrix<f64> {
    let (e, v, l) = (youngs_modulus, poisson_ratio, length);
    let g = e / (2.0 * (1.0 + v));
    let area = std::f64::consts::PI * radius * radius;
    let inertia = 0.25 * area * radius * radius;
    let polar = 2.0 * inertia;
    let kappa = 6.0 * (1.0 + v) / (7.0 + 6.0 * v);
    let phi = 12.0 * e * inertia / (kappa * g * area * l * l);
    let mut k = DMatrix::zeros(12, 12);
    let mut add2 = |a: usize, b: usize, s: f64| {
        k[(a, a)] += s;
        k[(b, b)] += s;
        k[(a, b)] -= s;
        k[(b, a)] -= s;
    };
    add2(2, 8, e * area / l);
    add2(5, 11, g * polar / l);
    // Bending: deflection w with slope s = dw/dz at both ends, (w1, s1, w2, s2).
    let c = e * inertia / ((1.0 + phi) * l * l * l);
    let plane = [
        [12.0, 6.0 * l, -12.0, 6.0 * l],
        [6.0 * l, (4.0 + phi) * l * l, -6.0 * l, (2.0 - phi) * l * l],
        [-12.0, -6.0 * l, 12.0, -6.0 * l],
        [6.0 * l, (2.0 - phi) * l * l, -6.0 * l, (4.0 + phi) * l * l],
    ];
    // x-z plane: w = u_x, s = theta_y; y-z plane: w = u_y, s = -theta_x.
    for (dofs, signs) in [
        ([0, 4, 6, 10], [1.0, 1.0, 1.0, 1.0]),
        ([1, 3, 7, 9], [1.0, -1.0, 1.0, -1.0]),
    ] {
        for a in 0..4 {
            for b in 0..4 {
                k[(dofs[a], dofs[b])] += c * plane[a][b] * signs[a] * signs[b];
            }
        }
    }
    k
}

/// Rigid offset along the axis: the DOFs of a point at z = d on a rigid body in terms of the
/// body's reference point at z = 0 (u = t + theta x (0, 0, d)).
fn rigid_offset(d: f64) -> Matrix6<f64> {
    let mut t = Matrix6::identity();
    t[(0, 4)] = d;
    t[(1, 3)] = -d;
    t
}

impl WheelShaft {
    /// Compliance of the hub's rigid-body motion at the wheel centre (z = 0), 6 x 6 symmetric:
    /// (translation m, rotation rad) per (force N, moment N m).
    pub fn compliance(&self) -> Matrix6<f64> {
        let [za, zb] = self.bearings;
        let h = self.hub_half_width;
        // Unknowns: bearing A's free DOFs (u_z, theta_x, theta_y, theta_z), then the hub's 6.
        // Bearing B is clamped.
        let free_a = [2usize, 3, 4, 5];
        let mut k = DMatrix::<f64>::zeros(10, 10);
        let segment = |near_hub: f64, bearing: f64| {
            let (z0, z1) = if bearing < near_hub {
                (bearing, near_hub)
            } else {
                (near_hub, bearing)
            };
            let ke = beam_stiffness(
                z1 - z0,
                self.radius,
                self.youngs_modulus,
                self.poisson_ratio,
            );
            (ke, bearing < near_hub)
        };
        // Hub DOFs of a segment end at z = d: u_end = T(d) u_hub.
        let mut assemble = |near: f64, bearing: f64, bearing_free: &[usize], offset: usize| {
            let (ke, bearing_first) = segment(near, bearing);
            let (bo, ho) = if bearing_first { (0, 6) } else { (6, 0) };
            let t = rigid_offset(near);
            // Map element DOFs to unknowns: bearing DOF -> its slot, hub-end DOF -> T row.
            let mut map = DMatrix::<f64>::zeros(12, 10);
            for (slot, &d) in bearing_free.iter().enumerate() {
                map[(bo + d, offset + slot)] = 1.0;
            }
            for r in 0..6 {
                for c in 0..6 {
                    map[(ho + r, 4 + c)] = t[(r, c)];
                }
            }
            k += map.transpose() * ke * map;
        };
        assemble(-h.copysign(zb - za), za, &free_a, 0);
        assemble(h.copysign(zb - za), zb, &[], 0);
        let inverse = k
            .clone()
            .cholesky()
            .map(|c| c.inverse())
            .unwrap_or_else(|| DMatrix::zeros(10, 10));
        let mut s = Matrix6::zeros();
        for r in 0..6 {
            for c in 0..6 {
                s[(r, c)] = 0.5 * (inverse[(4 + r, 4 + c)] + inverse[(4 + c, 4 + r)]);
            }
        }
        s
    }
}

/// Generalised direction of a unit normal force n at the point p (wheel frame): the wrench
/// (n, p x n) it puts on the wheel, which is also the normal displacement it reads from a
/// rigid-body motion.
pub fn wrench(point: &nalgebra::Vector3<f64>, normal: &nalgebra::Vector3<f64>) -> Vector6<f64> {
    let m = point.cross(normal);
    Vector6::new(normal.x, normal.y, normal.z, m.x, m.y, m.z)
}
