//! Rigid transform between the wheel frame and a worm (or hob) frame (MODEL §1).
//!
//! Wheel frame: origin at the wheel centre O2, z2 the wheel axis. Worm frame: x1 the worm axis,
//! y1 towards the wheel centre. With a placement (a, offset, inclination) the worm axis passes
//! through (0, -a, offset) of the wheel frame with direction e1 = (cos i, 0, sin i); y1 = y2;
//! z1 = e1 x y1. Without misalignment the worm frame is the wheel frame shifted by a along y,
//! so O2 = (0, a, 0) in the worm frame.

use crate::input::Placement;
use nalgebra::Vector3;

impl Placement {
    /// Nominal placement: centre distance only, m.
    pub fn aligned(centre_distance: f64) -> Self {
        Self {
            centre_distance,
            offset: 0.0,
            inclination: 0.0,
        }
    }

    #[inline]
    fn axes(&self) -> (Vector3<f64>, Vector3<f64>) {
        let (s, c) = self.inclination.sin_cos();
        (Vector3::new(c, 0.0, s), Vector3::new(-s, 0.0, c))
    }

    /// Worm-frame coordinates of a point given in the (stationary) wheel frame, m.
    #[inline]
    pub fn wheel_to_worm(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let (e1, e3) = self.axes();
        let d = Vector3::new(p.x, p.y + self.centre_distance, p.z - self.offset);
        Vector3::new(e1.dot(&d), d.y, e3.dot(&d))
    }

    /// Wheel-frame coordinates of a point given in the worm frame, m.
    #[inline]
    pub fn worm_to_wheel(&self, q: &Vector3<f64>) -> Vector3<f64> {
        let v = self.vector_worm_to_wheel(q);
        Vector3::new(v.x, v.y - self.centre_distance, v.z + self.offset)
    }

    /// Wheel-frame components of a vector given in worm-frame components.
    #[inline]
    pub fn vector_worm_to_wheel(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let (e1, e3) = self.axes();
        e1 * v.x + Vector3::new(0.0, v.y, 0.0) + e3 * v.z
    }

    /// Worm-frame components of a vector given in wheel-frame components.
    #[inline]
    pub fn vector_wheel_to_worm(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let (e1, e3) = self.axes();
        Vector3::new(e1.dot(v), v.y, e3.dot(v))
    }
}

/// A [`Placement`] with its axes precomputed, for hot loops (same transforms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacementFrame {
    pub placement: Placement,
    e1: Vector3<f64>,
    e3: Vector3<f64>,
}

impl From<Placement> for PlacementFrame {
    fn from(placement: Placement) -> Self {
        let (e1, e3) = placement.axes();
        Self { placement, e1, e3 }
    }
}

impl PlacementFrame {
    /// Worm-frame coordinates of a wheel-frame point, m.
    #[inline]
    pub fn wheel_to_worm(&self, p: &Vector3<f64>) -> Vector3<f64> {
        let d = Vector3::new(
            p.x,
            p.y + self.placement.centre_distance,
            p.z - self.placement.offset,
        );
        Vector3::new(self.e1.dot(&d), d.y, self.e3.dot(&d))
    }

    /// Worm-frame components of a wheel-frame vector.
    #[inline]
    pub fn vector_wheel_to_worm(&self, v: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(self.e1.dot(v), v.y, self.e3.dot(v))
    }

    /// Wheel-frame components of a worm-frame vector.
    #[inline]
    pub fn vector_worm_to_wheel(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.e1 * v.x + Vector3::new(0.0, v.y, 0.0) + self.e3 * v.z
    }
}

/// Stationary wheel-frame position of the wheel material point (r, theta, z) when the wheel has
/// turned by theta2 (MODEL §1: x2 = r cos(theta + theta2), y2 = -r sin(theta + theta2)). m.
#[inline]
pub fn wheel_point(r: f64, theta: f64, z: f64, theta2: f64) -> Vector3<f64> {
    let (s, c) = (theta + theta2).sin_cos();
    Vector3::new(r * c, -r * s, z)
}

/// Rotates a stationary wheel-frame vector back to the wheel's own (body) frame, for a wheel
/// turned by theta2 (inverse of the motion of [`wheel_point`]).
#[inline]
pub fn to_wheel_body(v: &Vector3<f64>, theta2: f64) -> Vector3<f64> {
    let (s, c) = theta2.sin_cos();
    Vector3::new(v.x * c - v.y * s, v.x * s + v.y * c, v.z)
}

/// Turns a wheel body-frame vector into the stationary wheel frame for a wheel turned by theta2
/// (the motion of [`wheel_point`]; inverse of [`to_wheel_body`]).
#[inline]
pub fn from_wheel_body(v: &Vector3<f64>, theta2: f64) -> Vector3<f64> {
    to_wheel_body(v, -theta2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_nominal_shift() {
        let p = Placement {
            centre_distance: 0.125,
            offset: 0.002,
            inclination: 0.01,
        };
        let x = Vector3::new(0.01, -0.09, 0.005);
        let back = p.worm_to_wheel(&p.wheel_to_worm(&x));
        assert!((back - x).norm() < 1e-15);
        let nominal = Placement::aligned(0.125);
        let q = nominal.wheel_to_worm(&x);
        assert!((q - Vector3::new(x.x, x.y + 0.125, x.z)).norm() < 1e-15);
        // Wheel centre is at (0, a, 0) in the worm frame.
        let o2 = nominal.wheel_to_worm(&Vector3::zeros());
        assert!((o2 - Vector3::new(0.0, 0.125, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn precomputed_frame_matches_placement() {
        let p = Placement {
            centre_distance: 0.125,
            offset: -0.001,
            inclination: -0.02,
        };
        let f = PlacementFrame::from(p);
        let x = Vector3::new(0.03, -0.1, 0.012);
        assert!((f.wheel_to_worm(&x) - p.wheel_to_worm(&x)).norm() < 1e-16);
        assert!((f.vector_wheel_to_worm(&x) - p.vector_wheel_to_worm(&x)).norm() < 1e-16);
        assert!((f.vector_worm_to_wheel(&x) - p.vector_worm_to_wheel(&x)).norm() < 1e-16);
    }

    #[test]
    fn body_rotation_inverts_wheel_motion() {
        let (r, th, z, th2) = (0.1, 0.7, 0.003, 0.2);
        let stat = wheel_point(r, th, z, th2);
        let body = to_wheel_body(&stat, th2);
        assert!((body - wheel_point(r, th, z, 0.0)).norm() < 1e-15);
    }
}
