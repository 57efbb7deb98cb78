//! Wheel flanks by simulation of hobbing (MODEL §3).
//!
//! The hob (a thread surface) turns by theta_h and the wheel by theta2 = theta_h z_h / z2. A
//! wheel material point (r, theta, z) lies at the stationary angle psi = theta + theta2. For a
//! given psi the point (fixed in the stationary frame) is on the hob's flank for exactly one
//! hob rotation per thread, which gives the wheel angle at which the point is cut:
//!
//! ```text
//! theta_c(psi) = psi - g(psi) / r_2,   g(psi) = X_flank(y1, z1) - x1,   r_2 = p_x z2 / 2pi
//! ```
//!
//! ((x1, y1, z1) the point in the hob frame at cutting placement; k = 0 thread, i.e. the
//! reference tooth space). The generated flank is the envelope: theta_w(r, z) = max over psi of
//! theta_c for the hob's left flank (material left at theta > theta_w), min for the right
//! flank, over the psi interval in which the point is inside the hob's tip cylinder. An
//! interior extremum satisfies the meshing equation (d theta_c / d psi = 0 <=> n . v = 0); an
//! extremum on the interval's end means the point is cut by the hob's tip edge (root fillet),
//! not by its flank.

use super::placement::{to_wheel_body, wheel_point, PlacementFrame};
use super::roots::{bisect, brent_max};
use super::thread::{Flank, ThreadSurface};
use super::GeometryError;
use crate::input::Placement;
use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI};

/// How the hob generates a wheel point (r, z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum PointKind {
    /// Cut by the hob flank (interior envelope: a flank point).
    Flank,
    /// Cut by the hob's tip edge (root fillet or undercut).
    Fillet,
    /// Never inside the hob's tip cylinder (below the root: no tooth space there).
    NotReached,
    /// Reaches the hob's root cylinder: the hob core would cut it.
    RootCut,
}

/// Envelope of the hob at one wheel point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopePoint {
    pub kind: PointKind,
    /// Flank angle theta_w in the wheel's body frame, rad (valid for Flank and Fillet).
    pub theta: f64,
    /// Stationary angle psi at which the point is generated, rad.
    pub psi: f64,
    /// Radius of the generating point on the hob, m.
    pub hob_radius: f64,
}

/// The hobbing set-up: hob, its placement, and the wheel tooth count.
#[derive(Debug, Clone)]
pub struct Hobbing<'a> {
    pub hob: &'a ThreadSurface,
    pub setting: Placement,
    frame: PlacementFrame,
    /// r_2 = p_x z2 / 2pi: the wheel radius that rolls on the hob's axial pitch line, m.
    pub rolling_radius: f64,
}

/// Samples of theta_c before the Brent refinement.
const ENVELOPE_SAMPLES: usize = 40;
/// Tolerance of the generating angle psi, rad.
const PSI_TOL: f64 = 1e-10;

impl<'a> Hobbing<'a> {
    /// Hobbing of a wheel of `teeth` teeth by `hob` at `setting`.
    pub fn new(hob: &'a ThreadSurface, setting: Placement, teeth: u32) -> Self {
        Self {
            hob,
            setting,
            frame: setting.into(),
            rolling_radius: hob.axial_pitch() * teeth as f64 / (2.0 * PI),
        }
    }

    /// The wheel point (r, psi, z) in the hob frame.
    #[inline]
    fn hob_point(&self, r: f64, z: f64, psi: f64) -> Vector3<f64> {
        self.frame.wheel_to_worm(&wheel_point(r, psi, z, 0.0))
    }

    /// Radius of the wheel point (r, psi, z) from the hob axis, m.
    #[inline]
    fn hob_radius(&self, r: f64, z: f64, psi: f64) -> f64 {
        let q = self.hob_point(r, z, psi);
        (q.y * q.y + q.z * q.z).sqrt()
    }

    /// Wheel angle theta_c(psi) at which the point (r, z), seen at stationary angle psi, lies on
    /// the hob's `flank` (reference tooth space), rad.
    #[inline]
    pub fn cut_angle(&self, flank: Flank, r: f64, z: f64, psi: f64) -> f64 {
        let q = self.hob_point(r, z, psi);
        let (x_flank, _, _) = self.hob.flank_x(flank, q.y, q.z);
        psi - (x_flank - q.x) / self.rolling_radius
    }

    /// Envelope at the wheel point (r, z) for the hob's `flank` (MODEL §3.2).
    pub fn envelope(&self, flank: Flank, r: f64, z: f64) -> EnvelopePoint {
        let tip = self.hob.def.tip_radius;
        let root = self.hob.def.root_radius;
        // Closest approach to the hob axis (near the line of centres).
        let (psi_near, neg_rho) = brent_max(
            |psi| -self.hob_radius(r, z, psi),
            FRAC_PI_2 - 1.0,
            FRAC_PI_2 + 1.0,
            1e-9,
        );
        let rho_near = -neg_rho;
        let none = |kind| EnvelopePoint {
            kind,
            theta: f64::NAN,
            psi: psi_near,
            hob_radius: rho_near,
        };
        if rho_near >= tip {
            return none(PointKind::NotReached);
        }
        if rho_near < root {
            return none(PointKind::RootCut);
        }
        let outside = |psi: f64| self.hob_radius(r, z, psi) - tip;
        let lo = bisect(outside, psi_near - FRAC_PI_2, psi_near, PSI_TOL);
        let hi = bisect(outside, psi_near, psi_near + FRAC_PI_2, PSI_TOL);
        let (Some(lo), Some(hi)) = (lo, hi) else {
            return none(PointKind::NotReached);
        };
        let sign = -flank.sign(); // +1: maximum (left flank), -1: minimum (right flank)
        let f = |psi: f64| sign * self.cut_angle(flank, r, z, psi);
        let step = (hi - lo) / (ENVELOPE_SAMPLES - 1) as f64;
        let mut best = (0, f64::NEG_INFINITY);
        for k in 0..ENVELOPE_SAMPLES {
            let v = f(lo + step * k as f64);
            if v > best.1 {
                best = (k, v);
            }
        }
        // Refine around the best sample (also when it is an end sample: the maximum may lie
        // between it and its neighbour), then classify by where the refined maximum lies.
        let (k, v) = best;
        let a = lo + step * k.saturating_sub(1) as f64;
        let b = lo + step * (k + 1).min(ENVELOPE_SAMPLES - 1) as f64;
        let (psi, v_refined) = brent_max(f, a, b, PSI_TOL);
        let (psi, v) = if v_refined >= v {
            (psi, v_refined)
        } else {
            (lo + step * k as f64, v)
        };
        let at_end = (psi - lo).abs() < 1e3 * PSI_TOL || (hi - psi).abs() < 1e3 * PSI_TOL;
        EnvelopePoint {
            kind: if at_end {
                PointKind::Fillet
            } else {
                PointKind::Flank
            },
            theta: sign * v,
            psi,
            hob_radius: self.hob_radius(r, z, psi),
        }
    }

    /// Unit normal of the generated wheel flank at an envelope point, in the wheel's body frame,
    /// pointing out of the wheel material (into the tooth space). It is the hob flank's normal
    /// at the generating point (the two surfaces are tangent there).
    pub fn wheel_normal(&self, flank: Flank, r: f64, z: f64, e: &EnvelopePoint) -> Vector3<f64> {
        let q = self.hob_point(r, z, e.psi);
        let into_hob = -self.hob.outward_normal(flank, q.y, q.z);
        let stationary = self.setting.vector_worm_to_wheel(&into_hob);
        to_wheel_body(&stationary, e.psi - e.theta)
    }

    /// Meshing function n . v at the stationary angle psi (MODEL §3.2, classical view): the
    /// hob-flank normal dotted with the velocity of the wheel point relative to the hob surface,
    /// per unit hob rotation. Zero at generated flank points.
    pub fn meshing_function(&self, flank: Flank, r: f64, z: f64, psi: f64) -> f64 {
        let q = self.hob_point(r, z, psi);
        let (_, dy, dz) = self.hob.flank_x(flank, q.y, q.z);
        // Hob flank at rotation theta_h: F = x - X(y, z) + h theta_h = 0 (advance -h theta_h).
        let grad = Vector3::new(1.0, -dy, -dz);
        // Wheel point velocity per unit hob rotation: (z_h/z2) d p / d psi, in the hob frame.
        let ratio = self.hob.lead_per_rad() / self.rolling_radius;
        let dp_stat = Vector3::new(-r * psi.sin(), -r * psi.cos(), 0.0) * ratio;
        let dp = self.setting.vector_wheel_to_worm(&dp_stat);
        grad.dot(&dp) + self.hob.lead_per_rad()
    }

    /// Radius range [r_low, r_high] of the generated `flank` inside the blank at face position z:
    /// r_high is the blank top (outer cylinder clipped by the throat torus), r_low the lowest
    /// point cut by the hob flank (below it the hob's tip edge cuts the fillet). m.
    pub fn radial_limits(
        &self,
        flank: Flank,
        z: f64,
        blank_top: f64,
    ) -> Result<(f64, f64), GeometryError> {
        let top = self.envelope(flank, blank_top, z);
        if top.kind != PointKind::Flank {
            let cut_by = match top.kind {
                PointKind::Fillet => "the hob's tip edge cuts there, not its flank",
                PointKind::NotReached => "the hob does not reach there",
                PointKind::RootCut => "the hob's root cylinder cuts there",
                PointKind::Flank => "",
            };
            return Err(GeometryError::Wheel(format!(
                "the hob does not generate the {} flank at the blank top (r = {:.4} mm, \
                 z = {:.4} mm): {cut_by}",
                flank.name(),
                blank_top * 1e3,
                z * 1e3,
            )));
        }
        let depth = self.hob.def.tip_radius - self.hob.def.root_radius;
        let mut lo = self.setting.centre_distance - self.hob.def.tip_radius - depth;
        if self.envelope(flank, lo, z).kind == PointKind::Flank {
            lo -= 2.0 * depth;
        }
        let mut hi = blank_top;
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            if self.envelope(flank, mid, z).kind == PointKind::Flank {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Ok((hi, blank_top))
    }
}
