//! The wheel, its cutting and the operating mesh (MODEL §1, §3): the wheel blank and body, the
//! cutting and operating placements, and the relations between them (radial clearances, the face
//! width the worm can reach).

use super::*;

/// [cutting]: the hob's placement, SI; an invalid field is NaN (its error recorded).
pub(super) fn cutting_placement(ck: &mut Checker, c: &SettingSpec) -> Placement {
    let a = ck.positive(
        "cutting.centre_distance_mm",
        c.centre_distance_mm,
        10_000.0,
        "mm",
    );
    let offset = ck.range("cutting.offset_mm", c.offset_mm, -1000.0, 1000.0, "mm");
    let tilt = ck.range(
        "cutting.inclination_deg",
        c.inclination_deg,
        -20.0,
        20.0,
        "deg",
    );
    Placement {
        centre_distance: a.unwrap_or(f64::NAN) * MM,
        offset: offset.unwrap_or(f64::NAN) * MM,
        inclination: tilt.unwrap_or(f64::NAN) * DEG,
    }
}

/// [operating], checked field by field (SI; None where the field is invalid).
pub(super) struct OperatingParts {
    pub(super) nominal_centre_distance: Option<f64>,
    pub(super) centre_distance_error: Option<f64>,
    pub(super) worm_offset: Option<f64>,
    pub(super) inclination: Option<f64>,
    pub(super) rotation: Option<Rotation>,
}

impl OperatingParts {
    /// The operating placement: nominal centre distance plus its error.
    pub(super) fn placement(&self) -> Option<Placement> {
        Some(Placement {
            centre_distance: self.nominal_centre_distance? + self.centre_distance_error?,
            offset: self.worm_offset?,
            inclination: self.inclination?,
        })
    }
}

pub(super) fn operating_parts(ck: &mut Checker, o: &OperatingSpec) -> OperatingParts {
    let a = ck.positive(
        "operating.centre_distance_mm",
        o.centre_distance_mm,
        10_000.0,
        "mm",
    );
    let da = ck.range(
        "operating.centre_distance_error_mm",
        o.centre_distance_error_mm,
        -1.0,
        1.0,
        "mm",
    );
    let offset = ck.range(
        "operating.worm_offset_mm",
        o.worm_offset_mm,
        -5.0,
        5.0,
        "mm",
    );
    let tilt = ck.range(
        "operating.inclination_deg",
        o.inclination_deg,
        -2.0,
        2.0,
        "deg",
    );
    let rotation = ck.choice(
        "operating.worm_rotation",
        &o.worm_rotation,
        &[
            ("positive", Rotation::Positive),
            ("negative", Rotation::Negative),
        ],
    );
    OperatingParts {
        nominal_centre_distance: a.map(|v| v * MM),
        centre_distance_error: da.map(|v| v * MM),
        worm_offset: offset.map(|v| v * MM),
        inclination: tilt.map(|v| v * DEG),
        rotation,
    }
}

/// [wheel], checked field by field (SI; None where the field is invalid).
pub(super) struct WheelParts {
    pub(super) teeth: Option<u32>,
    pub(super) face_width: Option<f64>,
    pub(super) outer_radius: Option<f64>,
    pub(super) throat_radius: Option<f64>,
    pub(super) rim_thickness: Option<f64>,
    pub(super) web_thickness: Option<f64>,
    pub(super) hub_radius: Option<f64>,
    pub(super) shaft_radius: Option<f64>,
    pub(super) bearing_positions: Option<Vec<f64>>,
    pub(super) edge_relief: Option<EdgeRelief>,
    pub(super) face_edge_chamfer: Option<f64>,
}

impl WheelParts {
    /// The blank, when its required fields are valid.
    pub(super) fn blank(self) -> Option<WheelBlank> {
        Some(WheelBlank {
            teeth: self.teeth?,
            face_width: self.face_width?,
            outer_radius: self.outer_radius?,
            throat_radius: self.throat_radius?,
            rim_thickness: self.rim_thickness,
            web_thickness: self.web_thickness,
            hub_radius: self.hub_radius,
            shaft_radius: self.shaft_radius,
            bearing_positions: self.bearing_positions,
            edge_relief: self.edge_relief.unwrap_or(EdgeRelief::SHARP),
            face_edge_chamfer: self.face_edge_chamfer?,
        })
    }
}

pub(super) fn wheel_parts(ck: &mut Checker, w: &WheelSpec) -> WheelParts {
    let teeth = ck
        .int_range("wheel.teeth", w.teeth, 10, 500)
        .map(|v| v as u32);
    let length =
        |ck: &mut Checker, name: &str, v: f64| ck.positive(name, v, 5000.0, "mm").map(|x| x * MM);
    let face_width = ck
        .positive("wheel.face_width_mm", w.face_width_mm, 2000.0, "mm")
        .map(|v| v * MM);
    let outer_radius = length(ck, "wheel.outer_radius_mm", w.outer_radius_mm);
    let throat_radius = length(ck, "wheel.throat_radius_mm", w.throat_radius_mm);
    let optional =
        |ck: &mut Checker, name: &str, v: Option<f64>| v.and_then(|x| length(ck, name, x));
    let rim_thickness = optional(ck, "wheel.rim_thickness_mm", w.rim_thickness_mm);
    let web_thickness = optional(ck, "wheel.web_thickness_mm", w.web_thickness_mm);
    let hub_radius = optional(ck, "wheel.hub_radius_mm", w.hub_radius_mm);
    let shaft_radius = optional(ck, "wheel.shaft_radius_mm", w.shaft_radius_mm);
    let bearing_positions = w.bearing_positions_mm.as_ref().map(|v| {
        v.iter()
            .enumerate()
            .map(|(i, &x)| {
                let name = format!("wheel.bearing_positions_mm[{i}]");
                ck.range(&name, x, -5000.0, 5000.0, "mm")
                    .unwrap_or(f64::NAN)
                    * MM
            })
            .collect::<Vec<_>>()
    });
    if let (Some(re), Some(ra)) = (outer_radius, throat_radius) {
        if re < ra {
            let problem = format!("must be >= wheel.throat_radius_mm = {}", w.throat_radius_mm);
            ck.fail("wheel.outer_radius_mm", w.outer_radius_mm, problem);
        }
    }
    let edge_relief = face_width.and_then(|b| {
        edge_relief(
            ck,
            "wheel.edge_relief_um",
            w.edge_relief_um,
            "wheel.edge_relief_length_mm",
            w.edge_relief_length_mm,
            (0.25 * b, "a quarter of wheel.face_width_mm"),
        )
    });
    let face_edge_chamfer = face_edge_chamfer(ck, w.face_edge_chamfer_mm, face_width);
    if let (Some(hub), Some(sh)) = (hub_radius, shaft_radius) {
        if sh >= hub {
            let problem = format!(
                "must be < wheel.hub_radius_mm = {}",
                w.hub_radius_mm.unwrap_or_default()
            );
            ck.fail(
                "wheel.shaft_radius_mm",
                w.shaft_radius_mm.unwrap_or_default(),
                problem,
            );
        }
    }
    WheelParts {
        teeth,
        face_width,
        outer_radius,
        throat_radius,
        rim_thickness,
        web_thickness,
        hub_radius,
        shaft_radius,
        bearing_positions,
        edge_relief,
        face_edge_chamfer,
    }
}

/// The face-end chamfer's width (mm in, m out; MODEL §2.3): 0 when not given, at most a
/// quarter of the face width `face_width` (m).
fn face_edge_chamfer(ck: &mut Checker, given: Option<f64>, face_width: Option<f64>) -> Option<f64> {
    match (given, face_width) {
        (None, _) => Some(0.0),
        (Some(c), Some(b)) => {
            let most = 0.25 * b / MM;
            let unit = format!("mm (at most a quarter of wheel.face_width_mm, {most:.3} mm)");
            ck.range("wheel.face_edge_chamfer_mm", c, 0.0, most, &unit)
                .map(|c| c * MM)
        }
        (Some(_), None) => None,
    }
}

/// The blank's valid radii and the centre distance, SI.
pub(super) struct BlankRadii {
    pub(super) nominal_centre_distance: f64,
    pub(super) teeth: u32,
    pub(super) face_width: f64,
    pub(super) outer_radius: f64,
    pub(super) throat_radius: f64,
}

impl BlankRadii {
    pub(super) fn of(op: &OperatingParts, w: &WheelParts) -> Option<Self> {
        Some(Self {
            nominal_centre_distance: op.nominal_centre_distance?,
            teeth: w.teeth?,
            face_width: w.face_width?,
            outer_radius: w.outer_radius?,
            throat_radius: w.throat_radius?,
        })
    }
}

/// Worm, hob and blank together: what must fit for the wheel to be cut and to mesh.
pub(super) struct Mesh<'a> {
    pub(super) worm: &'a ThreadDef,
    pub(super) hob: &'a ThreadDef,
    pub(super) cutting: &'a Placement,
    pub(super) blank: BlankRadii,
    pub(super) worm_offset: Option<f64>,
    pub(super) throat_radius_mm: f64,
}

impl Mesh<'_> {
    pub(super) fn check(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        self.radial_clearances(ck, warnings);
        self.profile_shift(ck, warnings);
        if self.throat_in_range(ck) {
            self.face_width(ck);
        }
        let lead_diff = self.hob.lead_angle() - self.worm.lead_angle();
        if (lead_diff - self.cutting.inclination).abs() > 1.0 * DEG {
            warnings.push(format!(
                "hob lead angle differs from the worm's by {:.3} deg and the hob inclination is \
                 {:.3} deg: the wheel will have a lead mismatch",
                lead_diff / DEG,
                self.cutting.inclination / DEG
            ));
        }
    }

    /// The worm root clears the wheel throat; the hob root does not cut the blank's throat;
    /// the hob tip cuts the wheel root deep enough for the worm tip.
    pub(super) fn radial_clearances(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        let (wm, hb) = (self.worm, self.hob);
        let (an, ra) = (self.blank.nominal_centre_distance, self.blank.throat_radius);
        let a0 = self.cutting.centre_distance;
        if an - ra <= wm.root_radius {
            ck.fail(
                "wheel.throat_radius_mm",
                self.throat_radius_mm,
                format!(
                    "must be < operating.centre_distance_mm - worm.root_radius_mm = {:.6} mm \
                     (the wheel tip would hit the worm root)",
                    (an - wm.root_radius) / MM
                ),
            );
        }
        if !a0.is_finite() {
            return;
        }
        if a0 - ra < hb.root_radius {
            ck.fail(
                "hob.root_radius_mm",
                hb.root_radius / MM,
                format!(
                    "must be <= cutting.centre_distance_mm - wheel.throat_radius_mm = {:.6} mm \
                     (the hob root would cut the wheel tip)",
                    (a0 - ra) / MM
                ),
            );
        }
        let clearance = (an - wm.tip_radius) - (a0 - hb.tip_radius);
        if clearance < 0.0 {
            ck.fail(
                "hob.tip_radius_mm",
                hb.tip_radius / MM,
                format!(
                    "must be >= worm.tip_radius_mm + cutting.centre_distance_mm - \
                     operating.centre_distance_mm = {:.6} mm (the worm tip would hit the wheel \
                     root)",
                    (wm.tip_radius + a0 - an) / MM
                ),
            );
        }
        if hb.tip_radius < wm.tip_radius + a0 - an + 1e-9 && clearance >= 0.0 {
            warnings
                .push("no bottom clearance: the hob tip radius equals the worm tip radius".into());
        }
    }

    /// The centre distance must be consistent with the radii (implied wheel profile shift).
    pub(super) fn profile_shift(&self, ck: &mut Checker, warnings: &mut Vec<String>) {
        let wm = self.worm;
        let (an, ra) = (self.blank.nominal_centre_distance, self.blank.throat_radius);
        let r2 = self.blank.teeth as f64 * wm.axial_pitch / (2.0 * PI);
        let x2 = (an - wm.reference_radius - r2) / wm.axial_module();
        if x2.abs() > 1.5 {
            ck.fail(
                "operating.centre_distance_mm",
                an / MM,
                format!(
                    "inconsistent with worm.reference_radius_mm + wheel reference radius \
                     (wheel.teeth x axial module / 2 = {:.4} mm): the implied profile shift x2 = \
                     {:.3} is outside [-1.5, 1.5]",
                    r2 / MM,
                    x2
                ),
            );
        } else if x2.abs() > 1.0 {
            warnings.push(format!("large wheel profile shift x2 = {x2:.3}"));
        }
        if ra < r2 && ra >= self.lowest_throat() {
            warnings.push(format!(
                "wheel throat radius {:.3} mm is below the reference radius {:.3} mm",
                ra / MM,
                r2 / MM
            ));
        }
    }

    /// The lowest throat radius a wheel blank may have: two axial modules below the wheel's
    /// reference radius z2 m_x / 2 (a wheel tip below that cuts away the teeth).
    pub(super) fn lowest_throat(&self) -> f64 {
        let wm = self.worm;
        let r2 = self.blank.teeth as f64 * wm.axial_pitch / (2.0 * PI);
        r2 - 2.0 * wm.axial_module()
    }

    /// Whether the throat radius is at least [`Self::lowest_throat`]; else an error on it
    /// (and the face width, which the throat decides, is not checked).
    pub(super) fn throat_in_range(&self, ck: &mut Checker) -> bool {
        let (ra, lowest) = (self.blank.throat_radius, self.lowest_throat());
        if ra >= lowest {
            return true;
        }
        ck.fail(
            "wheel.throat_radius_mm",
            ra / MM,
            format!(
                "must be >= {:.3} mm: the wheel's tip (throat) radius is more than two axial \
                 modules below its reference radius z2 m_x / 2 = {:.3} mm",
                lowest / MM,
                (lowest + 2.0 * self.worm.axial_module()) / MM
            ),
        );
        false
    }

    /// The face width the worm can reach (at |z| = b/2 the blank top must be inside the worm
    /// tip cylinder), and the offsets inside it.
    pub(super) fn face_width(&self, ck: &mut Checker) {
        let bl = &self.blank;
        let b = bl.face_width;
        let gorge = bl.nominal_centre_distance - bl.throat_radius;
        let reach = reachable_half_width(
            bl.nominal_centre_distance,
            bl.outer_radius,
            gorge,
            self.worm.tip_radius,
        );
        if 0.5 * b >= reach {
            ck.fail(
                "wheel.face_width_mm",
                b / MM,
                format!(
                    "larger than the worm can reach: must be < {:.3} mm (twice the half-width \
                     at which the blank top, wheel.outer_radius_mm, leaves the worm tip \
                     cylinder, worm.tip_radius_mm)",
                    2.0 * reach / MM
                ),
            );
        }
        let inside = format!(
            "must be inside the face width: |offset| < {} mm",
            0.5 * b / MM
        );
        if let Some(off) = self.worm_offset.filter(|o| o.abs() >= 0.5 * b) {
            ck.fail("operating.worm_offset_mm", off / MM, inside.clone());
        }
        let off = self.cutting.offset;
        if off.is_finite() && off.abs() >= 0.5 * b {
            ck.fail("cutting.offset_mm", off / MM, inside);
        }
    }
}

/// The wheel body the bending model builds (rim, web, hub, shaft and its bearings), checked
/// with its defaults filled in: each part must fit inside the one around it.
pub(super) fn check_wheel_body(gear: &GearSet) -> Result<(), InputError> {
    let b = gear.wheel_body();
    let mut errors = Vec::new();
    let mut fail = |field: &str, value: f64, problem: String| {
        errors.push(FieldError {
            field: field.into(),
            value: format!("{:.4} mm", value / MM),
            problem,
        })
    };
    let r_in = b.rim_inner_radius();
    if r_in <= 0.0 {
        fail(
            "wheel.rim_thickness_mm",
            b.rim_thickness,
            format!("must be < the root radius {:.4} mm", b.root_radius / MM),
        );
    } else if b.hub_radius >= r_in {
        fail(
            "wheel.hub_radius_mm",
            b.hub_radius,
            format!(
                "must be < the rim's inner radius (root radius - rim thickness) = {:.4} mm",
                r_in / MM
            ),
        );
    }
    if b.shaft_radius >= b.hub_radius {
        fail(
            "wheel.shaft_radius_mm",
            b.shaft_radius,
            format!("must be < the hub radius {:.4} mm", b.hub_radius / MM),
        );
    }
    if b.web_thickness > gear.wheel.face_width {
        fail(
            "wheel.web_thickness_mm",
            b.web_thickness,
            format!(
                "must be <= the face width (wheel.face_width_mm) {} mm",
                Number(gear.wheel.face_width / MM)
            ),
        );
    }
    match gear.wheel.bearing_positions.as_deref() {
        Some(v) if v.len() != 2 => errors.push(FieldError {
            field: "wheel.bearing_positions_mm".into(),
            value: format!("{:?}", v.iter().map(|x| x / MM).collect::<Vec<_>>()),
            problem: "must hold two positions (the laterally holding bearing, then the fixed end)"
                .into(),
        }),
        _ => {
            let [a, c] = b.bearings;
            let h = b.hub_half_width;
            if !(a.min(c) < -h && a.max(c) > h) {
                errors.push(FieldError {
                    field: "wheel.bearing_positions_mm".into(),
                    value: format!("[{:.4}, {:.4}]", a / MM, c / MM),
                    problem: format!(
                        "need one bearing on each side of the hub, beyond +/- {:.4} mm (half the \
                         face width)",
                        h / MM
                    ),
                });
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(InputError::Invalid(errors))
    }
}

/// Internal consistency guard: a missing value without a recorded error is a bug, reported as
/// an error rather than a panic.
pub(super) fn unreachable_input<T>() -> Result<T, InputError> {
    Err(InputError::Invalid(vec![FieldError {
        field: "(internal)".into(),
        value: "-".into(),
        problem: "validation lost a value without reporting why; please report this file".into(),
    }]))
}

/// Largest |z| at which the wheel blank top (outer cylinder clipped by the throat torus) is
/// still inside the worm tip cylinder of radius `tip` (worm axis at distance `a`). m.
pub(super) fn reachable_half_width(a: f64, outer: f64, gorge: f64, tip: f64) -> f64 {
    let top_distance = |z: f64| {
        let r_top = if z.abs() < gorge {
            outer.min(a - (gorge * gorge - z * z).sqrt())
        } else {
            outer
        };
        ((a - r_top).powi(2) + z * z).sqrt()
    };
    if top_distance(0.0) >= tip {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, tip);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if top_distance(mid) < tip {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}
