//! The worm's CAD solid (MODEL §2): its threads on the root cylinder over the body length the
//! wheel can reach (`bending.worm_body_length_mm`), worm frame, rotation 0, mm.
//!
//! Every worm flank is a helicoid (MODEL §2.1): the transverse section at axial position x is the
//! section at x = 0 turned by x / (hand p_z / 2 pi). The section at x = 0 is, per thread, the two
//! flanks from the root radius to the tip radius (polar angle -X_ax(rho) / (hand p_z / 2 pi)),
//! the tip arc between them and the root arc to the next thread; a broken tip edge (MODEL §2.3)
//! joins a flank to the tip arc as its own face. Stations are spaced at most
//! 1/48 turn apart, which keeps the interpolated helices within 1e-4 um of the true ones.

use super::bspline::{mean_chord_params, uniform_params};
use super::section_solid::{build, FaceKind, SectionSweep, SweptFace};
use super::{CadError, CadPart, FitCheck};
use crate::geometry::{Flank, Geometry};
use crate::input::GearSet;
use std::f64::consts::PI;
use truck_modeling::{Point3, Vector3};

/// Points along each flank of the section.
const FLANK_POINTS: usize = 17;
/// Stations per turn of the section.
const STATIONS_PER_TURN: f64 = 48.0;
/// Largest angle between two points of an arc, rad.
const ARC_STEP: f64 = 0.05;

/// A point of the section at x = 0: (radius, polar angle), m and rad.
type Polar = (f64, f64);

/// The worm's solid and the checks of its flank fit.
pub fn worm_part(gear: &GearSet, geo: &Geometry) -> Result<CadPart, CadError> {
    let worm = &geo.worm;
    let (rf, ra) = (gear.worm.root_radius, gear.worm.tip_radius);
    let screw = worm.hand_sign() * worm.lead_per_rad();
    let length = gear.bending.worm_body_length;
    let angle = |flank: Flank, rho: f64| -worm.axial_profile(flank, rho).0 / screw;
    // The flank at the smaller polar angle comes first counter-clockwise.
    let sides = if angle(Flank::Left, rf) < angle(Flank::Right, rf) {
        [Flank::Left, Flank::Right]
    } else {
        [Flank::Right, Flank::Left]
    };
    let starts = worm.starts() as usize;
    let tops = sides.map(|flank| FlankTop::of(gear, geo, flank, screw));
    let pieces = section_pieces((rf, ra), starts, (sides, &tops), &angle)?;
    let turns = length / (2.0 * PI * screw.abs());
    let stations = ((turns * STATIONS_PER_TURN).ceil() as usize).max(8) + 1;
    let xs: Vec<f64> = uniform_params(stations)
        .iter()
        .map(|t| length * (t - 0.5))
        .collect();
    let point = |x: f64, (r, t): Polar| {
        let phi = t + x / screw;
        Point3::new(x * 1e3, r * phi.cos() * 1e3, r * phi.sin() * 1e3)
    };
    let outer: Vec<SweptFace> = pieces
        .iter()
        .map(|(kind, index, section)| SweptFace {
            kind: *kind,
            index: *index,
            rows: xs
                .iter()
                .map(|&x| section.iter().map(|&p| point(x, p)).collect())
                .collect(),
        })
        .collect();
    let checks = fit_checks(&outer, &pieces, &xs, &point, angle);
    let built = build(SectionSweep {
        outer,
        inner: Vec::new(),
        axis: Vector3::unit_x(),
        breaks: Vec::new(),
    })?;
    let checks = checks.into_iter().map(|c| built.map_check(c)).collect();
    let pitch_angle = 2.0 * PI / starts as f64;
    let section = section_area(rf, ra, starts, pitch_angle, angle, (sides, &tops));
    Ok(CadPart {
        built,
        checks,
        volume_mm3: section * length * 1e9,
    })
}

/// The pieces of the section at x = 0, counter-clockwise: per thread, flank A up from the root
/// radius, its broken tip edge where it has one, the tip arc, flank B's edge and flank B down,
/// the root arc to the next thread (`angle`: the flanks' polar angle at a radius, rad; `tops`:
/// where each flank meets the tip land).
fn section_pieces(
    (rf, ra): (f64, f64),
    starts: usize,
    ([a, b], [top_a, top_b]): ([Flank; 2], &[FlankTop; 2]),
    angle: &impl Fn(Flank, f64) -> f64,
) -> Result<Vec<(FaceKind, usize, Vec<Polar>)>, CadError> {
    let pitch_angle = 2.0 * PI / starts as f64;
    let tip_width = top_b.tip_angle - top_a.tip_angle;
    let root_width = angle(a, rf) + pitch_angle - angle(b, rf);
    if tip_width <= 0.0 || root_width <= 0.0 {
        return Err(CadError::Build(format!(
            "the worm's section does not close: thread {tip_width:.4} rad wide at the tip, \
             root gap {root_width:.4} rad"
        )));
    }
    let flank = |side: Flank, from: f64, to: f64, turn: f64| -> Vec<Polar> {
        (0..FLANK_POINTS)
            .map(|i| from + (to - from) * i as f64 / (FLANK_POINTS - 1) as f64)
            .map(|r| (r, angle(side, r) + turn))
            .collect()
    };
    let arc = |r: f64, t0: f64, t1: f64| -> Vec<Polar> {
        let n = (((t1 - t0).abs() / ARC_STEP).ceil() as usize).max(2) + 1;
        (0..n)
            .map(|i| (r, t0 + (t1 - t0) * i as f64 / (n - 1) as f64))
            .collect()
    };
    let turned = |points: Vec<Polar>, turn: f64| -> Vec<Polar> {
        points.into_iter().map(|(r, t)| (r, t + turn)).collect()
    };
    let mut pieces = Vec::new();
    for thread in 0..starts {
        let turn = thread as f64 * pitch_angle;
        let tip = arc(ra, top_a.tip_angle + turn, top_b.tip_angle + turn);
        let next = angle(a, rf) + turn + pitch_angle;
        pieces.push((kind(a), thread, flank(a, rf, top_a.tangent_radius, turn)));
        if let Some(edge) = top_a.edge_points() {
            pieces.push((FaceKind::Edge, 2 * thread, turned(edge, turn)));
        }
        pieces.push((FaceKind::Tip, thread, tip));
        if let Some(mut edge) = top_b.edge_points() {
            edge.reverse();
            pieces.push((FaceKind::Edge, 2 * thread + 1, turned(edge, turn)));
        }
        pieces.push((kind(b), thread, flank(b, top_b.tangent_radius, rf, turn)));
        pieces.push((FaceKind::Root, thread, arc(rf, angle(b, rf) + turn, next)));
    }
    Ok(pieces)
}

/// Points along a broken tip edge of the section.
const EDGE_POINTS: usize = 17;

/// Where a worm flank meets the tip land in the section at x = 0 (MODEL §2.3): at the tip
/// radius (a sharp edge), or through its broken tip edge, the circle of radius R tangent to the
/// tip line rho = r_a and to the flank's tangent line at the tip in the axial section, as the
/// analyses' gap has it ([`crate::kinematics::TipEdge`]).
#[derive(Debug, Clone, Copy)]
struct FlankTop {
    /// Radius where the flank ends (the edge's tangent point; r_a when sharp), m.
    tangent_radius: f64,
    /// Polar angle where the tip land starts, rad.
    tip_angle: f64,
    edge: Option<EdgeArc>,
}

/// A broken tip edge in the axial section (x along the worm axis, rho from it), m.
#[derive(Debug, Clone, Copy)]
struct EdgeArc {
    radius: f64,
    /// The circle's centre (x, rho), m.
    centre: (f64, f64),
    /// Direction angles from the centre of the tangent point on the flank and of the tip point
    /// (the arc runs between them the short way), rad.
    from: f64,
    sweep: f64,
    /// The true flank's x less its tangent line's at the tangent point, m (0 for a straight
    /// axial profile): faded out along the arc so that it starts on the flank's own point.
    offset: f64,
    /// hand p_z / 2 pi: x = -screw x polar angle on a helicoid, m/rad.
    screw: f64,
}

impl EdgeArc {
    /// (x, rho) at t in [0, 1] from the tangent point to the tip point, m.
    fn at(&self, t: f64) -> (f64, f64) {
        let a = self.from + self.sweep * t;
        let (cx, cr) = self.centre;
        (
            cx + self.radius * a.cos() + self.offset * (1.0 - t),
            cr + self.radius * a.sin(),
        )
    }

    /// d(x, rho)/dt, m.
    fn derivative(&self, t: f64) -> (f64, f64) {
        let a = self.from + self.sweep * t;
        let r = self.radius * self.sweep;
        (-r * a.sin() - self.offset, r * a.cos())
    }

    /// The section's (rho, polar angle) at t.
    fn polar(&self, t: f64) -> Polar {
        let (x, rho) = self.at(t);
        (rho, -x / self.screw)
    }

    /// 1/2 integral of rho^2 dphi from the tangent point to the tip (Green's theorem's share of
    /// the section's area, m^2), by Simpson's rule on 2000 intervals of t, dphi = -dx / screw.
    fn area_share(&self) -> f64 {
        let n = 2000;
        let f = |t: f64| {
            let (_, rho) = self.at(t);
            -0.5 * rho * rho * self.derivative(t).0 / self.screw
        };
        let h = 1.0 / n as f64;
        (0..n)
            .map(|i| {
                let t0 = h * i as f64;
                h / 6.0 * (f(t0) + 4.0 * f(t0 + 0.5 * h) + f(t0 + h))
            })
            .sum()
    }
}

impl FlankTop {
    /// The top of `flank` of the gear's worm with its `worm.tip_edge_radius`; `screw` =
    /// hand p_z / 2 pi (m/rad).
    fn of(gear: &GearSet, geo: &Geometry, flank: Flank, screw: f64) -> Self {
        let worm = &geo.worm;
        let (ra, radius) = (gear.worm.tip_radius, gear.worm.tip_edge_radius);
        let (x_tip, slope) = worm.axial_profile(flank, ra);
        if radius <= 0.0 {
            return Self {
                tangent_radius: ra,
                tip_angle: -x_tip / screw,
                edge: None,
            };
        }
        // The material side along x (toward the thread's middle, x = 0) and the circle's
        // centre: R below the tip line, R from the flank's tangent line on that side.
        let side = if x_tip < 0.0 { 1.0 } else { -1.0 };
        let norm = (1.0 + slope * slope).sqrt();
        let centre = (
            x_tip + slope * (-radius) + side * radius * norm,
            ra - radius,
        );
        let from = (side * slope / norm).atan2(-side / norm);
        let mut sweep = 0.5 * PI - from;
        if sweep > PI {
            sweep -= 2.0 * PI;
        } else if sweep < -PI {
            sweep += 2.0 * PI;
        }
        let tangent_radius = centre.1 + radius * from.sin();
        let line_x = x_tip + slope * (tangent_radius - ra);
        let edge = EdgeArc {
            radius,
            centre,
            from,
            sweep,
            offset: worm.axial_profile(flank, tangent_radius).0 - line_x,
            screw,
        };
        Self {
            tangent_radius,
            tip_angle: edge.polar(1.0).1,
            edge: Some(edge),
        }
    }

    /// The broken edge's section points from the flank up to the tip (None: sharp).
    fn edge_points(&self) -> Option<Vec<Polar>> {
        let e = self.edge?;
        Some(
            (0..EDGE_POINTS)
                .map(|i| e.polar(i as f64 / (EDGE_POINTS - 1) as f64))
                .collect(),
        )
    }
}

/// Area of the worm's transverse section (the same at every x: a screw motion keeps areas), m^2:
/// Green's theorem in polar form, A = 1/2 closed integral of rho^2 dphi, along each flank by
/// Simpson's rule on 2000 intervals of rho, exactly on the arcs. The volume of the body is this
/// area times its length (Cavalieri), independent of the sections sampled for the surfaces.
fn section_area(
    rf: f64,
    ra: f64,
    starts: usize,
    pitch_angle: f64,
    angle: impl Fn(Flank, f64) -> f64,
    ([a, b], [top_a, top_b]): ([Flank; 2], &[FlankTop; 2]),
) -> f64 {
    let n = 2000;
    // 1/2 integral of rho^2 dphi up the flank to its top, phi(rho) differentiated by central
    // differences; then up its broken edge to the tip.
    let up = |flank: Flank, top: &FlankTop| -> f64 {
        let h = (top.tangent_radius - rf) / n as f64;
        let f = |r: f64| {
            let d = 1e-3 * h;
            0.5 * r * r * (angle(flank, r + d) - angle(flank, r - d)) / (2.0 * d)
        };
        (0..n)
            .map(|i| {
                let (r0, r1) = (rf + h * i as f64, rf + h * (i + 1) as f64);
                h / 6.0 * (f(r0) + 4.0 * f(0.5 * (r0 + r1)) + f(r1))
            })
            .sum::<f64>()
            + top.edge.map_or(0.0, |e| e.area_share())
    };
    let tip = 0.5 * ra * ra * (top_b.tip_angle - top_a.tip_angle);
    let root = 0.5 * rf * rf * (angle(a, rf) + pitch_angle - angle(b, rf));
    starts as f64 * (up(a, top_a) + tip - up(b, top_b) + root)
}

/// The face kind of a worm flank.
fn kind(flank: Flank) -> FaceKind {
    match flank {
        Flank::Left => FaceKind::FlankLeft,
        Flank::Right => FaceKind::FlankRight,
    }
}

/// Flank points between the interpolated ones (half a radius step and half a station off), on
/// the flank's own helicoid, with the parameters near them.
fn fit_checks(
    outer: &[SweptFace],
    pieces: &[(FaceKind, usize, Vec<Polar>)],
    xs: &[f64],
    point: &impl Fn(f64, Polar) -> Point3,
    angle: impl Fn(Flank, f64) -> f64,
) -> Vec<FitCheck> {
    let v = uniform_params(xs.len());
    pieces
        .iter()
        .enumerate()
        .filter(|(_, (kind, _, _))| kind.is_flank())
        .map(|(face, (kind, _, section))| {
            let flank = if *kind == FaceKind::FlankLeft {
                Flank::Left
            } else {
                Flank::Right
            };
            let turn = section[0].1 - angle(flank, section[0].0);
            let u = mean_chord_params(&outer[face].rows);
            let mut points = Vec::new();
            for k in 0..xs.len() - 1 {
                let x = 0.5 * (xs[k] + xs[k + 1]);
                for i in 0..section.len() - 1 {
                    let r = 0.5 * (section[i].0 + section[i + 1].0);
                    let hint = (0.5 * (u[i] + u[i + 1]), 0.5 * (v[k] + v[k + 1]));
                    points.push((point(x, (r, angle(flank, r) + turn)), hint));
                }
            }
            FitCheck {
                face,
                band: 0,
                points,
            }
        })
        .collect()
}
