//! The shafts and their bearings (`shaft`, `*_bearing`, coordinate systems): the frames, the
//! bearing positions of both shafts and the bending section of the gear file.

use super::*;

/// A frame: origin (mm) and unit axes u, v, w, in the gear unit's coordinates.
#[derive(Clone, Copy)]
pub(super) struct Frame {
    pub(super) origin: [f64; 3],
    pub(super) axes: [[f64; 3]; 3],
}

impl Frame {
    const GLOBAL: Frame = Frame {
        origin: [0.0; 3],
        axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    pub(super) fn point(&self, p: [f64; 3]) -> [f64; 3] {
        let mut q = self.origin;
        for (i, axis) in self.axes.iter().enumerate() {
            for k in 0..3 {
                q[k] += p[i] * axis[k];
            }
        }
        q
    }

    pub(super) fn direction(&self, d: [f64; 3]) -> [f64; 3] {
        let o = Frame {
            origin: [0.0; 3],
            ..*self
        };
        o.point(d)
    }
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(a, a).sqrt();
    (n > 1e-12).then(|| a.map(|x| x / n))
}

/// The frame a component's position attributes are given in: that of its
/// `reference_component_for_position` (resolved through the chain), else the global one.
pub(super) fn reference_frame(
    reader: &Reader,
    c: &Component,
    depth: usize,
) -> Result<Frame, RexsError> {
    let Some(r) = c.attribute("reference_component_for_position") else {
        return Ok(Frame::GLOBAL);
    };
    reader.mark(c, "reference_component_for_position");
    let id = match &r.value {
        Value::Reference(id) => Some(*id),
        Value::Integer(i) => u64::try_from(*i).ok(),
        Value::Text(s) => s.trim().parse().ok(),
        _ => None,
    };
    match id.and_then(|id| reader.model.component(id)) {
        Some(rc) if rc.id != c.id && depth < 8 => own_frame(reader, rc, depth + 1),
        _ => Ok(Frame::GLOBAL),
    }
}

/// A component's own frame (support vector and axes) in global coordinates.
pub(super) fn own_frame(reader: &Reader, c: &Component, depth: usize) -> Result<Frame, RexsError> {
    let parent = reference_frame(reader, c, depth)?;
    let origin = reader.vector(c, "support_vector")?.unwrap_or([0.0; 3]);
    let u = reader
        .vector(c, "u_axis_vector")?
        .and_then(unit)
        .unwrap_or([1.0, 0.0, 0.0]);
    let w0 = reader
        .vector(c, "w_axis_vector")?
        .and_then(unit)
        .unwrap_or([0.0, 0.0, 1.0]);
    let v = unit(cross(w0, u)).unwrap_or([0.0, 1.0, 0.0]);
    let w = cross(u, v);
    Ok(Frame {
        origin: parent.point(origin),
        axes: [
            parent.direction(u),
            parent.direction(v),
            parent.direction(w),
        ],
    })
}

/// Where the stage's axes are: worm centre and axis, wheel centre and axis (global, mm).
pub(super) struct Axes {
    pub(super) worm_centre: [f64; 3],
    pub(super) x1: [f64; 3],
    pub(super) wheel_centre: [f64; 3],
    pub(super) z2: [f64; 3],
}

pub(super) fn stage_axes(reader: &Reader, parts: &Parts) -> Result<Option<Axes>, RexsError> {
    let has_position = |c: &Component| c.attribute("support_vector").is_some();
    if !has_position(parts.worm) || !has_position(parts.wheel) {
        return Ok(None);
    }
    let worm = own_frame(reader, parts.worm, 0)?;
    let wheel = own_frame(reader, parts.wheel, 0)?;
    let x1 = match parts.worm_shaft {
        Some(s) => own_frame(reader, s, 0)?.axes[0],
        None => worm.axes[0],
    };
    let line = sub(wheel.origin, worm.origin);
    let Some(y1) = unit(sub(line, x1.map(|x| x * dot(line, x1)))) else {
        return Ok(None);
    };
    Ok(Some(Axes {
        worm_centre: worm.origin,
        x1,
        wheel_centre: wheel.origin,
        z2: cross(x1, y1),
    }))
}

/// A bearing's centre (global, mm): its support vector, else its u coordinate on the shaft.
pub(super) fn bearing_point(
    reader: &Reader,
    b: &Component,
    shaft: Option<&Component>,
) -> Result<Option<[f64; 3]>, RexsError> {
    if b.attribute("support_vector").is_some() {
        let frame = reference_frame(reader, b, 0)?;
        return Ok(reader.vector(b, "support_vector")?.map(|p| frame.point(p)));
    }
    let u = match reader.number(b, "u_coordinate_on_shaft_inner_side", Quantity::Length)? {
        Some(u) => Some(u),
        None => reader.number(b, "u_coordinate_on_shaft", Quantity::Length)?,
    };
    match (u, shaft) {
        (Some(u), Some(s)) => Ok(Some(own_frame(reader, s, 0)?.point([u, 0.0, 0.0]))),
        _ => Ok(None),
    }
}

/// The load point of a shaft (the torque's external_load), global mm.
pub(super) fn load_point(
    reader: &Reader,
    loads: &[&Component],
    shaft: Option<&Component>,
) -> Result<Option<[f64; 3]>, RexsError> {
    let Some(s) = shaft else { return Ok(None) };
    for l in loads {
        if l.attribute("torque_around_u_axis").is_some() || l.attribute("defines_torque").is_some()
        {
            if let Some(u) = reader.number(l, "u_coordinate_on_shaft", Quantity::Length)? {
                return Ok(Some(own_frame(reader, s, 0)?.point([u, 0.0, 0.0])));
            }
        }
    }
    Ok(None)
}

/// [bending]: FE bending with the worm's body length, shaft radius and bearing positions;
/// then the wheel's shaft radius and bearings ([`wheel_support`]).
pub(super) fn bending(
    reader: &Reader,
    parts: &Parts,
    worm: &Worm,
    wheel: &Wheel,
    out: &mut GearText,
) -> Result<(), RexsError> {
    out.section("bending");
    match custom(reader, parts.stage, "fe_bending", Quantity::Ratio)? {
        Some(0.0) => out.field_text("model", "none", Some("custom_wormwear_fe_bending = 0")),
        _ => out.field_text(
            "model",
            "fe",
            Some("worm and wheel bending with their shafts and bearings"),
        ),
    }
    if let Some(l) = reader.positive(parts.worm, "length_worm_gear", Quantity::Length)? {
        out.field("worm_body_length_mm", l, "worm_gear.length_worm_gear");
    }
    let sections: Vec<f64> = parts
        .worm_sections
        .iter()
        .map(|s| {
            Ok([
                reader.positive(s, "outer_diameter_begin", Quantity::Length)?,
                reader.positive(s, "outer_diameter_end", Quantity::Length)?,
            ])
        })
        .collect::<Result<Vec<_>, RexsError>>()?
        .into_iter()
        .flatten()
        .flatten()
        .collect();
    if let Some(d) = sections.iter().copied().reduce(f64::min) {
        let r = 0.5 * d;
        if r < worm.root_radius {
            out.field(
                "worm_shaft_radius_mm",
                r,
                "smallest shaft_section outer diameter / 2 of the worm shaft",
            );
        } else {
            out.field("worm_shaft_radius_mm", worm.root_radius, &format!("the worm root radius: the file's shaft sections (smallest {d} mm) are not thinner than the threaded body"));
        }
    }
    let axes = stage_axes(reader, parts)?;
    match &axes {
        Some(ax) => {
            let points = bearing_positions(
                reader,
                &parts.worm_bearings,
                parts.worm_shaft,
                ax.worm_centre,
                ax.x1,
            )?;
            let load = load_point(reader, &parts.worm_loads, parts.worm_shaft)?
                .map(|p| dot(sub(p, ax.worm_centre), ax.x1));
            write_bearings(out, "worm_bearing_positions_mm", points, load, true, "along the worm axis from the worm centre; drive side (nearest the worm's load) first");
        }
        None => out.note(
            "worm_bearing_positions_mm: default (the file gives no positions of worm and wheel)",
        ),
    }
    wheel_support(reader, parts, wheel, axes.as_ref(), out)
}

pub(super) fn bearing_positions(
    reader: &Reader,
    bearings: &[&Component],
    shaft: Option<&Component>,
    centre: [f64; 3],
    axis: [f64; 3],
) -> Result<Vec<f64>, RexsError> {
    let mut v = Vec::new();
    for b in bearings {
        if let Some(p) = bearing_point(reader, b, shaft)? {
            v.push(dot(sub(p, centre), axis));
        }
    }
    Ok(v)
}

/// Writes two bearing positions ordered by the load: the one nearest the load first
/// (`near_first`) or last.
pub(super) fn write_bearings(
    out: &mut GearText,
    key: &str,
    mut points: Vec<f64>,
    load: Option<f64>,
    near_first: bool,
    what: &str,
) {
    if points.is_empty() {
        out.note(&format!(
            "{key}: default (no bearings on this shaft in the file)"
        ));
        return;
    }
    if points.len() != 2 {
        out.warn(format!("{key}: the file has {} bearings on this shaft, wormwear's model takes two: default positions used", points.len()));
        return;
    }
    points.sort_by(f64::total_cmp);
    if let Some(l) = load {
        let near_lower = (points[0] - l).abs() <= (points[1] - l).abs();
        if near_lower != near_first {
            points.swap(0, 1);
        }
    }
    out.line(
        key,
        format!("[{}, {}]", float(points[0]), float(points[1])),
        Some(&format!("concept bearings' support_vector, {what}")),
    );
}

/// The wheel's shaft radius and bearing positions, inserted into the [wheel] table written
/// earlier (a table's keys must follow its header).
pub(super) fn wheel_support(
    reader: &Reader,
    parts: &Parts,
    wheel: &Wheel,
    axes: Option<&Axes>,
    out: &mut GearText,
) -> Result<(), RexsError> {
    let mut lines = GearText::default();
    if let Some(ax) = axes {
        let points = bearing_positions(
            reader,
            &parts.wheel_bearings,
            parts.wheel_shaft,
            ax.wheel_centre,
            ax.z2,
        )?;
        let load = load_point(reader, &parts.wheel_loads, parts.wheel_shaft)?
            .map(|p| dot(sub(p, ax.wheel_centre), ax.z2));
        write_bearings(&mut lines, "bearing_positions_mm", points, load, false, "along the wheel axis z2 from the wheel centre; the fixed end (nearest the wheel's load) last");
    }
    if let (Some(s), Some(_)) = (parts.wheel_shaft, axes) {
        let u_wheel = reader.number(parts.wheel, "u_coordinate_on_shaft", Quantity::Length)?;
        let mut radius = None;
        for sec in &parts.wheel_sections {
            let u0 = reader.number(sec, "u_coordinate_on_shaft", Quantity::Length)?;
            let len = reader.positive(sec, "length", Quantity::Length)?;
            let d = reader.positive(sec, "outer_diameter_begin", Quantity::Length)?;
            if let (Some(u), Some(u0), Some(len), Some(d)) = (u_wheel, u0, len, d) {
                if u >= u0 && u <= u0 + len {
                    radius = Some(0.5 * d);
                }
            }
        }
        let hub_default = custom(reader, parts.wheel, "hub_radius", Quantity::Length)?
            .unwrap_or(0.35 * wheel.reference_radius);
        match radius {
            Some(r) if r < hub_default => lines.field("shaft_radius_mm", r, &format!("shaft_section of shaft [{}] under the wheel: outer diameter / 2", s.id)),
            Some(r) => lines.warn(format!("the wheel shaft radius {r} mm is not below the default hub radius {hub_default:.3} mm: the default shaft radius is used")),
            None => {}
        }
    }
    out.warnings.append(&mut lines.warnings);
    insert_into_table(&mut out.text, "wheel", &lines.text);
    Ok(())
}
