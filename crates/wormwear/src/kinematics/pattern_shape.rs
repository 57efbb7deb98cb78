//! The shape of a contact pattern on the loaded wheel flank (MODEL §17): where it sits across
//! the face, from the face end where the worm's thread enters the mesh (the entering side) to
//! the one where it leaves (the leaving side), and
//! up the flank, and how far it reaches along the face and up the flank. What a workshop reads
//! off a marking test (MODEL §4.4), for the no-load pattern and the loaded one alike.

use crate::geometry::WheelFlank;

/// The shape of a pattern: its cells' area-weighted centre and their span, as shares of the
/// flank grid (the active flank between the face ends and between the flank's lower and upper
/// limits of each column).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PatternShape {
    /// Centre across the face: 0 at the entering side's face end, 1 at the leaving side's.
    pub centre_across_face: f64,
    /// Centre up the flank: 0 at the flank's lower limit (the wheel's root side), 1 at its
    /// upper limit.
    pub centre_up_flank: f64,
    /// Share of the face the pattern spans, from its first to its last column of cells.
    pub extent_along_face: f64,
    /// Share of the flank height it spans, from its lowest to its highest row of cells.
    pub extent_up_flank: f64,
    /// Face position (wheel axis, mm) of the entry side's face end.
    pub entry_side_z_mm: f64,
}

impl PatternShape {
    /// The shape of the cells `in_pattern` (flank-grid cell order: column j, row i at
    /// j * rows + i) of `wf`, with the contact entering at the low-z face end when
    /// `entry_at_low_z`. None for an empty pattern.
    pub fn of(wf: &WheelFlank, in_pattern: &[bool], entry_at_low_z: bool) -> Option<Self> {
        let (ni, nj) = (wf.cells_height, wf.cells_face);
        // A node's height fraction on its column (0 at the foot, 1 at the top; the rows are
        // not evenly spaced at the worm-tip trace, MODEL §3.3).
        let fraction =
            |i: usize, j: usize| (wf.node(i, j).r - wf.r_low[j]) / (wf.r_high[j] - wf.r_low[j]);
        let (mut area, mut across, mut up) = (0.0, 0.0, 0.0);
        let (mut j_lo, mut j_hi) = (usize::MAX, 0);
        // The lowest and highest height fraction the pattern's cells reach (their rows' edges,
        // the mean of the cell's two node columns).
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for j in 0..nj {
            for i in 0..ni {
                let k = j * ni + i;
                if !in_pattern.get(k).copied().unwrap_or(false) {
                    continue;
                }
                let a = wf.cell_area[k];
                area += a;
                across += a * (j as f64 + 0.5) / nj as f64;
                let centre = fraction(i, j)
                    + fraction(i + 1, j)
                    + fraction(i, j + 1)
                    + fraction(i + 1, j + 1);
                up += a * 0.25 * centre;
                (j_lo, j_hi) = (j_lo.min(j), j_hi.max(j));
                low = low.min(0.5 * (fraction(i, j) + fraction(i, j + 1)));
                high = high.max(0.5 * (fraction(i + 1, j) + fraction(i + 1, j + 1)));
            }
        }
        if area <= 0.0 {
            return None;
        }
        let from_low_z = across / area;
        let (z_first, z_last) = (wf.z[0], wf.z[nj]);
        Some(Self {
            centre_across_face: if entry_at_low_z {
                from_low_z
            } else {
                1.0 - from_low_z
            },
            centre_up_flank: up / area,
            extent_along_face: (j_hi + 1 - j_lo) as f64 / nj as f64,
            extent_up_flank: high - low,
            entry_side_z_mm: 1e3
                * if entry_at_low_z {
                    z_first.min(z_last)
                } else {
                    z_first.max(z_last)
                },
        })
    }
}

/// Whether the worm's thread enters the mesh at the wheel's low-z face end: the entering side
/// is the face end from which the worm's surface, and the oil it carries, comes into the mesh
/// (the leaving side, where a workshop puts the pattern, is the other). At the pitch point on
/// the line of centres the worm's material velocity (`material_velocities`, worm turning at
/// `theta1_dot` rad/s of thread advance, placed by `placement`) points along the wheel axis,
/// from the entering side to the leaving side: its wheel-frame z component decides. A property
/// of the worm's rotation sense alone (not of the flanks or the pattern), so a pattern's centre
/// across the face does not jump when the flanks change a little (the covariance of the nodes'
/// contact moments with z over the whole flank, used before, is near zero on a conjugate flank
/// and flipped between cutting settings 0.1 mm apart). Within a localised pattern the contact
/// lines sweep the face from the entering side to the leaving side (tests/suite/tca.rs).
pub fn entry_at_low_z(
    worm: &crate::geometry::ThreadSurface,
    placement: &crate::input::Placement,
    reference_radius: f64,
    theta1_dot: f64,
) -> bool {
    let pitch_point = nalgebra::Vector3::new(0.0, reference_radius, 0.0);
    let v = super::material_velocities(&pitch_point, worm, placement, theta1_dot, 1.0);
    placement
        .vector_worm_to_wheel(&nalgebra::Vector3::from(v.worm))
        .z
        > 0.0
}
