//! Worm and hob thread surfaces as helicoids (MODEL §2.1).
//!
//! In the thread's own frame (x along its axis), the flank of thread k through a point with
//! radius rho and polar angle phi = atan2(z, y) is at
//!
//! ```text
//! X(y, z; theta1) = X_ax(rho) + s h phi - h theta1 + k p_x
//! ```
//!
//! with s = +1 (right hand) or -1 (left hand), h = p_z / 2pi, p_x the axial pitch and
//! theta1 the rotation angle of the thread, defined so that the thread *advances* by
//! -h theta1 along x for either hand (MODEL §12a; the physical rotation about +x is s theta1).

use super::profile::{AxialProfile, ProfileGenerator};
use super::GeometryError;
use crate::input::ThreadDef;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Side of a thread, as seen in the axial section with x pointing right.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Flank {
    /// The flank facing -x (loaded when the worm turns in the positive sense).
    Left,
    /// The flank facing +x.
    Right,
}

impl Flank {
    /// Both flanks, left first.
    pub const BOTH: [Flank; 2] = [Flank::Left, Flank::Right];

    /// -1 for the left flank, +1 for the right one (sign of its outward normal's x component).
    pub fn sign(self) -> f64 {
        match self {
            Flank::Left => -1.0,
            Flank::Right => 1.0,
        }
    }

    /// Lower-case name for files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Flank::Left => "left",
            Flank::Right => "right",
        }
    }
}

/// A worm or hob thread: both flanks of all starts (MODEL §2).
#[derive(Debug, Clone)]
pub struct ThreadSurface {
    /// The thread definition it was built from.
    pub def: ThreadDef,
    /// Left-flank axial profile (the right flank is its mirror).
    profile: AxialProfile,
    /// The exact generator (used by tests and for checks).
    generator: ProfileGenerator,
    /// Shift applied to the generator so the axial thickness at r1 is exact, m.
    shift: f64,
    h: f64,
    hand: f64,
    pitch: f64,
}

/// Number of knots of the axial-profile table.
const PROFILE_KNOTS: usize = 512;

impl ThreadSurface {
    /// Builds the thread surface: computes the axial profile from the tool and places it so the
    /// axial thread thickness at the reference radius is exactly `def.axial_thickness`.
    pub fn new(def: &ThreadDef) -> Result<Self, GeometryError> {
        let generator = ProfileGenerator::new(def)?;
        let (x_ref, _) = generator.eval(def.reference_radius).ok_or_else(|| {
            GeometryError::Profile("the tool does not reach the reference radius".into())
        })?;
        let shift = -0.5 * def.axial_thickness - x_ref;
        let height = def.tip_radius - def.root_radius;
        let rho_min = (def.root_radius - 0.25 * height).max(0.5 * def.root_radius);
        let rho_max = def.tip_radius + 0.25 * height;
        let profile = AxialProfile::tabulate(&generator, rho_min, rho_max, PROFILE_KNOTS, shift)?;
        let surface = Self {
            def: def.clone(),
            profile,
            generator,
            shift,
            h: def.lead_per_rad(),
            hand: def.hand.sign(),
            pitch: def.axial_pitch,
        };
        // The thread must have material between its flanks up to the tip and a space down to
        // the root.
        let tip = surface.axial_thickness_at(def.tip_radius);
        if tip <= 0.0 {
            return Err(GeometryError::Profile(format!(
                "the thread is pointed below its tip (axial thickness at the tip {:.4} mm)",
                tip * 1e3
            )));
        }
        let space = def.axial_pitch - surface.axial_thickness_at(def.root_radius);
        if space <= 0.0 {
            return Err(GeometryError::Profile(format!(
                "the thread space closes above the root (space at the root {:.4} mm)",
                space * 1e3
            )));
        }
        Ok(surface)
    }

    /// Lead per radian h = p_z / 2pi, m/rad.
    pub fn lead_per_rad(&self) -> f64 {
        self.h
    }
    /// Axial pitch p_x, m.
    pub fn axial_pitch(&self) -> f64 {
        self.pitch
    }
    /// +1 right hand, -1 left hand.
    pub fn hand_sign(&self) -> f64 {
        self.hand
    }

    /// Axial profile of `flank` at radius rho: (X_ax, dX_ax/drho), m (thread k = 0 centred on x = 0).
    #[inline]
    pub fn axial_profile(&self, flank: Flank, rho: f64) -> (f64, f64) {
        let (x, s) = self.profile.eval(rho);
        match flank {
            Flank::Left => (x, s),
            Flank::Right => (-x, -s),
        }
    }

    /// The axial profile's angle to the radial direction at the tip radius of `flank`, rad
    /// (psi of the broken tip edge, MODEL §2.3).
    pub fn tip_profile_angle(&self, flank: Flank) -> f64 {
        self.axial_profile(flank, self.def.tip_radius)
            .1
            .abs()
            .atan()
    }

    /// Exact (untabulated) axial profile, for checks. None where the tool does not reach.
    pub fn axial_profile_exact(&self, flank: Flank, rho: f64) -> Option<(f64, f64)> {
        let (x, s) = self.generator.eval(rho)?;
        let x = x + self.shift;
        Some(match flank {
            Flank::Left => (x, s),
            Flank::Right => (-x, -s),
        })
    }

    /// x shift applied to the raw tool generator to make the thickness at r1 exact, m.
    pub fn generator_shift(&self) -> f64 {
        self.shift
    }

    /// Axial thread thickness at radius rho, m.
    pub fn axial_thickness_at(&self, rho: f64) -> f64 {
        self.axial_profile(Flank::Right, rho).0 - self.axial_profile(Flank::Left, rho).0
    }

    /// x of `flank` of thread k = 0 through the point (y, z) of the thread frame, thread at
    /// rotation 0, with its partial derivatives: (X, dX/dy, dX/dz). m.
    #[inline]
    pub fn flank_x(&self, flank: Flank, y: f64, z: f64) -> (f64, f64, f64) {
        let rho2 = y * y + z * z;
        let rho = rho2.sqrt();
        let (xa, slope) = self.axial_profile(flank, rho);
        let sh = self.hand * self.h;
        let phi = z.atan2(y);
        (
            xa + sh * phi,
            slope * y / rho - sh * z / rho2,
            slope * z / rho + sh * y / rho2,
        )
    }

    /// Unit normal of `flank` at a point of the flank (thread frame, rotation 0), pointing out of
    /// the thread material.
    pub fn outward_normal(&self, flank: Flank, y: f64, z: f64) -> Vector3<f64> {
        let (_, dy, dz) = self.flank_x(flank, y, z);
        // Surface x = X(y, z): gradient of x - X is (1, -dX/dy, -dX/dz), pointing to larger x.
        let g = Vector3::new(1.0, -dy, -dz).normalize();
        g * flank.sign()
    }

    /// Signed clearance along the thread axis between the point `p` (thread frame) and the
    /// nearest `flank` of the thread at rotation theta1: positive outside the thread material,
    /// negative inside. The thread is chosen so the result lies in [-s/2, p_x - s/2) (s the
    /// axial thickness at r1). Also returns the point's radius rho. m.
    #[inline]
    pub fn axial_gap(&self, flank: Flank, p: &Vector3<f64>, theta1: f64) -> (f64, f64) {
        let (gap, _, _, rho, _) = self.axial_gap_with_gradient(flank, p, theta1, None);
        (gap, rho)
    }

    /// As [`Self::axial_gap`], with the partial derivatives dX/dy, dX/dz of the flank at the
    /// point (one flank evaluation) and the thread index used: (gap, dX/dy, dX/dz, rho, k).
    /// With `thread = Some(k)` the gap is measured to thread k instead of the nearest one (keeps
    /// iterations on one thread).
    #[inline]
    pub fn axial_gap_with_gradient(
        &self,
        flank: Flank,
        p: &Vector3<f64>,
        theta1: f64,
        thread: Option<f64>,
    ) -> (f64, f64, f64, f64, f64) {
        let (x_flank, xy, xz) = self.flank_x(flank, p.y, p.z);
        let half = 0.5 * self.def.axial_thickness;
        let rho = (p.y * p.y + p.z * p.z).sqrt();
        let t = p.x + self.h * theta1 - x_flank;
        let (gap, k) = match flank {
            Flank::Left => {
                let k = thread.unwrap_or_else(|| ((t - half) / self.pitch).ceil());
                (k * self.pitch - t, k)
            }
            Flank::Right => {
                let k = thread.unwrap_or_else(|| ((t + half) / self.pitch).floor());
                (t - k * self.pitch, k)
            }
        };
        (gap, xy, xz, rho, k)
    }

    /// Point of `flank` of thread k at radius rho and polar angle phi (thread frame, rotation 0). m.
    pub fn flank_point(&self, flank: Flank, rho: f64, phi: f64, k: i64) -> Vector3<f64> {
        let (xa, _) = self.axial_profile(flank, rho);
        Vector3::new(
            xa + self.hand * self.h * phi + k as f64 * self.pitch,
            rho * phi.cos(),
            rho * phi.sin(),
        )
    }

    /// Lead angle at radius rho, rad.
    pub fn lead_angle_at(&self, rho: f64) -> f64 {
        (self.h / rho).atan()
    }

    /// Axial pressure angle of `flank` measured on the surface at radius rho (angle between the
    /// axial profile and the radial direction), rad.
    pub fn axial_pressure_angle_at(&self, rho: f64) -> f64 {
        self.axial_profile(Flank::Left, rho).1.atan()
    }

    /// Normal pressure angle at radius rho from the surface's tangent plane:
    /// tan(alpha_n) = tan(alpha_x) cos(gamma), rad.
    pub fn normal_pressure_angle_at(&self, rho: f64) -> f64 {
        (self.axial_pressure_angle_at(rho).tan() * self.lead_angle_at(rho).cos()).atan()
    }

    /// Number of starts.
    pub fn starts(&self) -> u32 {
        self.def.starts
    }

    /// Full turn of the thread advances it by the lead p_z = 2 pi h, m.
    pub fn lead(&self) -> f64 {
        2.0 * PI * self.h
    }
}
