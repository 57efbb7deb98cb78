//! Stage 1 — gear geometry (MODEL §2-3): worm and hob thread surfaces from their tools, wheel
//! flanks from a simulation of hobbing, on the global flank grid.
//!
//! [`Geometry::build`] is the entry point; its result is a plain struct the next stages read.

pub mod hobbing;
mod memo;
pub mod placement;
pub mod profile;
pub mod roots;
pub mod rows;
pub mod sections;
pub mod stl;
pub mod thread;
pub mod wheel;

use crate::input::{GearSet, Placement, ProfileType, ThreadDef, WheelBlank};
pub use hobbing::{EnvelopePoint, Hobbing, PointKind};
pub use thread::{Flank, ThreadSurface};
pub use wheel::{BlankLimits, FlankField, FlankPoint, WheelFlank};

/// Why the geometry could not be built from a (validated) gear set.
#[derive(Debug, Clone, thiserror::Error)]
pub enum GeometryError {
    #[error("thread profile: {0}")]
    Profile(String),
    #[error("wheel generation: {0}")]
    Wheel(String),
}

/// Worm, hob and wheel flanks of a gear set.
#[derive(Debug, Clone)]
pub struct Geometry {
    pub worm: ThreadSurface,
    pub hob: ThreadSurface,
    /// Wheel flanks of the reference tooth space: index 0 mates with the worm's left flank,
    /// index 1 with its right flank.
    pub wheel_flanks: [WheelFlank; 2],
    pub blank: BlankLimits,
    /// Number of wheel teeth.
    pub teeth: u32,
}

/// What to change when the hob does not generate the wheel blank (MODEL §3.2): where the blank
/// lies well below the hob's reach at the throat (the centre distance moved, the blank did
/// not), the throat and outer radii that follow the cutting centre distance; else the inputs
/// that shape the envelope and the direction that brings the blank inside it.
fn blank_fit(inputs: &GeometryInputs) -> String {
    let mm = 1e3;
    let reach = inputs.cutting.centre_distance - inputs.hob.root_radius;
    let below = reach - inputs.wheel.throat_radius;
    // The examples' blanks sit 0.01 mm below the hob's root; half a millimetre is a blank
    // left behind by a changed centre distance.
    if below > 0.5e-3 {
        let throat = reach - 0.01e-3;
        return format!(
            "the wheel blank does not follow the cutting centre distance: the hob's root reaches \
             r = {:.2} mm at the throat (cutting.centre_distance_mm - hob.root_radius_mm), \
             {:.2} mm above wheel.throat_radius_mm = {:.2}; a changed centre distance moves the \
             wheel's teeth with it: raise wheel.throat_radius_mm to about {:.2} mm and \
             wheel.outer_radius_mm by as much (to about {:.2} mm), or keep the centre distance \
             and change the worm and the hob instead",
            reach * mm,
            below * mm,
            inputs.wheel.throat_radius * mm,
            throat * mm,
            (inputs.wheel.outer_radius + throat - inputs.wheel.throat_radius) * mm
        );
    }
    "the blank must lie inside the region the hob envelops: lower wheel.outer_radius_mm or \
     wheel.face_width_mm, or check the hob against the wheel ([hob] starts, lead_mm, \
     tip_radius_mm and pressure angle; [cutting] centre_distance_mm, offset_mm and \
     inclination_deg; wheel.teeth)"
        .to_string()
}

/// What the geometry is generated from: the parts of a gear set that shape the flanks (its
/// conditions, materials, lubricant, life and the other analysis settings do not), and the
/// flank grid. [`Geometry::generate`] reads nothing else, so equal inputs give the same
/// geometry, which is what lets [`Geometry::build_with_grid`] reuse a recent one.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GeometryInputs {
    pub worm: ThreadDef,
    pub hob: ThreadDef,
    /// The hob's placement when it cut the wheel.
    pub cutting: Placement,
    /// The worm's placement in operation (where its tip reaches the wheel flank).
    pub operating: Placement,
    pub wheel: WheelBlank,
    /// Nominal centre distance a, m (with the throat radius, the blank's gorge radius).
    pub nominal_centre_distance: f64,
    /// Node rows of the band above the worm-tip trace (`analysis.tip_trace_refinement`).
    pub tip_trace_refinement: usize,
    /// Cells of the global flank grid along the height and along the face width.
    pub cells_height: usize,
    pub cells_face: usize,
}

impl GeometryInputs {
    /// The geometry inputs of `gear` with the grid `cells_height` x `cells_face`.
    pub fn of(gear: &GearSet, cells_height: usize, cells_face: usize) -> Self {
        Self {
            worm: gear.worm.clone(),
            hob: gear.hob.clone(),
            cutting: gear.cutting,
            operating: gear.operating,
            wheel: gear.wheel.clone(),
            nominal_centre_distance: gear.nominal_centre_distance,
            tip_trace_refinement: gear.analysis.tip_trace_refinement,
            cells_height,
            cells_face,
        }
    }
}

impl Geometry {
    /// Builds all flanks with the grid of the gear set's analysis settings.
    pub fn build(gear: &GearSet) -> Result<Self, GeometryError> {
        Self::build_with_grid(
            gear,
            gear.analysis.flank_cells_height,
            gear.analysis.flank_cells_face,
        )
    }

    /// Builds all flanks with an explicit grid (cells along the height and the face width):
    /// a copy of the geometry of one of the last few builds with equal [`GeometryInputs`]
    /// (a variant of the gear in its conditions, materials or lubricant, a Python session
    /// running the same gear again), else [`Self::generate`]d and kept.
    pub fn build_with_grid(
        gear: &GearSet,
        cells_height: usize,
        cells_face: usize,
    ) -> Result<Self, GeometryError> {
        let inputs = GeometryInputs::of(gear, cells_height, cells_face);
        if let Some(kept) = memo::recall(&inputs) {
            return Ok(kept);
        }
        let geometry = Self::generate(&inputs)?;
        memo::keep(&inputs, &geometry);
        Ok(geometry)
    }

    /// Generates worm, hob and wheel flanks from `inputs` (MODEL §2-3), every time.
    pub fn generate(inputs: &GeometryInputs) -> Result<Self, GeometryError> {
        let (cells_height, cells_face) = (inputs.cells_height, inputs.cells_face);
        let thread_hint = |member: &'static str| {
            move |e: GeometryError| {
                match e {
                GeometryError::Profile(m) => GeometryError::Profile(format!(
                    "{member}: {m}; the inputs that shape it: [{member}] profile, starts, \
                     lead_mm or axial_module_mm, pressure_angle_deg with pressure_angle_plane, \
                     root_radius_mm and tip_radius_mm (an involute worm's base radius must lie below its root; a \
                     K or C worm's grinding wheel, or profile radius, must reach the root)"
                )),
                other => other,
            }
            }
        };
        let worm = ThreadSurface::new(&inputs.worm).map_err(thread_hint("worm"))?;
        let hob = ThreadSurface::new(&inputs.hob).map_err(thread_hint("hob"))?;
        let blank = BlankLimits {
            face_width: inputs.wheel.face_width,
            outer_radius: inputs.wheel.outer_radius,
            gorge_radius: inputs.nominal_centre_distance - inputs.wheel.throat_radius,
            centre_distance: inputs.nominal_centre_distance,
        };
        let hobbing = Hobbing::new(&hob, inputs.cutting, inputs.wheel.teeth);
        let wheel_hint = |e: GeometryError| match e {
            GeometryError::Wheel(m) => GeometryError::Wheel(format!("{m}; {}", blank_fit(inputs))),
            other => other,
        };
        let worm_cut = Hobbing::new(&worm, inputs.operating, inputs.wheel.teeth);
        let refinement = inputs.tip_trace_refinement;
        let frame = |flank: Flank| {
            let strip = worm_edge_strip(&worm, flank, &inputs.worm);
            let reach =
                |z: f64, foot: f64, top: f64| worm_reach(&worm_cut, flank, z, (foot, top), strip);
            wheel::FlankFrame::new(
                &hobbing,
                flank,
                &blank,
                (cells_height, cells_face),
                &reach,
                refinement,
            )
        };
        let frames = [
            frame(Flank::Left).map_err(wheel_hint)?,
            frame(Flank::Right).map_err(wheel_hint)?,
        ];
        let knots: Vec<_> = frames
            .iter()
            .flat_map(|f| f.columns.iter().chain(&f.mids))
            .copied()
            .collect();
        let plan = rows::RowPlan::of(&knots, cells_height, refinement);
        let generate =
            |f: &wheel::FlankFrame| wheel::generate_flank(&hobbing, f, &plan, cells_height);
        let left = generate(&frames[0]).map_err(wheel_hint)?;
        let right = generate(&frames[1]).map_err(wheel_hint)?;
        Ok(Self {
            worm,
            hob,
            wheel_flanks: [left, right],
            blank,
            teeth: inputs.wheel.teeth,
        })
    }

    /// The wheel flank that mates with the worm's `flank`.
    pub fn wheel_flank(&self, flank: Flank) -> &WheelFlank {
        match flank {
            Flank::Left => &self.wheel_flanks[0],
            Flank::Right => &self.wheel_flanks[1],
        }
    }

    /// The hobbing set-up this geometry was generated with.
    pub fn hobbing<'a>(&'a self, gear: &GearSet) -> Hobbing<'a> {
        Hobbing::new(&self.hob, gear.cutting, self.teeth)
    }
}

/// The worm's radial height, from its tip down, of the strip its broken tip edge (MODEL §2.3:
/// R (1 - sin psi), psi the axial profile's angle at the tip) or its tip relief (its length)
/// sweeps on `flank`, m; 0 for a sharp, unrelieved tip.
fn worm_edge_strip(worm: &ThreadSurface, flank: Flank, def: &ThreadDef) -> f64 {
    let edge = def.tip_edge_radius * (1.0 - worm.tip_profile_angle(flank).sin());
    let relief = &def.tip_relief;
    edge.max(if relief.amount > 0.0 {
        relief.length
    } else {
        0.0
    })
}

/// Where the worm at its operating placement (`worm_cut`: the worm as a hob) reaches the
/// wheel's node column at z between its foot and top: the worm-tip trace (the lowest radius
/// the worm's flank generates) and the top of the strip of height `strip` below the worm's tip
/// (the wheel radius whose generating point lies at the worm radius r_a - strip), m. None
/// where the worm does not reach the column's top.
fn worm_reach(
    worm_cut: &Hobbing,
    flank: Flank,
    z: f64,
    (foot, top): (f64, f64),
    strip: f64,
) -> Option<rows::WormReach> {
    let trace = worm_cut.radial_limits(flank, z, top).ok()?.0.max(foot);
    if strip <= 0.0 {
        return Some(rows::WormReach {
            trace,
            strip_top: trace,
        });
    }
    let edge_start = worm_cut.hob.def.tip_radius - strip;
    let above_edge = |r: f64| {
        let e = worm_cut.envelope(flank, r, z);
        e.kind == PointKind::Flank && e.hob_radius <= edge_start
    };
    let (mut lo, mut hi) = (trace, top);
    if !above_edge(hi) {
        return Some(rows::WormReach {
            trace,
            strip_top: top,
        });
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if above_edge(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(rows::WormReach {
        trace,
        strip_top: hi,
    })
}

/// Derived quantities reported by `check` and in `summary.json` (units in the names).
#[derive(Debug, Clone, serde::Serialize)]
pub struct GeometrySummary {
    pub worm_profile: ProfileType,
    pub starts: u32,
    pub teeth: u32,
    pub ratio: f64,
    pub lead_mm: f64,
    pub lead_angle_deg: f64,
    pub axial_module_mm: f64,
    pub normal_module_mm: f64,
    /// Measured on the worm surface at the reference radius (left flank).
    pub axial_pressure_angle_deg: f64,
    pub normal_pressure_angle_deg: f64,
    /// Base radius (profile I only).
    pub base_radius_mm: Option<f64>,
    pub worm_reference_radius_mm: f64,
    pub worm_tip_thickness_axial_mm: f64,
    pub wheel_reference_radius_mm: f64,
    pub wheel_profile_shift: f64,
    /// Throat (tip) radius r_a2 at the median plane.
    pub throat_radius_mm: f64,
    /// Gorge radius r_g = a - r_a2 of the tip torus.
    pub gorge_radius_mm: f64,
    pub outer_radius_mm: f64,
    pub face_width_mm: f64,
    /// Wheel root radius at the median plane, a0 - r_a0.
    pub wheel_root_radius_mm: f64,
    /// Bottom clearance between worm tip and wheel root at the median plane (operating).
    pub bottom_clearance_mm: f64,
    pub centre_distance_mm: f64,
    pub cutting_centre_distance_mm: f64,
    pub hob_lead_angle_deg: f64,
    /// Sliding speed at the pitch point, r1 omega1 / cos(gamma) (MODEL §4.5).
    pub pitch_sliding_speed_m_s: f64,
    /// Active flank area of the flank loaded by the operating rotation (whole grid).
    pub active_flank_area_mm2: f64,
    pub active_flank_area_left_mm2: f64,
    pub active_flank_area_right_mm2: f64,
    /// Lowest and highest radius of the active flank (over the face width).
    pub active_flank_min_radius_mm: f64,
    pub active_flank_max_radius_mm: f64,
    pub flank_cells_height: usize,
    pub flank_cells_face: usize,
    pub warnings: Vec<String>,
}

impl GeometrySummary {
    /// Derived data of a gear set and its built geometry.
    pub fn new(gear: &GearSet, geo: &Geometry) -> Self {
        let deg = 180.0 / std::f64::consts::PI;
        let w = &geo.worm;
        let r1 = gear.worm.reference_radius;
        let gamma = gear.worm.lead_angle();
        let loaded = match gear.rotation {
            crate::input::Rotation::Positive => Flank::Left,
            crate::input::Rotation::Negative => Flank::Right,
        };
        let [l, r] = &geo.wheel_flanks;
        let fold = |f: fn(f64, f64) -> f64, init: f64, v: &[f64]| v.iter().copied().fold(init, f);
        let min_r =
            fold(f64::min, f64::INFINITY, &l.r_low).min(fold(f64::min, f64::INFINITY, &r.r_low));
        let max_r = fold(f64::max, 0.0, &l.r_high).max(fold(f64::max, 0.0, &r.r_high));
        let root2 = gear.cutting.centre_distance - gear.hob.tip_radius;
        Self {
            worm_profile: gear.worm.profile,
            starts: gear.worm.starts,
            teeth: gear.wheel.teeth,
            ratio: gear.ratio(),
            lead_mm: gear.worm.lead() * 1e3,
            lead_angle_deg: gamma * deg,
            axial_module_mm: gear.worm.axial_module() * 1e3,
            normal_module_mm: gear.worm.axial_module() * gamma.cos() * 1e3,
            axial_pressure_angle_deg: w.axial_pressure_angle_at(r1) * deg,
            normal_pressure_angle_deg: w.normal_pressure_angle_at(r1) * deg,
            base_radius_mm: (gear.worm.profile == ProfileType::I)
                .then(|| gear.worm.base_radius() * 1e3),
            worm_reference_radius_mm: r1 * 1e3,
            worm_tip_thickness_axial_mm: w.axial_thickness_at(gear.worm.tip_radius) * 1e3,
            wheel_reference_radius_mm: gear.wheel_reference_radius() * 1e3,
            wheel_profile_shift: (gear.nominal_centre_distance
                - r1
                - gear.wheel_reference_radius())
                / gear.worm.axial_module(),
            throat_radius_mm: gear.wheel.throat_radius * 1e3,
            gorge_radius_mm: gear.gorge_radius() * 1e3,
            outer_radius_mm: gear.wheel.outer_radius * 1e3,
            face_width_mm: gear.wheel.face_width * 1e3,
            wheel_root_radius_mm: root2 * 1e3,
            bottom_clearance_mm: (gear.operating.centre_distance - gear.worm.tip_radius - root2)
                * 1e3,
            centre_distance_mm: gear.operating.centre_distance * 1e3,
            cutting_centre_distance_mm: gear.cutting.centre_distance * 1e3,
            hob_lead_angle_deg: gear.hob.lead_angle() * deg,
            pitch_sliding_speed_m_s: r1 * gear.conditions.worm_speed / gamma.cos(),
            active_flank_area_mm2: geo.wheel_flank(loaded).active_area() * 1e6,
            active_flank_area_left_mm2: l.active_area() * 1e6,
            active_flank_area_right_mm2: r.active_area() * 1e6,
            active_flank_min_radius_mm: min_r * 1e3,
            active_flank_max_radius_mm: max_r * 1e3,
            flank_cells_height: l.cells_height,
            flank_cells_face: l.cells_face,
            warnings: gear.warnings.clone(),
        }
    }
}
