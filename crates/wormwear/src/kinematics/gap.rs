//! The gap of a wheel point to the worm flank at given rotations (MODEL §4.2): the linear gap
//! along the worm axis, the exact angular gap, their gradients, and the edge reliefs.

use super::*;
use crate::geometry::placement::{wheel_point, PlacementFrame};
use crate::geometry::{Flank, Geometry, ThreadSurface};
use crate::input::{GearSet, Placement};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Gap of a wheel point to the worm flank at given rotations.
#[derive(Debug, Clone, Copy)]
pub struct GapEvaluator<'a> {
    pub worm: &'a ThreadSurface,
    pub placement: Placement,
    pub(super) frame: PlacementFrame,
    /// Edge reliefs (normal distance added to the gap): worm tip, wheel edges (blank top and
    /// face ends), and the blank limits they refer to.
    pub tip_relief: crate::input::EdgeRelief,
    pub edge_relief: crate::input::EdgeRelief,
    /// The worm's broken tip edge (MODEL §2.3).
    pub tip_edge: TipEdge,
    /// Width along z of the wheel's 45 deg face-end chamfers, m (0: sharp).
    pub face_edge_chamfer: f64,
    pub blank: crate::geometry::BlankLimits,
    /// Loaded worm flank.
    pub flank: Flank,
    /// +1: wheel driven towards increasing theta2 (positive worm rotation), -1 otherwise.
    pub sigma: f64,
    /// z2 / z1.
    pub ratio: f64,
}

impl<'a> GapEvaluator<'a> {
    /// Evaluator for the gear's operating set-up and loaded flank.
    pub fn new(gear: &GearSet, geo: &'a Geometry) -> Self {
        Self::for_flank(gear, geo, loaded_flank(gear))
    }

    /// Evaluator for the operating set-up and the given worm flank (the opposite flank for
    /// backlash: its angular gaps close by turning the wheel the other way).
    pub fn for_flank(gear: &GearSet, geo: &'a Geometry, flank: Flank) -> Self {
        Self {
            worm: &geo.worm,
            placement: gear.operating,
            frame: gear.operating.into(),
            tip_relief: gear.worm.tip_relief,
            edge_relief: gear.wheel.edge_relief,
            tip_edge: TipEdge::of(&geo.worm, flank, gear.worm.tip_edge_radius),
            face_edge_chamfer: gear.wheel.face_edge_chamfer,
            blank: geo.blank,
            flank,
            sigma: -flank.sign(),
            ratio: gear.ratio(),
        }
    }

    /// Linear gap along the worm axis of the wheel point (r, theta_body, z) with the wheel at
    /// theta2 and the worm at theta1, its derivative with respect to the stationary angle, and
    /// the point's radius from the worm axis. m, m/rad, m.
    #[inline]
    pub fn linear(&self, r: f64, theta: f64, z: f64, theta2: f64, theta1: f64) -> (f64, f64, f64) {
        let (e, de, rho, _, _) = self.linear_on(r, theta, z, theta2, theta1, None);
        (e, de, rho)
    }

    /// [`Self::linear`] measured to worm thread `thread` (None: the nearest), also returning the
    /// thread index and the worm flank's axial-gap gradient (X_y, X_z) there.
    #[inline]
    fn linear_on(
        &self,
        r: f64,
        theta: f64,
        z: f64,
        theta2: f64,
        theta1: f64,
        thread: Option<f64>,
    ) -> (f64, f64, f64, f64, [f64; 2]) {
        let p = wheel_point(r, theta, z, theta2);
        let q = self.frame.wheel_to_worm(&p);
        let (e, xy, xz, rho, k) = self
            .worm
            .axial_gap_with_gradient(self.flank, &q, theta1, thread);
        let dq = self
            .frame
            .vector_wheel_to_worm(&Vector3::new(p.y, -p.x, 0.0));
        let mut de = (xy * dq.y + xz * dq.z - dq.x) * -self.flank.sign();
        // Edge reliefs, as normal distances turned into axial ones (|n_x| = 1 / sqrt(1 + X_y^2
        // + X_z^2) on the worm flank).
        let (relief, d_relief_drho) = self.relief(r, z, rho);
        let axial = (1.0 + xy * xy + xz * xz).sqrt();
        if relief > 0.0 {
            de += d_relief_drho * axial * (q.y * dq.y + q.z * dq.z) / rho;
        }
        (e + relief * axial, de, rho, k, [xy, xz])
    }

    /// Unit normal of the worm flank (worm frame) at the worm point axially opposite a wheel
    /// point (the point the axial gap is measured to), from the axial-gap gradient (X_y, X_z)
    /// that [`Self::angular_with_gradient`] returns for the wheel point, oriented like the
    /// wheel flank normal `towards` (worm frame) there.
    pub fn worm_normal_from(gradient: [f64; 2], towards: &Vector3<f64>) -> Vector3<f64> {
        let n = Vector3::new(1.0, -gradient[0], -gradient[1]).normalize();
        if n.dot(towards) < 0.0 {
            -n
        } else {
            n
        }
    }

    /// Normal relief at a wheel point (r, z) touching the worm at radius rho: the worm's tip
    /// relief C (s/L)^2 with s = rho - (r_a1 - L) and its broken tip edge ([`TipEdge`]), plus
    /// the wheel's edge relief towards the blank top and the face ends and its face-end
    /// chamfers (45 deg: the flank recedes as far as the point lies inside the chamfer's width).
    /// Returns the relief (m) and its derivative with respect to rho.
    #[inline]
    pub fn relief(&self, r: f64, z: f64, rho: f64) -> (f64, f64) {
        let t = self.tip_relief;
        let (mut relief, mut slope) = t.at(rho - (self.worm.def.tip_radius - t.length));
        if self.tip_edge.radius > 0.0 {
            let (edge, edge_slope) = self.tip_edge.at(rho);
            relief += edge;
            slope += edge_slope;
        }
        let w = self.edge_relief;
        if w.amount > 0.0 {
            relief += w.at(r - (self.blank.top(z) - w.length)).0;
            relief += w.at(z.abs() - (0.5 * self.blank.face_width - w.length)).0;
        }
        if self.face_edge_chamfer > 0.0 {
            relief += (z.abs() - (0.5 * self.blank.face_width - self.face_edge_chamfer)).max(0.0);
        }
        (relief, slope)
    }

    /// Exact angular gap: the rotation of the wheel against its driven sense that closes the
    /// linear gap at the point, with the worm fixed (Newton on the nearest thread). +infinity
    /// when the point is outside the worm tip cylinder (the flank cannot reach it). rad.
    #[inline]
    pub fn angular(&self, r: f64, theta: f64, z: f64, theta2: f64, theta1: f64) -> f64 {
        self.angular_with_gradient(r, theta, z, theta2, theta1).0
    }

    /// [`Self::angular`] and the worm flank's axial-gap gradient (X_y, X_z) at the point's
    /// start (for [`Self::worm_normal_from`]), from the same surface evaluation.
    #[inline]
    pub fn angular_with_gradient(
        &self,
        r: f64,
        theta: f64,
        z: f64,
        theta2: f64,
        theta1: f64,
    ) -> (f64, [f64; 2]) {
        let (e, de, rho, k, gradient) = self.linear_on(r, theta, z, theta2, theta1, None);
        (
            self.angular_from(r, theta, z, theta2, theta1, (e, de, rho, k)),
            gradient,
        )
    }

    /// The Newton of [`Self::angular`] from the first evaluation (e, de, rho, thread); where it
    /// does not settle inside a broken tip edge, [`Self::angular_bracketed`].
    #[inline]
    fn angular_from(
        &self,
        r: f64,
        theta: f64,
        z: f64,
        theta2: f64,
        theta1: f64,
        (e, de, rho, k): (f64, f64, f64, f64),
    ) -> f64 {
        let tip = self.worm.def.tip_radius;
        if rho > tip || de.abs() < 1e-12 {
            return f64::INFINITY;
        }
        let point = (r, theta, z, theta2, theta1);
        match self.newton(point, (e, de, k)) {
            Some(delta) => delta,
            None if self.tip_edge.radius > 0.0 => self.angular_bracketed(point, k),
            None => f64::INFINITY,
        }
    }

    /// Newton on e(psi - sigma delta) = 0 on thread k from (e, de): None where a rotation of a
    /// tooth pitch cannot close the gap or the iteration does not settle (possible inside the
    /// edge reliefs, where the relief's slope can cancel the flank's). rad.
    #[inline]
    fn newton(
        &self,
        (r, theta, z, theta2, theta1): (f64, f64, f64, f64, f64),
        (e, de, k): (f64, f64, f64),
    ) -> Option<f64> {
        // e(psi - sigma delta) = 0, de/dpsi has the sign of sigma.
        let limit = 2.0 * PI / self.ratio / self.worm.starts() as f64;
        if self.sigma * de <= 0.0 {
            return None;
        }
        let mut delta = e / (self.sigma * de);
        for _ in 0..12 {
            if !delta.is_finite() || delta.abs() > limit {
                return None;
            }
            let (e, de, _, _, _) =
                self.linear_on(r, theta, z, theta2 - self.sigma * delta, theta1, Some(k));
            if self.sigma * de <= 0.0 {
                return None;
            }
            let step = e / (self.sigma * de);
            delta += step;
            // Exact near contact (1e-13 rad), 1e-9 relative for far points (a 1 mm gap to
            // about a nanometre).
            if step.abs() < 1e-13 + 1e-9 * delta.abs() {
                return Some(delta);
            }
        }
        None
    }

    /// The angular gap where the Newton does not settle inside the broken tip edge (MODEL
    /// §2.3): its relief grows with the worm radius up to h = R (1 - sin psi), so the gap e
    /// of the rounded flank lies between the sharp flank's e_0 and e_0 + h |axial| and its
    /// closing rotations between the sharp flank's (e_0 = 0, where e >= 0) and the rotation
    /// past it where e <= 0. That bracket (found by doubling a step of the sharp flank's
    /// Newton) is narrowed by the Illinois false position to the Newton's tolerance; +infinity
    /// where the sharp flank is out of reach or the bracket leaves a tooth pitch. rad.
    #[cold]
    fn angular_bracketed(&self, point: (f64, f64, f64, f64, f64), k: f64) -> f64 {
        let (r, theta, z, theta2, theta1) = point;
        let sharp = Self {
            tip_edge: TipEdge {
                radius: 0.0,
                ..self.tip_edge
            },
            ..*self
        };
        let gap = |delta: f64| {
            self.linear_on(r, theta, z, theta2 - self.sigma * delta, theta1, Some(k))
                .0
        };
        let (e0, de0, _, _, _) = sharp.linear_on(r, theta, z, theta2, theta1, Some(k));
        let Some(low) = sharp.newton(point, (e0, de0, k)) else {
            return f64::INFINITY;
        };
        let limit = 2.0 * PI / self.ratio / self.worm.starts() as f64;
        let (e_low, de_low, _, _, gradient) =
            sharp.linear_on(r, theta, z, theta2 - self.sigma * low, theta1, Some(k));
        let (mut a, mut fa) = (low, gap(low));
        if fa <= 0.0 {
            return a;
        }
        let axial = (1.0 + gradient[0].powi(2) + gradient[1].powi(2)).sqrt();
        let height = self.tip_edge.radius * (1.0 - (1.0 - self.tip_edge.cos_angle.powi(2)).sqrt());
        let mut step = (height * axial - e_low).max(fa) / (self.sigma * de_low);
        let (mut b, mut fb) = (a + step, gap(a + step));
        while fb > 0.0 {
            (a, fa) = (b, fb);
            step *= 2.0;
            b = a + step;
            if !step.is_finite() || b.abs() > limit {
                return f64::INFINITY;
            }
            fb = gap(b);
        }
        let found = crate::geometry::roots::illinois(
            |c| Ok::<f64, std::convert::Infallible>(gap(c)),
            (a, fa),
            (b, fb),
            |c, fc, width| fc == 0.0 || width < 1e-13 + 1e-9 * c.abs(),
            100,
        );
        found.unwrap_or_else(|never| match never {})
    }

    /// Lever arm converting an angular separation into a normal distance at a wheel point:
    /// |(P x n)_z| (MODEL §5.3), m.
    pub fn lever(point: &Vector3<f64>, normal: &Vector3<f64>) -> f64 {
        (point.x * normal.y - point.y * normal.x).abs()
    }
}

/// The worm's broken tip edge (MODEL §2.3): in the axial section a circle of radius R tangent
/// to the flank and to the tip cylinder. Near the tip the flank is taken as its tangent line at
/// the tip (axial pressure angle psi there, from the thread's own profile): the circle touches
/// it at rho_t = r_a - R (1 - sin psi), and a flank point a distance d = (rho - rho_t) / cos psi
/// past that along the profile lies R - sqrt(R^2 - d^2) above the circle, normal to the flank
/// (about d^2 / (2 R) near the tangent point). Exact for a straight axial profile (ZA); for a
/// curved one the tangent line's error over the edge's few tenths of a millimetre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipEdge {
    /// R, m (0: sharp).
    pub radius: f64,
    /// rho_t, the tangent point's radius from the worm axis, m.
    pub tangent_radius: f64,
    /// cos psi.
    pub cos_angle: f64,
}

impl TipEdge {
    /// The broken tip edge of radius `radius` (m) on `flank` of `worm`.
    pub fn of(worm: &ThreadSurface, flank: Flank, radius: f64) -> Self {
        let tip = worm.def.tip_radius;
        let psi = worm.tip_profile_angle(flank);
        Self {
            radius,
            tangent_radius: tip - radius * (1.0 - psi.sin()),
            cos_angle: psi.cos(),
        }
    }

    /// The normal relief at radius `rho` from the worm axis and its derivative with respect to
    /// rho (0 below the tangent point), m and m/m.
    #[inline]
    pub fn at(&self, rho: f64) -> (f64, f64) {
        if self.radius <= 0.0 || rho <= self.tangent_radius {
            return (0.0, 0.0);
        }
        let d = (rho - self.tangent_radius) / self.cos_angle;
        // The arc ends at the circle's top (tangent to the tip cylinder), reached from the
        // flank point d = R cos psi (beyond the tip radius): past it the relief holds its end,
        // R (1 - sin psi), with no slope, as the sharp flank's continuation past the tip does
        // for the unrounded edge (the flank's gap a Newton may cross on its way). The slope
        // stays bounded by 1 / (sin psi cos psi), whatever R: as R -> 0 the edge's gap tends
        // to the sharp one uniformly.
        let top = self.radius * self.cos_angle;
        let d = d.min(top);
        let root = (self.radius * self.radius - d * d).sqrt();
        let slope = if d < top {
            d / root / self.cos_angle
        } else {
            0.0
        };
        (self.radius - root, slope)
    }
}
