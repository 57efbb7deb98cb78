//! CAD solids of the worm and the wheel, new and worn, as STEP files (ISO 10303-21, AP214
//! "automotive_design" context, written by truck-stepio), in millimetres in the worm frame of
//! MODEL §1 (x1 along the worm axis, the wheel centre at y1 = a): the two files assemble at the
//! operating centre distance, worm and wheel at rotation 0.
//!
//! Each part is swept through parallel sections ([`section_solid`]): the worm through
//! transverse sections along its axis over the body length the wheel can reach (threads on the
//! root cylinder), the wheel through transverse sections across its face width (flanks, fillets
//! and root lands cut by the hob, the blank top, and the rim down to its inner radius). The
//! flanks are bicubic B-splines interpolating the computed flank points; the fit's deviation is
//! measured at computed points between the interpolated ones ([`FitCheck`]).

pub mod bspline;
pub mod section_solid;
pub mod wheel;
pub mod worm;

use crate::geometry::GeometryError;
use section_solid::{FaceKind, SweptSolid};
use truck_modeling::{EuclideanSpace, InnerSpace, Point3};
use truck_stepio::out::{CompleteStepDisplay, StepHeaderDescriptor, StepModel};

/// Why a CAD solid could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CadError {
    #[error("CAD solid: {0}")]
    Build(String),
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    #[error("{0}")]
    Request(String),
}

/// Computed flank points that the fit did not use, to measure its deviation: `face` indexes the
/// part's lateral faces (before [`SweptSolid::map_check`]: the piece of the outer loop in
/// `band`), `hint` is a parameter near each point.
#[derive(Debug, Clone, Default)]
pub struct FitCheck {
    pub face: usize,
    pub band: usize,
    pub points: Vec<(Point3, (f64, f64))>,
}

/// A part ready to write: the solid, the checks of its flank fit and its volume computed
/// from the sections (worm: the section's area times the length; wheel: the sections' areas
/// integrated across the face width), mm^3.
#[derive(Debug, Clone)]
pub struct CadPart {
    pub built: SweptSolid,
    pub checks: Vec<FitCheck>,
    pub volume_mm3: f64,
}

/// Area and centroid of one lateral face, integrated on its B-spline surface. mm^2, mm.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FaceSummary {
    pub kind: FaceKind,
    pub index: usize,
    /// Band between the splits along the sweep ([`section_solid::SectionSweep::breaks`]).
    pub band: usize,
    pub area_mm2: f64,
    pub centroid_mm: [f64; 3],
}

/// What the summary says about one written part.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PartSummary {
    pub file: String,
    pub faces: usize,
    /// Volume from the sections ([`CadPart::volume_mm3`]), mm^3.
    pub volume_mm3: f64,
    /// Sum of the left / right flank faces' areas on the B-spline surfaces, mm^2.
    pub flank_area_left_mm2: f64,
    pub flank_area_right_mm2: f64,
    /// Largest distance from a computed flank point (not interpolated) to the flank surface, um.
    pub max_fit_deviation_um: f64,
    pub fit_check_points: usize,
    /// Every lateral face (for `cad_faces.csv`; not in summary.json).
    #[serde(skip)]
    pub face_list: Vec<FaceSummary>,
}

/// Gauss-Legendre nodes and weights on [0, 1], two per knot span in each direction.
const GAUSS: [(f64, f64); 2] = [
    (0.211_324_865_405_187_1, 0.5),
    (0.788_675_134_594_812_9, 0.5),
];

/// Area (mm^2) and centroid (mm) of a B-spline surface: sum of |S_u x S_v| by two-point Gauss
/// rules on every knot span.
pub fn surface_area(surface: &truck_modeling::BSplineSurface<Point3>) -> (f64, [f64; 3]) {
    let local = bspline::LocalSurface::new(surface);
    let [su, sv] = local.spans();
    let (mut area, mut moment) = (0.0, truck_modeling::Vector3::new(0.0, 0.0, 0.0));
    for &(u0, u1) in &su {
        for &(v0, v1) in &sv {
            for (gu, wu) in GAUSS {
                for (gv, wv) in GAUSS {
                    let (u, v) = (u0 + (u1 - u0) * gu, v0 + (v1 - v0) * gv);
                    let (p, s_u, s_v) = local.eval(u, v);
                    let da = s_u.cross(s_v).magnitude() * wu * wv * (u1 - u0) * (v1 - v0);
                    area += da;
                    moment += p.to_vec() * da;
                }
            }
        }
    }
    let c = moment / area;
    (area, [c.x, c.y, c.z])
}

impl CadPart {
    /// Area and centroid of every lateral face.
    pub fn face_summaries(&self) -> Vec<FaceSummary> {
        use rayon::prelude::*;
        self.built
            .faces
            .par_iter()
            .map(|f| {
                let (area_mm2, centroid_mm) = surface_area(&f.surface);
                FaceSummary {
                    kind: f.kind,
                    index: f.index,
                    band: f.band,
                    area_mm2,
                    centroid_mm,
                }
            })
            .collect()
    }

    /// Largest distance from the check points to their flank surface, mm.
    pub fn max_fit_deviation_mm(&self) -> f64 {
        self.fit_deviations_mm()
            .iter()
            .map(|d| d.0)
            .fold(0.0, f64::max)
    }

    /// Per check: the largest distance from its points to their flank surface (mm) and the
    /// point where it occurs.
    pub fn fit_deviations_mm(&self) -> Vec<(f64, Point3)> {
        use rayon::prelude::*;
        self.checks
            .par_iter()
            .map(|check| {
                let surface = bspline::LocalSurface::new(&self.built.faces[check.face].surface);
                check
                    .points
                    .iter()
                    .map(|&(p, hint)| (surface.distance(p, hint), p))
                    .fold((0.0, Point3::new(0.0, 0.0, 0.0)), |a, b| {
                        if b.0 > a.0 {
                            b
                        } else {
                            a
                        }
                    })
            })
            .collect()
    }

    /// The summary of this part written as `file`.
    pub fn summary(&self, file: &str) -> PartSummary {
        let faces = self.face_summaries();
        let area = |kind| {
            faces
                .iter()
                .filter(|f| f.kind == kind)
                .map(|f| f.area_mm2)
                .sum()
        };
        PartSummary {
            file: file.to_string(),
            faces: self.built.solid.face_iter().count(),
            volume_mm3: self.volume_mm3,
            flank_area_left_mm2: area(FaceKind::FlankLeft),
            flank_area_right_mm2: area(FaceKind::FlankRight),
            max_fit_deviation_um: self.max_fit_deviation_mm() * 1e3,
            fit_check_points: self.checks.iter().map(|c| c.points.len()).sum(),
            face_list: faces,
        }
    }

    /// The STEP text of the part, the product named `name`. Two lines of truck-stepio's output
    /// are rewritten: its FILE_NAME header nests the author and organisation lists one level
    /// too deep (OpenCASCADE reports unresolved references) and its PRODUCT has no name. The
    /// time stamp is fixed so that the same input gives the same file byte for byte.
    pub fn step_text(&self, name: &str) -> Result<String, CadError> {
        let compressed = self.built.solid.compress();
        let text = CompleteStepDisplay::new(
            StepModel::from(&compressed),
            StepHeaderDescriptor::default(),
        )
        .to_string();
        let name = name.replace('\'', "");
        let file_name = format!(
            "FILE_NAME('{name}.step', '2000-01-01T00:00:00', (''), (''), 'truck-stepio', \
             'wormwear {}', '');",
            env!("CARGO_PKG_VERSION")
        );
        let product = format!("#7 = PRODUCT('{name}','{name}','', (#8));");
        let mut replaced = 0;
        let lines: Vec<String> = text
            .lines()
            .map(|line| {
                if line.starts_with("FILE_NAME(") {
                    replaced += 1;
                    file_name.clone()
                } else if line.starts_with("#7 = PRODUCT(") {
                    replaced += 1;
                    product.clone()
                } else {
                    line.to_string()
                }
            })
            .collect();
        if replaced != 2 {
            return Err(CadError::Build(
                "the STEP writer's header is not the expected one (FILE_NAME, #7 PRODUCT)".into(),
            ));
        }
        Ok(lines.join("\n") + "\n")
    }
}

/// The CAD solids a run asks for: the wheel's tooth count (None: all) and, after a life, the
/// wear step of the map state whose worn wheel is written (None: the last state).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CadRequest {
    pub teeth: Option<usize>,
    pub state: Option<usize>,
}

impl CadRequest {
    /// Checks the tooth count against the wheel's `teeth` before any work.
    pub fn check(&self, teeth: u32) -> Result<(), CadError> {
        match self.teeth {
            Some(n) if n == 0 || n > teeth as usize => Err(CadError::Request(format!(
                "the wheel's tooth count for the STEP file is {n}, allowed 1 to {teeth} (the \
                 wheel's teeth)"
            ))),
            _ => Ok(()),
        }
    }
}

/// The worn state a worn wheel shows: its wear step and wheel cycles.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WornFrom {
    pub step: usize,
    pub cycles: f64,
}

/// The solids of a run: worm and wheel as built, and the worn wheel after a life.
#[derive(Debug, Clone)]
pub struct CadSolids {
    pub worm: CadPart,
    pub wheel: CadPart,
    pub worn: Option<(WornFrom, CadPart)>,
}

/// Builds the solids of `request`; `worn` is the life's state to show: which state, the loaded
/// flank and its change on the flank grid (wear, pits and plastic set, normal depth, m).
pub fn solids(
    gear: &crate::input::GearSet,
    geo: &crate::geometry::Geometry,
    request: CadRequest,
    worn: Option<(
        WornFrom,
        crate::geometry::Flank,
        &crate::geometry::FlankField,
    )>,
) -> Result<CadSolids, CadError> {
    request.check(geo.teeth)?;
    let teeth = request.teeth;
    let worm = worm::worm_part(gear, geo)?;
    let wheel = wheel::wheel_part(
        gear,
        geo,
        wheel::WheelRequest {
            teeth,
            change: None,
        },
    )?;
    let worn = match worn {
        Some((from, flank, change)) => {
            let change = Some((flank, change));
            let part = wheel::wheel_part(gear, geo, wheel::WheelRequest { teeth, change })?;
            Some((from, part))
        }
        None => None,
    };
    Ok(CadSolids { worm, wheel, worn })
}
