//! A closed B-spline solid swept through parallel sections: the boundary representation shared by
//! the worm and the wheel (mm).
//!
//! Both parts are described the same way: at each of K stations along an axis (the worm's axis,
//! the wheel's face width) a closed outer loop of section curves (flank, fillet, root, tip ...),
//! and for the wheel's full rim an inner loop (the bore). Each piece of a loop, followed through
//! the stations, becomes one lateral face: a bicubic B-spline interpolating the points (u along
//! the section, v through the stations). Neighbouring faces meet on a rail, the curve through
//! their common points, interpolated once and used by both faces (their boundaries coincide; see
//! [`super::bspline`]); the first and last stations close the solid with planar end faces whose
//! boundaries are the section curves. Every edge is used once in each direction, so the shell is
//! closed and oriented by construction; truck checks it ([`Solid::try_new`]).

use super::bspline::{interpolate_surface, mean_chord_params, uniform_params, Interpolant};
use super::CadError;
use truck_modeling::{
    BSplineCurve, BSplineSurface, Curve, Edge, EuclideanSpace, Face, InnerSpace, Plane, Point3,
    Shell, Solid, Surface, Vector3, Vertex, Wire,
};

/// What a lateral face of a CAD solid is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaceKind {
    /// Left flank (the worm's or wheel's flank mating the worm's left flank).
    FlankLeft,
    /// Right flank.
    FlankRight,
    /// Tip land (worm outside cylinder, wheel blank top).
    Tip,
    /// Edge break between a flank and the tip land (the worm's rounded tip edge, MODEL §2.3).
    Edge,
    /// Root: fillet and root land (wheel), root cylinder between threads (worm).
    Root,
    /// Side of a wheel sector (a tooth count below the wheel's).
    Side,
    /// Bore of the wheel's rim.
    Bore,
}

impl FaceKind {
    /// Is this a flank (the surfaces fitted to the computed flank points)?
    pub fn is_flank(self) -> bool {
        matches!(self, FaceKind::FlankLeft | FaceKind::FlankRight)
    }
}

/// One piece of a section loop followed through the stations: `rows[k][m]` is point m (along
/// the loop) at station k, mm.
#[derive(Debug, Clone)]
pub struct SweptFace {
    pub kind: FaceKind,
    /// Tooth or thread number.
    pub index: usize,
    pub rows: Vec<Vec<Point3>>,
}

/// The loops of a swept solid: `outer` and optional `inner` (holes), each a closed chain of
/// pieces (the last point of a piece is the first of the next, at every station). `axis` points
/// from the first station to the last. Loops may run either way: the outer one is turned
/// counter-clockwise about the axis and the inner ones clockwise. `breaks` are stations where
/// the faces are split (the sections have a kink along the axis there): each band between
/// breaks gets its own faces, stations evenly spaced within it.
#[derive(Debug, Clone)]
pub struct SectionSweep {
    pub outer: Vec<SweptFace>,
    pub inner: Vec<SweptFace>,
    pub axis: Vector3,
    pub breaks: Vec<usize>,
}

/// A lateral face of a built solid: what it is, its tooth or thread, its band between breaks.
#[derive(Debug, Clone)]
pub struct LateralFace {
    pub kind: FaceKind,
    pub index: usize,
    pub band: usize,
    pub surface: BSplineSurface<Point3>,
}

/// A built solid with its lateral faces (band by band, the outer then the inner loop's) and
/// the volume of the sections it was fitted to.
#[derive(Debug, Clone)]
pub struct SweptSolid {
    pub solid: Solid,
    pub faces: Vec<LateralFace>,
    /// Volume enclosed by the section polygons, mm^3 ([`mesh_volume`]).
    pub mesh_volume_mm3: f64,
    /// The outer loop was turned (its pieces' order and direction reversed).
    outer_reversed: bool,
    outer_len: usize,
    pieces_per_band: usize,
}

impl SweptSolid {
    /// A fit check written against a piece of the outer loop as given (`check.face`) in band
    /// `check.band`, on the built faces.
    pub fn map_check(&self, mut check: super::FitCheck) -> super::FitCheck {
        if self.outer_reversed && check.face < self.outer_len {
            check.face = self.outer_len - 1 - check.face;
            for (_, hint) in check.points.iter_mut() {
                hint.0 = 1.0 - hint.0;
            }
        }
        check.face += check.band * self.pieces_per_band;
        check
    }
}

/// Largest gap allowed between the end of a piece and the start of the next, mm.
const JOIN_TOLERANCE_MM: f64 = 1e-6;

/// Builds the closed solid of `sweep` (see the module doc).
pub fn build(mut sweep: SectionSweep) -> Result<SweptSolid, CadError> {
    let stations = sweep.outer.first().map_or(0, |f| f.rows.len());
    if stations < 2 {
        return Err(CadError::Build(
            "a swept solid needs two stations or more".into(),
        ));
    }
    let bounds = band_bounds(&sweep.breaks, stations)?;
    join_loop(&mut sweep.outer, stations)?;
    join_loop(&mut sweep.inner, stations)?;
    let outer_reversed = orient(&mut sweep);
    let mesh_volume_mm3 = mesh_volume(&sweep, &bounds);
    let v: Vec<Interpolant> = bounds
        .windows(2)
        .map(|w| Interpolant::new(&uniform_params(w[1] - w[0] + 1)))
        .collect();
    let outer = LoopEdges::new(&sweep.outer, &bounds, &v);
    let inner = LoopEdges::new(&sweep.inner, &bounds, &v);
    let mut faces = Vec::new();
    let mut lateral = Vec::new();
    for (band, w) in bounds.windows(2).enumerate() {
        for (pieces, edges) in [(&sweep.outer, &outer), (&sweep.inner, &inner)] {
            for (i, piece) in pieces.iter().enumerate() {
                let surface = interpolate_surface(&edges.u[i], &v[band], &piece.rows[w[0]..=w[1]]);
                faces.push(edges.lateral_face(band, i, surface.clone()));
                lateral.push(LateralFace {
                    kind: piece.kind,
                    index: piece.index,
                    band,
                    surface,
                });
            }
        }
    }
    faces.push(end_face(&sweep, &outer, &inner, 0, 0)?);
    faces.push(end_face(
        &sweep,
        &outer,
        &inner,
        bounds.len() - 1,
        stations - 1,
    )?);
    let solid = Solid::try_new(vec![Shell::from(faces)])
        .map_err(|e| CadError::Build(format!("the shell is not a closed solid: {e}")))?;
    Ok(SweptSolid {
        solid,
        faces: lateral,
        mesh_volume_mm3,
        outer_reversed,
        outer_len: sweep.outer.len(),
        pieces_per_band: sweep.outer.len() + sweep.inner.len(),
    })
}

/// The stations that bound the bands: 0, the breaks, the last; each band two stations or more.
fn band_bounds(breaks: &[usize], stations: usize) -> Result<Vec<usize>, CadError> {
    let mut bounds = vec![0];
    bounds.extend_from_slice(breaks);
    bounds.push(stations - 1);
    if bounds.windows(2).any(|w| w[1] <= w[0]) {
        return Err(CadError::Build(format!(
            "the breaks {breaks:?} are not increasing stations inside 0..{}",
            stations - 1
        )));
    }
    Ok(bounds)
}

/// Checks that each piece of a loop ends where the next begins (to `JOIN_TOLERANCE_MM`) and
/// makes the points identical, so both faces interpolate the same rail.
fn join_loop(pieces: &mut [SweptFace], stations: usize) -> Result<(), CadError> {
    let n = pieces.len();
    for i in 0..n {
        let next = (i + 1) % n;
        if pieces[i].rows.len() != stations || pieces[i].rows.iter().any(|r| r.len() < 2) {
            return Err(CadError::Build(format!(
                "piece {i} ({:?}) has {} stations of which some have fewer than 2 points, \
                 expected {stations}",
                pieces[i].kind,
                pieces[i].rows.len()
            )));
        }
        for k in 0..stations {
            let start = pieces[next].rows[k][0];
            let end = pieces[i].rows[k].last_mut().expect("two points or more");
            let gap = (*end - start).magnitude();
            if gap > JOIN_TOLERANCE_MM {
                return Err(CadError::Build(format!(
                    "piece {i} ({:?} {}) ends {gap:.3e} mm from the start of the next at \
                     station {k}",
                    pieces[i].kind, pieces[i].index
                )));
            }
            *end = start;
        }
    }
    Ok(())
}

/// Signed area of a loop's first-station polygon about `axis` (projected), mm^2.
fn loop_area(pieces: &[SweptFace], axis: Vector3) -> f64 {
    let points: Vec<Point3> = pieces
        .iter()
        .flat_map(|p| p.rows[0][..p.rows[0].len() - 1].iter().copied())
        .collect();
    let n = points.len();
    (0..n)
        .map(|m| {
            let (a, b) = (points[m].to_vec(), points[(m + 1) % n].to_vec());
            0.5 * a.cross(b).dot(axis)
        })
        .sum::<f64>()
        / axis.magnitude()
}

/// Reverses a loop (the pieces' order and the points in each).
fn reverse(pieces: &mut [SweptFace]) {
    pieces.reverse();
    for p in pieces.iter_mut() {
        for row in p.rows.iter_mut() {
            row.reverse();
        }
    }
}

/// Turns the outer loop counter-clockwise about the axis and the inner ones clockwise, so that
/// every lateral face's S_u x S_v points out of the material. Returns whether the outer loop
/// was turned.
fn orient(sweep: &mut SectionSweep) -> bool {
    if !sweep.inner.is_empty() && loop_area(&sweep.inner, sweep.axis) > 0.0 {
        reverse(&mut sweep.inner);
    }
    let turn = loop_area(&sweep.outer, sweep.axis) < 0.0;
    if turn {
        reverse(&mut sweep.outer);
    }
    turn
}

/// Volume enclosed by the sections, mm^3, by Cavalieri: the integral over the axis of the
/// sections' areas (outer minus inner), Simpson's rule over the evenly spaced stations of each
/// band (the 3/8 rule on the last three intervals when their count is odd). A section's area
/// is Green's 1/2 closed integral of (P x P') . axis along each piece's cubic through its points
/// (three Gauss points per span): the polygon through the points would miss the chords'
/// segments (~1e-4 of the wheel's volume, more than a worn flank removes).
fn mesh_volume(sweep: &SectionSweep, bounds: &[usize]) -> f64 {
    use truck_modeling::ParametricCurve;
    let axis = sweep.axis.normalize();
    let params: Vec<Interpolant> = sweep
        .outer
        .iter()
        .chain(&sweep.inner)
        .map(|p| Interpolant::new(&mean_chord_params(&p.rows)))
        .collect();
    const GAUSS3: [(f64, f64); 3] = [
        (0.112_701_665_379_258_3, 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.887_298_334_620_741_7, 5.0 / 18.0),
    ];
    let area = |k: usize| -> f64 {
        let mut area = 0.0;
        for (piece, u) in sweep.outer.iter().chain(&sweep.inner).zip(&params) {
            let curve = u.curve(&piece.rows[k]);
            let knots: Vec<f64> = u.knots.iter().copied().collect();
            for w in knots.windows(2).filter(|w| w[1] > w[0]) {
                for (g, weight) in GAUSS3 {
                    let t = w[0] + (w[1] - w[0]) * g;
                    let (p, d) = (curve.subs(t).to_vec(), curve.der(t));
                    area += 0.5 * p.cross(d).dot(axis) * weight * (w[1] - w[0]);
                }
            }
        }
        area
    };
    let areas: Vec<f64> = (0..=bounds[bounds.len() - 1]).map(area).collect();
    let rail = |k: usize| sweep.outer[0].rows[k][0];
    bounds
        .windows(2)
        .map(|w| {
            let h = (rail(w[1]) - rail(w[0])).dot(axis) / (w[1] - w[0]) as f64;
            simpson(&areas[w[0]..=w[1]], h)
        })
        .sum()
}

/// Integral of evenly spaced samples `f` at step `h`: Simpson's rule, the 3/8 rule on the
/// last three intervals when their count is odd, the trapezoid for one interval.
fn simpson(f: &[f64], h: f64) -> f64 {
    let n = f.len() - 1;
    if n == 1 {
        return 0.5 * h * (f[0] + f[1]);
    }
    let tail = if n % 2 == 1 { 3 } else { 0 };
    let mut sum = 0.0;
    for i in (0..n - tail).step_by(2) {
        sum += h / 3.0 * (f[i] + 4.0 * f[i + 1] + f[i + 2]);
    }
    if tail == 3 {
        let i = n - 3;
        sum += 3.0 * h / 8.0 * (f[i] + 3.0 * f[i + 1] + 3.0 * f[i + 2] + f[i + 3]);
    }
    sum
}

/// The vertices and edges of one loop: per piece, its section parameters, the section curves
/// at the band bounds and, per band, the rail at the piece's start.
struct LoopEdges {
    u: Vec<Interpolant>,
    /// `sections[b][i]`: piece i's section curve at bound b.
    sections: Vec<Vec<Edge>>,
    /// `rails[band][i]`: the rail at piece i's start through the band.
    rails: Vec<Vec<Edge>>,
}

impl LoopEdges {
    fn new(pieces: &[SweptFace], bounds: &[usize], v: &[Interpolant]) -> Self {
        let n = pieces.len();
        let u: Vec<Interpolant> = pieces
            .iter()
            .map(|p| Interpolant::new(&mean_chord_params(&p.rows)))
            .collect();
        let vertices: Vec<Vec<Vertex>> = bounds
            .iter()
            .map(|&k| pieces.iter().map(|p| Vertex::new(p.rows[k][0])).collect())
            .collect();
        let curve = |c: BSplineCurve<Point3>| Curve::BSplineCurve(c);
        let sections = bounds
            .iter()
            .zip(&vertices)
            .map(|(&k, ends)| {
                (0..n)
                    .map(|i| {
                        Edge::new(
                            &ends[i],
                            &ends[(i + 1) % n],
                            curve(u[i].curve(&pieces[i].rows[k])),
                        )
                    })
                    .collect()
            })
            .collect();
        let rails = bounds
            .windows(2)
            .enumerate()
            .map(|(band, w)| {
                (0..n)
                    .map(|i| {
                        let column: Vec<Point3> =
                            pieces[i].rows[w[0]..=w[1]].iter().map(|r| r[0]).collect();
                        let (a, b) = (&vertices[band][i], &vertices[band + 1][i]);
                        Edge::new(a, b, curve(v[band].curve(&column)))
                    })
                    .collect()
            })
            .collect();
        Self { u, sections, rails }
    }

    /// Lateral face of piece i in `band`: its wire runs counter-clockwise in (u, v).
    fn lateral_face(&self, band: usize, i: usize, surface: BSplineSurface<Point3>) -> Face {
        let next = (i + 1) % self.u.len();
        let wire: Wire = vec![
            self.sections[band][i].clone(),
            self.rails[band][next].clone(),
            self.sections[band + 1][i].inverse(),
            self.rails[band][i].inverse(),
        ]
        .into();
        Face::new(vec![wire], Surface::BSplineSurface(surface))
    }
}

/// The planar end face at the first (bound 0, station 0, normal against the axis) or the last
/// bound (station k).
fn end_face(
    sweep: &SectionSweep,
    outer: &LoopEdges,
    inner: &LoopEdges,
    bound: usize,
    k: usize,
) -> Result<Face, CadError> {
    let at_start = k == 0;
    let wire = |edges: &LoopEdges| -> Wire {
        if at_start {
            edges.sections[bound]
                .iter()
                .rev()
                .map(|e| e.inverse())
                .collect()
        } else {
            edges.sections[bound].iter().cloned().collect()
        }
    };
    let normal = if at_start { -sweep.axis } else { sweep.axis }.normalize();
    let origin = sweep.outer[0].rows[k][0];
    let helper = if normal.x.abs() < 0.9 {
        Vector3::unit_x()
    } else {
        Vector3::unit_y()
    };
    let e1 = helper.cross(normal).normalize();
    let e2 = normal.cross(e1);
    let plane = Plane::new(origin, origin + e1, origin + e2);
    let off_plane = sweep
        .outer
        .iter()
        .chain(&sweep.inner)
        .flat_map(|p| p.rows[k].iter())
        .map(|p| (p - origin).dot(normal).abs())
        .fold(0.0, f64::max);
    if off_plane > JOIN_TOLERANCE_MM {
        return Err(CadError::Build(format!(
            "the section at station {k} is not plane ({off_plane:.3e} mm off its plane)"
        )));
    }
    let mut boundaries = vec![wire(outer)];
    if !inner.u.is_empty() {
        boundaries.push(wire(inner));
    }
    Ok(Face::new(boundaries, Surface::Plane(plane)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of side 2 turned by `twist` rad per unit length along z, over z in [0, 3],
    /// as four faces with `m` points each; volume 12 whatever the twist (each section is the
    /// same square).
    pub(crate) fn twisted_square(twist: f64, stations: usize, m: usize) -> SectionSweep {
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let outer = (0..4)
            .map(|i| {
                let (a, b) = (corners[i], corners[(i + 1) % 4]);
                let rows = (0..stations)
                    .map(|k| {
                        let z = 3.0 * k as f64 / (stations - 1) as f64;
                        let (s, c) = (twist * z).sin_cos();
                        (0..m)
                            .map(|j| {
                                let t = j as f64 / (m - 1) as f64;
                                let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                                Point3::new(c * x - s * y, s * x + c * y, z)
                            })
                            .collect()
                    })
                    .collect();
                SweptFace {
                    kind: FaceKind::Tip,
                    index: i,
                    rows,
                }
            })
            .collect();
        SectionSweep {
            outer,
            inner: Vec::new(),
            axis: Vector3::unit_z(),
            breaks: Vec::new(),
        }
    }

    #[test]
    fn a_twisted_prism_is_a_closed_solid_of_the_section_area_times_the_length() {
        let mut sweep = twisted_square(0.3, 21, 5);
        // Built clockwise: the builder turns it.
        reverse(&mut sweep.outer);
        let built = build(sweep).expect("closed");
        assert!(
            (built.mesh_volume_mm3 - 12.0).abs() < 1e-9,
            "{}",
            built.mesh_volume_mm3
        );
        assert_eq!(built.solid.face_iter().count(), 6);
    }

    #[test]
    fn simpson_integrates_cubics_exactly_with_even_and_odd_interval_counts() {
        let f = |x: f64| 2.0 * x * x * x - x * x + 3.0;
        let exact = |x: f64| 0.5 * x.powi(4) - x.powi(3) / 3.0 + 3.0 * x;
        for n in [2usize, 3, 4, 5, 8, 9] {
            let h = 1.7 / n as f64;
            let samples: Vec<f64> = (0..=n).map(|i| f(h * i as f64)).collect();
            let expected = exact(1.7) - exact(0.0);
            assert!(
                (simpson(&samples, h) - expected).abs() < 1e-12,
                "{n} intervals"
            );
        }
        // One interval: the trapezoid, exact for a line.
        assert!((simpson(&[1.0, 3.0], 0.5) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_loop_that_does_not_close_is_refused() {
        let mut sweep = twisted_square(0.0, 3, 3);
        sweep.outer[2].rows[1][0].x += 1e-3;
        let err = build(sweep).unwrap_err().to_string();
        assert!(err.contains("ends") && err.contains("station 1"), "{err}");
    }
}
