//! Where the loaded cells of the loaded analysis stand on the wheel flank's grid over the mesh
//! cycle (MODEL §13's flank maps): each position is an instant of the band's passage, and the
//! cell stands for the strip the band sweeps until the instants before and after it (MODEL
//! §5.6's passage), so that the friction maps neither have holes between the positions'
//! bands nor depend on where the positions fall. Shares sum to one: a map integrates to the
//! mesh loss. SI units (m, rad).

use crate::geometry::rows::row_parameter_on;
use crate::geometry::WheelFlank;
use crate::kinematics::Tca;
use crate::ltca::Ltca;

/// The node columns of a flank grid: their z and their nodes' radii (m, column by column
/// from the foot up), and the cell rows.
pub(super) struct FlankGrid<'a> {
    z: &'a [f64],
    radii: Vec<f64>,
    rows: usize,
}

impl<'a> FlankGrid<'a> {
    pub(super) fn of(wf: &'a WheelFlank) -> Self {
        Self {
            z: &wf.z,
            radii: wf.nodes.iter().map(|n| n.r).collect(),
            rows: wf.cells_height,
        }
    }

    /// The height parameter (row index, fractional: linear in r between the column's nodes,
    /// extended with its end rows) of radius r on node column j.
    fn row_parameter(&self, j: usize, r: f64) -> f64 {
        let n = self.rows + 1;
        row_parameter_on(&self.radii[j * n..(j + 1) * n], |&x| x, r)
    }

    /// The grid cells under a strip spanning radii `r` (low, high) and z +- `half_dz` (m),
    /// with the share of the strip each takes, appended to `out`: the cell columns the strip
    /// overlaps by their overlap along z (a strip on a node column is half in the column on
    /// each side), and in each the rows by their overlap in the height parameter, blended
    /// linearly between the column's two node columns. What lies past the grid's edges is
    /// clamped onto it, so the shares sum to one.
    pub(super) fn cells_under(
        &self,
        r: (f64, f64),
        z: f64,
        half_dz: f64,
        out: &mut Vec<(usize, f64)>,
    ) {
        let (ni, nj) = (self.rows, self.z.len() - 1);
        let (z0, z1) = (self.z[0], self.z[nj]);
        let column = |z: f64| ((z - z0) / (z1 - z0) * nj as f64).clamp(0.0, nj as f64);
        let (a, b) = (column(z - half_dz), column(z + half_dz));
        // The strip's share in column j, spread over the column's rows by radius.
        let mut in_column = |j: usize, column_share: f64| {
            // The height parameter where the strip's centre lies along the column.
            let t = (column(z) - j as f64).clamp(0.0, 1.0);
            let u = |r: f64| {
                let g = (1.0 - t) * self.row_parameter(j, r) + t * self.row_parameter(j + 1, r);
                g.clamp(0.0, ni as f64)
            };
            let (u0, u1) = (u(r.0.min(r.1)), u(r.0.max(r.1)));
            if u1 - u0 <= 1e-9 {
                let i = (u0.min(ni as f64 - 1e-9).floor() as usize).min(ni - 1);
                out.push((j * ni + i, column_share));
                return;
            }
            let mut i = u0.floor() as usize;
            while (i as f64) < u1 && i < ni {
                let overlap = u1.min(i as f64 + 1.0) - u0.max(i as f64);
                if overlap > 0.0 {
                    out.push((j * ni + i, column_share * overlap / (u1 - u0)));
                }
                i += 1;
            }
        };
        if b - a <= 0.0 {
            in_column((a.floor() as usize).min(nj - 1), 1.0);
            return;
        }
        for j in (a.floor() as usize).min(nj - 1)..nj {
            if j as f64 >= b {
                break;
            }
            let share = (b.min(j as f64 + 1.0) - a.max(j as f64)).max(0.0) / (b - a);
            if share > 0.0 {
                in_column(j, share);
            }
        }
    }
}

/// The radial strip (low, high, m) each cell of each position of `ltca` stands for over the
/// mesh cycle, indexed [position][cell] (an unloaded cell: its own radius). Across the line,
/// from half-way to the previous loaded cell of its slice to half-way to the next (by radius;
/// a lone cell its width across the line); along the passage, widened by half the travel of
/// its band's pressure centroid to the band's instants just before and after it on the same
/// node column (the reference tooth's times sigma theta2 + k tau, `tau` the wheel's pitch
/// angle in rad; one side mirrored where the band enters or leaves).
pub(super) fn swept_strips(tca: &Tca, ltca: &Ltca, tau: f64) -> Vec<Vec<(f64, f64)>> {
    let mut strips: Vec<Vec<(f64, f64)>> = ltca
        .positions
        .iter()
        .map(|p| p.cells.iter().map(|c| (c.r, c.r)).collect())
        .collect();
    let bands = loaded_bands(tca, ltca, tau);
    for band in &bands {
        let p = &ltca.positions[band.at];
        let cells = &band.cells;
        for (n, &k) in cells.iter().enumerate() {
            let r = p.cells[k].r;
            let half_gap = |other: Option<&usize>| other.map(|&o| 0.5 * (p.cells[o].r - r));
            let (below, above) = match (
                half_gap(n.checked_sub(1).and_then(|m| cells.get(m))),
                half_gap(cells.get(n + 1)),
            ) {
                (Some(b), Some(a)) => (b, a),
                (Some(b), None) => (b, -b),
                (None, Some(a)) => (-a, a),
                (None, None) => (-p.cells[k].cell.half_nu, p.cells[k].cell.half_nu),
            };
            strips[band.at][k] = (r + below + band.travel.0, r + above + band.travel.1);
        }
    }
    strips
}

/// The loaded cells of one (position, tooth, node column), ascending in radius, with their
/// pressure centroid (m), the reference tooth's time (rad) and the centroid's travel to the
/// neighbouring instants (below, above its own: at most 0, at least 0; m).
struct Band {
    at: usize,
    time: f64,
    centroid: f64,
    cells: Vec<usize>,
    travel: (f64, f64),
}

/// The loaded bands of every position of `ltca`, with their travel along the passage.
fn loaded_bands(tca: &Tca, ltca: &Ltca, tau: f64) -> Vec<Band> {
    let mut bands = Vec::new();
    for (at, p) in ltca.positions.iter().enumerate() {
        let mut loaded: Vec<usize> = (0..p.cells.len())
            .filter(|&k| p.pressure[k] > 0.0)
            .collect();
        loaded.sort_by(|&a, &b| {
            let (ca, cb) = (&p.cells[a], &p.cells[b]);
            (ca.tooth, ca.slice)
                .cmp(&(cb.tooth, cb.slice))
                .then(ca.r.total_cmp(&cb.r))
        });
        for run in loaded.chunk_by(|&a, &b| {
            (p.cells[a].tooth, p.cells[a].slice) == (p.cells[b].tooth, p.cells[b].slice)
        }) {
            let c = &p.cells[run[0]];
            let load: f64 = run.iter().map(|&k| p.pressure[k]).sum();
            let moment: f64 = run.iter().map(|&k| p.pressure[k] * p.cells[k].r).sum();
            let theta2 = tca.positions[p.position].theta2 + tca.sigma * c.tooth as f64 * tau;
            bands.push(Band {
                at,
                time: tca.sigma * theta2,
                centroid: moment / load,
                cells: run.to_vec(),
                travel: (0.0, 0.0),
            });
        }
    }
    set_travel(&mut bands, ltca, tau / tca.positions.len().max(1) as f64);
    bands
}

/// Each band's travel to the bands of the same node column one position step `dt` (rad)
/// before and after it: half the centroids' distances.
fn set_travel(bands: &mut [Band], ltca: &Ltca, dt: f64) {
    let slice = |b: &Band| ltca.positions[b.at].cells[b.cells[0]].slice;
    let mut order: Vec<usize> = (0..bands.len()).collect();
    order.sort_by(|&a, &b| {
        slice(&bands[a])
            .cmp(&slice(&bands[b]))
            .then(bands[a].time.total_cmp(&bands[b].time))
    });
    let next = |a: usize, b: usize| {
        slice(&bands[a]) == slice(&bands[b])
            && ((bands[b].time - bands[a].time) / dt - 1.0).abs() < 1e-3
    };
    let mut travel = vec![(0.0, 0.0); bands.len()];
    for (n, &a) in order.iter().enumerate() {
        let half = |b: usize| 0.5 * (bands[b].centroid - bands[a].centroid);
        let before = n
            .checked_sub(1)
            .map(|m| order[m])
            .filter(|&b| next(b, a))
            .map(half);
        let after = order.get(n + 1).copied().filter(|&b| next(a, b)).map(half);
        let (s0, s1) = match (before, after) {
            (Some(b), Some(f)) => (b, f),
            (Some(b), None) => (b, -b),
            (None, Some(f)) => (-f, f),
            (None, None) => (0.0, 0.0),
        };
        travel[a] = (s0.min(s1).min(0.0), s0.max(s1).max(0.0));
    }
    for (band, t) in bands.iter_mut().zip(travel) {
        band.travel = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat flank grid: 4 columns over z in [-2, 2] mm, radii 0..10 mm in 5 rows.
    fn flat() -> FlankGrid<'static> {
        FlankGrid {
            z: &[-2e-3, -1e-3, 0.0, 1e-3, 2e-3],
            radii: (0..5)
                .flat_map(|_| (0..=5).map(|i| 2e-3 * i as f64))
                .collect(),
            rows: 5,
        }
    }

    fn under(wf: &FlankGrid, r: (f64, f64), z: f64, half_dz: f64) -> Vec<(usize, f64)> {
        let mut out = Vec::new();
        wf.cells_under(r, z, half_dz, &mut out);
        let total: f64 = out.iter().map(|s| s.1).sum();
        assert!((total - 1.0).abs() < 1e-12, "{out:?}");
        out
    }

    #[test]
    fn a_local_cell_is_shared_among_the_grid_columns_it_overlaps() {
        let wf = flat();
        // A strip on the node column z = 0 (half 0.5 mm): half in column 1, half in column 2.
        let shares = under(&wf, (5e-3, 5e-3), 0.0, 0.5e-3);
        assert_eq!((shares[0].0, shares[1].0), (5 + 2, 2 * 5 + 2));
        assert!((shares[0].1 - 0.5).abs() < 1e-12 && (shares[1].1 - 0.5).abs() < 1e-12);
        // Inside one column, all of it there; past the face end, clamped to the last column.
        assert_eq!(under(&wf, (1e-3, 1e-3), -1.5e-3, 0.2e-3), vec![(0, 1.0)]);
        assert_eq!(
            under(&wf, (9.9e-3, 9.9e-3), 2e-3, 0.5e-3),
            vec![(3 * 5 + 4, 1.0)]
        );
    }

    #[test]
    fn a_strip_is_shared_among_the_rows_it_overlaps_and_clamped_onto_the_grid() {
        let wf = flat();
        // Radii 3..7 mm in column 0 (rows of 2 mm): a quarter in row 1, half in 2, a quarter
        // in 3.
        let shares = under(&wf, (3e-3, 7e-3), -1.5e-3, 0.2e-3);
        let expected = [(1, 0.25), (2, 0.5), (3, 0.25)];
        assert_eq!(shares.len(), 3, "{shares:?}");
        for (s, e) in shares.iter().zip(expected) {
            assert_eq!(s.0, e.0);
            assert!((s.1 - e.1).abs() < 1e-12, "{shares:?}");
        }
        // Reaching past the tip, the part beyond is clamped onto the last row: 9..12 mm is
        // all in row 4.
        assert_eq!(under(&wf, (9e-3, 12e-3), -1.5e-3, 0.2e-3), vec![(4, 1.0)]);
    }
}
