//! Worm and wheel profiles in rack planes (planes parallel to the worm axis at offset z from
//! the wheel median plane), for drawings and checks. Coordinates: worm frame (x along the worm
//! axis, y towards the wheel centre), worm and wheel at rotation 0, nominal operating placement.

use super::placement::wheel_point;
use super::thread::Flank;
use super::wheel::generate_point;
use super::{Geometry, GeometryError, Hobbing};
use crate::input::GearSet;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// One drawn curve: which member, and its points (x, y) in the worm frame, m.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SectionCurve {
    /// "worm" or "wheel".
    pub member: &'static str,
    pub points: Vec<(f64, f64)>,
}

/// All curves of one rack-plane section.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Section {
    /// Offset of the plane from the wheel median plane, m.
    pub offset: f64,
    pub curves: Vec<SectionCurve>,
}

/// Samples along each flank.
const FLANK_SAMPLES: usize = 40;

/// Worm threads and wheel teeth in the rack plane at `offset` (m): `threads_each_side` threads
/// around x = 0 and as many wheel teeth around the line of centres.
pub fn rack_plane_section(
    gear: &GearSet,
    geo: &Geometry,
    offset: f64,
    threads_each_side: i64,
) -> Result<Section, GeometryError> {
    let curves = vec![
        SectionCurve {
            member: "worm",
            points: worm_outline(gear, geo, offset, threads_each_side),
        },
        SectionCurve {
            member: "wheel",
            points: wheel_outline(gear, geo, offset, threads_each_side)?,
        },
    ];
    Ok(Section { offset, curves })
}

/// The worm's outline in the rack plane at `c` (m; worm frame x, y): for each thread, left flank
/// up, tip, right flank down, root to the next.
fn worm_outline(gear: &GearSet, geo: &Geometry, c: f64, threads_each_side: i64) -> Vec<(f64, f64)> {
    let worm = &geo.worm;
    let (rf, ra) = (gear.worm.root_radius, gear.worm.tip_radius);
    let mut outline = Vec::new();
    let point = |flank: Flank, rho: f64, k: i64| -> Option<(f64, f64)> {
        if rho <= c.abs() {
            return None;
        }
        let y = (rho * rho - c * c).sqrt();
        let (x, _, _) = worm.flank_x(flank, y, c);
        Some((x + k as f64 * worm.axial_pitch(), y))
    };
    for k in -threads_each_side..=threads_each_side {
        for s in 0..=FLANK_SAMPLES {
            let rho = rf + (ra - rf) * s as f64 / FLANK_SAMPLES as f64;
            outline.extend(point(Flank::Left, rho, k));
        }
        for s in (0..=FLANK_SAMPLES).rev() {
            let rho = rf + (ra - rf) * s as f64 / FLANK_SAMPLES as f64;
            outline.extend(point(Flank::Right, rho, k));
        }
    }
    outline
}

/// The wheel teeth's outline in the rack plane at `c` (m; worm frame x, y): tooth k spans from
/// the left-mating flank of space k (theta_L + k tau) to the right-mating flank of space k + 1
/// (theta_R + (k + 1) tau).
fn wheel_outline(
    gear: &GearSet,
    geo: &Geometry,
    c: f64,
    threads_each_side: i64,
) -> Result<Vec<(f64, f64)>, GeometryError> {
    let hobbing: Hobbing = geo.hobbing(gear);
    let tau = 2.0 * PI / geo.teeth as f64;
    let top = geo.blank.top(c);
    let flank_curve = |flank: Flank| -> Result<Vec<(f64, f64)>, GeometryError> {
        let (lo, hi) = hobbing.radial_limits(flank, c, top)?;
        (0..=FLANK_SAMPLES)
            .map(|s| {
                let r = lo + (hi - lo) * s as f64 / FLANK_SAMPLES as f64;
                generate_point(&hobbing, flank, r, c).map(|p| (p.r, p.theta))
            })
            .collect()
    };
    let left = flank_curve(Flank::Left)?;
    let right = flank_curve(Flank::Right)?;
    let a = gear.operating;
    let to_xy = |r: f64, theta: f64| -> (f64, f64) {
        let q: Vector3<f64> = a.wheel_to_worm(&wheel_point(r, theta, c, 0.0));
        (q.x, q.y)
    };
    // Root radius at this offset (cut by the hob tip cylinder).
    let tip0 = gear.hob.tip_radius;
    let root = gear.cutting.centre_distance - (tip0 * tip0 - c * c).max(0.0).sqrt();
    let mut wheel = Vec::new();
    for k in -threads_each_side - 1..=threads_each_side {
        let kt = k as f64 * tau;
        // Root point in the middle of space k.
        let mid = 0.5 * (left[0].1 + right[0].1) + kt;
        wheel.push(to_xy(root, mid));
        for &(r, th) in &left {
            wheel.push(to_xy(r, th + kt));
        }
        let (t0, t1) = (
            left[FLANK_SAMPLES].1 + kt,
            right[FLANK_SAMPLES].1 + kt + tau,
        );
        for s in 1..FLANK_SAMPLES {
            wheel.push(to_xy(top, t0 + (t1 - t0) * s as f64 / FLANK_SAMPLES as f64));
        }
        for &(r, th) in right.iter().rev() {
            wheel.push(to_xy(r, th + kt + tau));
        }
    }
    Ok(wheel)
}
