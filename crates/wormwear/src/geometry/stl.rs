//! Triangulated surfaces of the worm and the wheel teeth, written as binary STL (mm), placed in
//! the worm frame at rotation 0 (nominal operating assembly). The surfaces are open at the
//! worm's ends and the wheel teeth stand without rim: they are for viewing, not for meshing.

use super::placement::wheel_point;
use super::thread::Flank;
use super::Geometry;
use crate::input::GearSet;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// A triangle soup.
#[derive(Debug, Clone, Default)]
pub struct TriangleMesh {
    pub triangles: Vec<[Vector3<f64>; 3]>,
}

impl TriangleMesh {
    /// Adds the quad (a, b, c, d) as two triangles.
    fn quad(&mut self, a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>, d: Vector3<f64>) {
        self.triangles.push([a, b, c]);
        self.triangles.push([a, c, d]);
    }

    /// Adds a structured patch given as rows of points (quads between consecutive rows).
    fn patch(&mut self, rows: &[Vec<Vector3<f64>>]) {
        for w in rows.windows(2) {
            for k in 0..w[0].len().min(w[1].len()).saturating_sub(1) {
                self.quad(w[0][k], w[0][k + 1], w[1][k + 1], w[1][k]);
            }
        }
    }

    /// Binary STL bytes, coordinates scaled by `scale` (1e3 for mm).
    pub fn to_binary_stl(&self, name: &str, scale: f64) -> Vec<u8> {
        let mut out = Vec::with_capacity(84 + 50 * self.triangles.len());
        let mut header = [0u8; 80];
        let text = format!("wormwear {name} (mm)");
        let n = text.len().min(80);
        header[..n].copy_from_slice(&text.as_bytes()[..n]);
        out.extend_from_slice(&header);
        out.extend_from_slice(&(self.triangles.len() as u32).to_le_bytes());
        for t in &self.triangles {
            let normal = (t[1] - t[0]).cross(&(t[2] - t[0]));
            let normal = if normal.norm() > 0.0 {
                normal.normalize()
            } else {
                normal
            };
            for v in std::iter::once(normal).chain(t.iter().map(|p| p * scale)) {
                for c in [v.x, v.y, v.z] {
                    out.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
        out
    }
}

/// Worm surface: `threads` axial pitches of thread outline swept over a full turn.
pub fn worm_mesh(gear: &GearSet, geo: &Geometry, threads: usize) -> TriangleMesh {
    let worm = &geo.worm;
    let (rf, ra) = (gear.worm.root_radius, gear.worm.tip_radius);
    let n = 16;
    // Axial outline over `threads` pitches: (x at phi = 0, rho).
    let mut outline = Vec::new();
    let k0 = -(threads as i64) / 2;
    for k in k0..k0 + threads as i64 {
        let dk = k as f64 * worm.axial_pitch();
        for s in 0..=n {
            let rho = rf + (ra - rf) * s as f64 / n as f64;
            outline.push((worm.axial_profile(Flank::Left, rho).0 + dk, rho));
        }
        for s in (0..=n).rev() {
            let rho = rf + (ra - rf) * s as f64 / n as f64;
            outline.push((worm.axial_profile(Flank::Right, rho).0 + dk, rho));
        }
    }
    let turns = 96;
    let sh = worm.hand_sign() * worm.lead_per_rad();
    let rows: Vec<Vec<Vector3<f64>>> = (0..=turns)
        .map(|m| {
            let phi = -PI + 2.0 * PI * m as f64 / turns as f64;
            let (s, c) = phi.sin_cos();
            outline
                .iter()
                .map(|&(x, rho)| Vector3::new(x + sh * phi, rho * c, rho * s))
                .collect()
        })
        .collect();
    let mut mesh = TriangleMesh::default();
    mesh.patch(&rows);
    mesh
}

/// Wheel teeth: `teeth` teeth around the line of centres (0 = all), flanks from the global
/// grid, tip surface, and the two end faces of each tooth.
pub fn wheel_mesh(gear: &GearSet, geo: &Geometry, teeth: usize) -> TriangleMesh {
    let (l, r) = (geo.wheel_flank(Flank::Left), geo.wheel_flank(Flank::Right));
    let z2 = geo.teeth as i64;
    let count = if teeth == 0 { z2 } else { teeth as i64 };
    let tau = 2.0 * PI / z2 as f64;
    let a = gear.operating;
    let place = |p: &super::FlankPoint, dtheta: f64| {
        a.wheel_to_worm(&wheel_point(p.r, p.theta + dtheta, p.z, 0.0))
    };
    let mut mesh = TriangleMesh::default();
    let (ni, nj) = (l.cells_height, l.cells_face);
    for k in -(count / 2)..count - count / 2 {
        let (dl, dr) = (k as f64 * tau, (k + 1) as f64 * tau);
        let rows_l: Vec<Vec<_>> = (0..=nj)
            .map(|j| (0..=ni).map(|i| place(l.node(i, j), dl)).collect())
            .collect();
        let rows_r: Vec<Vec<_>> = (0..=nj)
            .map(|j| (0..=ni).map(|i| place(r.node(i, j), dr)).collect())
            .collect();
        mesh.patch(&rows_l);
        mesh.patch(&rows_r);
        // Tip: between the top nodes of the two flanks of the tooth, across the tooth.
        let tips: Vec<Vec<Vector3<f64>>> = (0..=nj)
            .map(|j| {
                let (pl, pr) = (l.node(ni, j), r.node(ni, j));
                let (t0, t1) = (pl.theta + dl, pr.theta + dr);
                (0..=8)
                    .map(|s| {
                        a.wheel_to_worm(&wheel_point(
                            pl.r,
                            t0 + (t1 - t0) * s as f64 / 8.0,
                            pl.z,
                            0.0,
                        ))
                    })
                    .collect()
            })
            .collect();
        mesh.patch(&tips);
        // End faces: fan from the centroid of the tooth outline at j = 0 and j = nj.
        for j in [0, nj] {
            let mut ring: Vec<Vector3<f64>> = (0..=ni).map(|i| place(l.node(i, j), dl)).collect();
            ring.extend((0..=ni).rev().map(|i| place(r.node(i, j), dr)));
            let c = ring.iter().sum::<Vector3<f64>>() / ring.len() as f64;
            for w in 0..ring.len() {
                mesh.triangles
                    .push([c, ring[w], ring[(w + 1) % ring.len()]]);
            }
        }
    }
    mesh
}
