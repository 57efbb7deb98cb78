//! Finite-element model of the wheel sector built from the generated flanks: geometry
//! (volume), convergence of the tooth compliance, CalculiX on the same mesh.

use crate::common::example;
use std::f64::consts::PI;
use wormwear::bending::fe::{element_volume, solve, Elastic, Load};
use wormwear::bending::wheel_mesh::{sector_mesh, SectorMesh, SectorMeshSettings};
use wormwear::geometry::{Flank, Geometry};
use wormwear::input::GearSet;

const BRONZE: Elastic = Elastic {
    youngs_modulus: 110e9,
    poisson_ratio: 0.29,
};

fn settings(scale: usize) -> SectorMeshSettings {
    SectorMeshSettings {
        across: 2 * scale,
        height: 3 * scale,
        rim: scale,
        space: scale,
        face_step: 12 / scale,
        rim_thickness: 0.02,
        web: None,
    }
}

fn mesh(g: &GearSet, geo: &Geometry, scale: usize) -> SectorMesh {
    sector_mesh(
        geo,
        &settings(scale),
        g.hob.tip_radius,
        g.cutting.centre_distance,
    )
}

#[test]
fn sector_volume_matches_the_flank_geometry() {
    // Independent volume: in each layer z, the three teeth's section area
    // int r (theta_R(r) + tau - theta_L(r)) dr from the root circle to the blank top (flanks
    // continued radially below their bottom, as in the mesh) plus the rim annulus between its
    // inner radius and the root circle over the sector angle; integrated over z by Simpson.
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let m = mesh(&g, &geo, 2);
    let fe_volume: f64 = (0..m.mesh.elements.len())
        .map(|e| element_volume(&m.mesh, e))
        .sum();
    let (l, r) = (geo.wheel_flank(Flank::Left), geo.wheel_flank(Flank::Right));
    let tau = 2.0 * PI / geo.teeth as f64;
    let root_at = |z: f64| g.cutting.centre_distance - (g.hob.tip_radius.powi(2) - z * z).sqrt();
    let r_in = m.root_radius - 0.02;
    let area = |j: usize| {
        let z = l.z[j];
        let (root, top) = (root_at(z), l.r_high[j].min(r.r_high[j]));
        let n = 400;
        let width = |rr: f64| {
            let a = l.column_theta(j, rr.max(l.r_low[j])).0;
            let b = r.column_theta(j, rr.max(r.r_low[j])).0 + tau;
            b - a
        };
        let teeth: f64 = (0..n)
            .map(|k| {
                let rr = root + (top - root) * (k as f64 + 0.5) / n as f64;
                rr * width(rr) * (top - root) / n as f64
            })
            .sum::<f64>()
            * 3.0;
        // Sector angle: from mid-space before tooth -1 to mid-space after tooth +1 = 3 tau.
        let rim = 0.5 * (root * root - r_in * r_in) * 3.0 * tau;
        teeth + rim
    };
    let nj = l.cells_face;
    let h = l.z[1] - l.z[0];
    let mut vol = 0.0;
    for j in (0..nj).step_by(2) {
        vol += h / 3.0 * (area(j) + 4.0 * area(j + 1) + area(j + 2));
    }
    eprintln!(
        "sector volume: FE {:.6e} m^3, geometry {:.6e} m^3",
        fe_volume, vol
    );
    assert!(
        (fe_volume / vol - 1.0).abs() < 2e-3,
        "{fe_volume:e} vs {vol:e}"
    );
}

/// Line load of 1 N/mm along the central tooth's left-mating flank at mid-height (nodal forces
/// normal to the flank, into the tooth), and the mean normal deflection of its tip line, m/N.
fn tooth_compliance(
    g: &GearSet,
    geo: &Geometry,
    m: &SectorMesh,
) -> (f64, Vec<Load>, Vec<(usize, usize, f64)>) {
    let mut fixed = Vec::new();
    for &n in &m.inner {
        for d in 0..3 {
            fixed.push((n, d, 0.0));
        }
    }
    let flank = &m.left_flank[1];
    let max_h = flank.iter().map(|f| f.1).max().unwrap();
    let mid: Vec<usize> = flank
        .iter()
        .filter(|f| f.1 == max_h / 2)
        .map(|f| f.2)
        .collect();
    let tip: Vec<usize> = flank.iter().filter(|f| f.1 == max_h).map(|f| f.2).collect();
    // Direction: -x2 rotated to the tooth (approximately the flank normal at the line of centres).
    let total = g.wheel.face_width * 1e3; // 1 N/mm
    let per = total / mid.len() as f64;
    let loads: Vec<Load> = mid.iter().map(|&n| (n, 0, -per)).collect();
    let u = &solve(&m.mesh, &BRONZE, &fixed, std::slice::from_ref(&loads)).unwrap()[0];
    let deflection = tip.iter().map(|&n| -u[n][0]).sum::<f64>() / tip.len() as f64;
    let _ = geo;
    (deflection / total, loads, fixed)
}

#[test]
fn tooth_compliance_converges_under_refinement() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    // Converging: 6.5, 1.7, 0.8 % between scales 1-2, 2-3, 3-4 (measured when the far-face
    // flank nodes were not yet loaded; the lumped, not consistent, nodal line load slows it).
    // The suite checks 2 -> 3.
    let (c1, _, _) = tooth_compliance(&g, &geo, &mesh(&g, &geo, 2));
    let (c2, _, _) = tooth_compliance(&g, &geo, &mesh(&g, &geo, 3));
    eprintln!(
        "tooth tip compliance: {c1:.4e} m/N -> {c2:.4e} m/N ({:.2} %)",
        100.0 * (c2 / c1 - 1.0)
    );
    assert!(
        c1 > 0.0 && c2 > c1,
        "refinement must soften a displacement-based model"
    );
    assert!((c2 / c1 - 1.0).abs() < 0.03, "{c1:e} vs {c2:e}");
}

/// CalculiX on the same sector mesh and load (C3D20): same tip deflection. Ignored (needs ccx).
#[test]
#[ignore = "needs CalculiX (ccx) on the PATH"]
fn calculix_agrees_on_the_wheel_sector() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let dir = std::env::temp_dir().join(format!("wormwear-ccx-sector-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Same mesh (scale 1): the element and the solver.
    let m = mesh(&g, &geo, 1);
    let c = tooth_compliance(&g, &geo, &m).0;
    let theirs = calculix_tooth_compliance(&g, &geo, &m, &dir, "sector");
    eprintln!("wheel tooth tip compliance: ours {c:.6e} m/N, CalculiX {theirs:.6e} m/N");
    assert!((theirs / c - 1.0).abs() < 1e-5);
    // Our default bending mesh (scale 2) against CalculiX on a finer mesh of the same sector
    // (scale 3): the same geometry and load, a different discretisation, within 3 %.
    let m2 = mesh(&g, &geo, 2);
    let ours2 = tooth_compliance(&g, &geo, &m2).0;
    let m3 = mesh(&g, &geo, 3);
    let fine = calculix_tooth_compliance(&g, &geo, &m3, &dir, "fine");
    eprintln!(
        "tooth tip compliance: ours (scale 2, {} nodes) {ours2:.6e} m/N, CalculiX (scale 3, {} nodes) \
         {fine:.6e} m/N ({:+.2} %)",
        m2.mesh.nodes.len(),
        m3.mesh.nodes.len(),
        100.0 * (ours2 / fine - 1.0)
    );
    assert!((ours2 / fine - 1.0).abs() < 0.03);
    // The whole ring (rim all round, web clamped at the hub) as the bending stage builds it:
    // the same mesh in CalculiX, then our scale-2 ring against CalculiX on the scale-3 ring.
    let build = |scale: usize| {
        sector_mesh(
            &geo,
            &ring_settings(scale, 37 * scale / 2, scale + 1),
            g.hob.tip_radius,
            g.cutting.centre_distance,
        )
    };
    let r2 = build(2);
    let ours_ring = tooth_compliance(&g, &geo, &r2).0;
    let theirs_ring = calculix_tooth_compliance(&g, &geo, &r2, &dir, "ring");
    let r3 = build(3);
    let fine_ring = calculix_tooth_compliance(&g, &geo, &r3, &dir, "ring_fine");
    eprintln!(
        "whole ring: ours (scale 2, {} nodes) {ours_ring:.6e} m/N, CalculiX same mesh \
         {theirs_ring:.6e} m/N; CalculiX (scale 3, {} nodes) {fine_ring:.6e} m/N ({:+.2} %)",
        r2.mesh.nodes.len(),
        r3.mesh.nodes.len(),
        100.0 * (ours_ring / fine_ring - 1.0)
    );
    assert!((theirs_ring / ours_ring - 1.0).abs() < 1e-5);
    assert!((ours_ring / fine_ring - 1.0).abs() < 0.03);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The tooth tip compliance of [`tooth_compliance`]'s load case computed by CalculiX (C3D20)
/// on mesh `m`, m/N.
fn calculix_tooth_compliance(
    g: &GearSet,
    geo: &Geometry,
    m: &SectorMesh,
    dir: &std::path::Path,
    name: &str,
) -> f64 {
    use wormwear::bending::fe::{calculix_deck, read_calculix_displacements};
    let (_, loads, fixed) = tooth_compliance(g, geo, m);
    std::fs::write(
        dir.join(format!("{name}.inp")),
        calculix_deck(&m.mesh, &BRONZE, &fixed, &loads),
    )
    .unwrap();
    let out = std::process::Command::new("ccx")
        .arg(name)
        .current_dir(dir)
        .output()
        .expect("ccx runs");
    assert!(out.status.success());
    let dat = std::fs::read_to_string(dir.join(format!("{name}.dat"))).unwrap();
    let u = read_calculix_displacements(&dat, m.mesh.nodes.len()).expect("displacements");
    let flank = &m.left_flank[1];
    let max_h = flank.iter().map(|f| f.1).max().unwrap();
    let tip: Vec<usize> = flank.iter().filter(|f| f.1 == max_h).map(|f| f.2).collect();
    let total = g.wheel.face_width * 1e3;
    tip.iter().map(|&n| -u[n][0]).sum::<f64>() / tip.len() as f64 / total
}

#[test]
fn bending_coefficients_interpolate_the_fe_off_the_fit_grid() {
    // MODEL §5.5: unit normal loads at K = 5 x 6 points of the central tooth's loaded flank, FE
    // displacements with the opposite flank free and blocked, U = (free - blocked) . n, basis fit
    // C = F^-1 U F^-T; then the coefficient between two flank points off that grid must match
    // the FE within 5 % of the largest displacement. On the whole ring (web to the hub), as
    // the bending stage builds it.
    use faer::Mat;
    use wormwear::bending::basis::{Basis, WidthFunctions};
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let m = sector_mesh(
        &geo,
        &ring_settings(2, 37, 3),
        g.hob.tip_radius,
        g.cutting.centre_distance,
    );
    let wf = geo.wheel_flank(Flank::Left);
    let flank = &m.left_flank[1];
    let n_layers = m.layer_columns.len();
    let max_h = flank.iter().map(|f| f.1).max().unwrap();
    let node = |layer: usize, h: usize| {
        flank
            .iter()
            .find(|f| f.0 == layer && f.1 == h)
            .map(|f| f.2)
            .unwrap()
    };
    let normal = |layer: usize, n: usize| {
        let p = m.mesh.nodes[n];
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        wf.column_normal(m.layer_columns[layer], r)
    };
    assert_eq!(n_layers, 11);
    let heights: Vec<usize> = (0..5).map(|k| k * max_h / 4).collect();
    let widths: Vec<usize> = (0..6).map(|k| 2 * k).collect();
    let fit_points: Vec<(usize, usize)> = heights
        .iter()
        .flat_map(|&h| widths.iter().map(move |&w| (w, h)))
        .collect();
    let off_points: Vec<(usize, usize)> = vec![
        (1, max_h / 8),
        (5, 3 * max_h / 8),
        (9, 5 * max_h / 8),
        (3, 7 * max_h / 8),
        (7, max_h / 2),
    ];
    let points: Vec<(usize, usize)> = fit_points.iter().chain(&off_points).copied().collect();
    let ids: Vec<usize> = points.iter().map(|&(w, h)| node(w, h)).collect();
    let normals: Vec<nalgebra::Vector3<f64>> = points
        .iter()
        .zip(&ids)
        .map(|(&(w, _), &n)| normal(w, n))
        .collect();
    let loads: Vec<(usize, nalgebra::Vector3<f64>)> =
        ids.iter().copied().zip(normals.iter().copied()).collect();
    let bending =
        wormwear::bending::wheel_model::bending_displacements(&m, &BRONZE, &loads, &ids).unwrap();
    // Bending displacement at point l (into the tooth) due to a unit load at point c.
    let bend = |l: usize, c: usize| {
        let d = bending[c][l];
        -(d[0] * normals[l][0] + d[1] * normals[l][1] + d[2] * normals[l][2])
    };
    let k = fit_points.len();
    let basis = Basis {
        height: 5,
        width: 6,
        kind: WidthFunctions::FreeFree,
    };
    // Basis coordinates: r~ = height index / max, w~ = layer / (layers - 1).
    let coord =
        |(w, h): (usize, usize)| (h as f64 / max_h as f64, w as f64 / (n_layers - 1) as f64);
    // The basis grid is uniform in both directions: check the fit points are its points.
    for (p, q) in fit_points.iter().zip(basis.grid()) {
        let c = coord(*p);
        assert!((c.0 - q.0).abs() < 1e-12 && (c.1 - q.1).abs() < 1e-12);
    }
    let u = Mat::from_fn(k, k, &bend);
    let core = basis.fit(&u);
    let umax = (0..k).map(|l| u[(l, l)].abs()).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for a in k..points.len() {
        for b in k..points.len() {
            let fe = bend(a, b);
            let fit = basis.coefficient(&core, coord(points[a]), coord(points[b]));
            worst = worst.max((fit - fe).abs());
        }
    }
    eprintln!("bending coefficients off the fit grid: worst error {:.2} % of the largest displacement ({umax:.3e} m/N)", 100.0 * worst / umax);
    assert!(worst < 0.05 * umax);
}

#[test]
fn ltca_with_wheel_bending_is_more_compliant_and_in_equilibrium() {
    use wormwear::bending::wheel_model::WheelBending;
    use wormwear::ltca::{self, LtcaSettings};
    let mut g = example("gear-1x40-design.toml");
    g.analysis.positions = 8;
    let geo = Geometry::build(&g).unwrap();
    let model = WheelBending::build(&g, &geo, &settings(2), None, 5, 6).unwrap();
    // Reciprocity (Maxwell-Betti): the same-tooth core is symmetric up to round-off.
    let k = model.basis.len();
    let mut asym: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for i in 0..k {
        for j in 0..k {
            asym = asym.max((model.same[(i, j)] - model.same[(j, i)]).abs());
            scale = scale.max(model.same[(i, j)].abs());
        }
    }
    assert!(
        asym < 1e-8 * scale,
        "same-tooth core not symmetric: {asym:e} vs {scale:e}"
    );
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let s = LtcaSettings::from_gear(&g);
    let rigid = ltca::analyse_with(&g, &geo, &tca, &s, None).unwrap();
    let bent = ltca::analyse_with(&g, &geo, &tca, &s, Some(&model)).unwrap();
    assert_eq!(bent.bending_model, "fe-wheel");
    let (te0, p0) = rigid.te_stats();
    let (te1, p1) = bent.te_stats();
    eprintln!(
        "LTCA without / with wheel bending: TE mean {te0:.3e} / {te1:.3e} rad, p2p {p0:.3e} / {p1:.3e} rad, \
         stiffness {:.3e} / {:.3e} N m/rad, P_max {:.0} / {:.0} MPa",
        rigid.stiffness_mean(), bent.stiffness_mean(), rigid.max_pressure / 1e6, bent.max_pressure / 1e6
    );
    for p in &bent.positions {
        assert!(p.torque_residual < 1e-6);
        assert!(
            p.residuals.complementarity < 1e-7 && p.residuals.min_gap > -1e-7,
            "{:?}",
            p.residuals
        );
    }
    // More compliant: larger approach (more negative TE), lower mesh stiffness.
    assert!(te1 < te0 && bent.stiffness_mean() < rigid.stiffness_mean());
}

/// The whole ring with an 18 mm web: 0.4 b, which the layers of scales 2 (b/10) and 3 (b/15)
/// both represent exactly (a web between layer boundaries snaps to them: 15 mm would be 18 mm
/// at scale 2 and 12 mm at scale 3, a different geometry, not a finer mesh).
fn ring_settings(scale: usize, rest: usize, web_elements: usize) -> SectorMeshSettings {
    SectorMeshSettings {
        web: Some(wormwear::bending::wheel_mesh::WebSettings {
            thickness: 0.018,
            hub_radius: 0.035,
            elements: web_elements,
            rest_elements: rest,
        }),
        ..settings(scale)
    }
}

fn volume(m: &SectorMesh) -> f64 {
    (0..m.mesh.elements.len())
        .map(|e| element_volume(&m.mesh, e))
        .sum()
}

#[test]
fn whole_ring_adds_the_rim_and_web_volume_and_closes() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let plain = mesh(&g, &geo, 2);
    let web = ring_settings(2, 37, 3);
    let ring = sector_mesh(&geo, &web, g.hob.tip_radius, g.cutting.centre_distance);
    // Closed: no side cuts, and no two nodes at the same place (the ring's seam is glued).
    assert!(ring.sides.is_empty());
    let mut keys: Vec<(i64, i64, i64)> = ring
        .mesh
        .nodes
        .iter()
        .map(|p| {
            (
                (p[0] * 1e7).round() as i64,
                (p[1] * 1e7).round() as i64,
                (p[2] * 1e7).round() as i64,
            )
        })
        .collect();
    let n = keys.len();
    keys.sort_unstable();
    keys.dedup();
    assert_eq!(keys.len(), n, "coincident nodes left at the seam");
    // Exact added volume: the rest of the rim, (2 pi - 3 tau) of an annulus from the rim's inner
    // radius to the root circle (linear in z between layers, as the mesh), plus the web, a full
    // disk from the hub to the rim over the layers whose middle lies within half its thickness.
    let l = geo.wheel_flank(Flank::Left);
    let layers = &ring.layer_columns;
    let root_at = |z: f64| g.cutting.centre_distance - (g.hob.tip_radius.powi(2) - z * z).sqrt();
    let r_in = ring.root_radius - 0.02;
    let tau = 2.0 * PI / geo.teeth as f64;
    let w = web.web.unwrap();
    let mut exact = 0.0;
    for win in layers.windows(2) {
        let (z0, z1) = (l.z[win[0]], l.z[win[1]]);
        let (r0, r1) = (root_at(z0), root_at(z1));
        let dz = (z1 - z0).abs();
        let root_sq = (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
        exact += 0.5 * (2.0 * PI - 3.0 * tau) * (root_sq - r_in * r_in) * dz;
        if (0.5 * (z0 + z1)).abs() < 0.5 * w.thickness {
            exact += PI * (r_in * r_in - w.hub_radius.powi(2)) * dz;
        }
    }
    let added = volume(&ring) - volume(&plain);
    eprintln!(
        "ring: {} nodes, added volume {added:.6e} vs {exact:.6e} m^3 ({:.2e})",
        ring.mesh.nodes.len(),
        added / exact - 1.0
    );
    assert!((added / exact - 1.0).abs() < 1e-4);
}

#[test]
fn whole_ring_tooth_compliance_converges_around_the_ring() {
    // Clamped at the hub through the whole web instead of at the rim: the tooth is more
    // compliant, by the web's and the ring's bending (the earlier three-tooth wedge with free
    // side cuts came out 37 times more compliant: not a disk). Doubling the elements around
    // the rest of the ring and down the web changes the tooth compliance by < 1 %.
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let build =
        |s: &SectorMeshSettings| sector_mesh(&geo, s, g.hob.tip_radius, g.cutting.centre_distance);
    let (c0, _, _) = tooth_compliance(&g, &geo, &mesh(&g, &geo, 2));
    let (c1, _, _) = tooth_compliance(&g, &geo, &build(&ring_settings(2, 37, 3)));
    let (c2, _, _) = tooth_compliance(&g, &geo, &build(&ring_settings(2, 74, 6)));
    eprintln!(
        "tooth tip compliance: rim clamped {c0:.4e}, whole ring to the hub {c1:.4e}, refined \
         around the ring and down the web {c2:.4e} m/N ({:+.3} %)",
        100.0 * (c2 / c1 - 1.0)
    );
    assert!(c1 > c0 && c1 < 3.0 * c0, "{c0:e} {c1:e}");
    assert!((c2 / c1 - 1.0).abs() < 0.01);
}

/// A web thinner than the mesh's layers (1 mm against b/10 = 4.5 mm layers) is modelled as the
/// layer or two nearest the median plane: its volume is theirs, and the ring solves, more
/// compliant than with the 18 mm web (it was singular: no layer snapped into the web, the rim
/// joined to the hub by nothing; issue 38's probe, web 1.5 mm).
#[test]
fn a_web_thinner_than_a_layer_is_the_layer_nearest_the_median_plane() {
    let g = example("gear-1x40-design.toml");
    let geo = Geometry::build(&g).unwrap();
    let build =
        |s: &SectorMeshSettings| sector_mesh(&geo, s, g.hob.tip_radius, g.cutting.centre_distance);
    let mut thin = ring_settings(2, 37, 3);
    thin.web.as_mut().unwrap().thickness = 0.001;
    let (ring18, ring1) = (build(&ring_settings(2, 37, 3)), build(&thin));
    // The web's volume: the full disk over the layers nearest the median plane.
    let l = geo.wheel_flank(Flank::Left);
    let mids: Vec<(f64, f64)> = ring1
        .layer_columns
        .windows(2)
        .map(|w| {
            (
                (0.5 * (l.z[w[0]] + l.z[w[1]])).abs(),
                (l.z[w[1]] - l.z[w[0]]).abs(),
            )
        })
        .collect();
    let nearest = mids.iter().map(|m| m.0).fold(f64::INFINITY, f64::min);
    let r_in = ring1.root_radius - 0.02;
    let disk = |dz: f64| PI * (r_in * r_in - 0.035f64.powi(2)) * dz;
    let exact: f64 = mids
        .iter()
        .filter(|m| m.0 <= nearest * (1.0 + 1e-9))
        .map(|m| disk(m.1))
        .sum();
    let in_18: f64 = mids.iter().filter(|m| m.0 < 0.009).map(|m| disk(m.1)).sum();
    let web1 = volume(&ring18) - in_18 + exact;
    assert!(
        (volume(&ring1) / web1 - 1.0).abs() < 1e-4,
        "{} {web1}",
        volume(&ring1)
    );
    let (c18, _, _) = tooth_compliance(&g, &geo, &ring18);
    let (c1, _, _) = tooth_compliance(&g, &geo, &ring1);
    eprintln!("tooth tip compliance: web 18 mm {c18:.4e}, web of one layer {c1:.4e} m/N");
    assert!(c1.is_finite() && c1 > c18, "{c1:e} vs {c18:e}");
}

/// A wheel shaft that the load alone twists by more than a tooth pitch (2 mm radius under the
/// design case's 2400 N m: tens of radians) is refused at once, naming the shaft (issue 38's
/// probe: the solver's fallback ran for more than ten minutes); the 20 mm shaft is not.
#[test]
fn a_shaft_twisted_beyond_a_pitch_is_refused_naming_it() {
    use wormwear::bending::wheel_model::WheelBending;
    use wormwear::bending::wheel_shaft::WheelShaft;
    use wormwear::ltca::{self, LtcaError, LtcaSettings};
    let mut g = example("gear-1x40-design.toml");
    g.analysis.positions = 2;
    let geo = Geometry::build(&g).unwrap();
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let shaft = |radius: f64| WheelShaft {
        radius,
        hub_half_width: 0.5 * g.wheel.face_width,
        bearings: [-0.06, 0.06],
        youngs_modulus: 210e9,
        poisson_ratio: 0.3,
    };
    let s = LtcaSettings::from_gear(&g);
    let thin = WheelBending::build(&g, &geo, &settings(2), Some(&shaft(0.002)), 3, 3).unwrap();
    let start = std::time::Instant::now();
    match ltca::analyse_with(&g, &geo, &tca, &s, Some(&thin)) {
        Err(LtcaError::ShaftTorsion(m)) => {
            assert!(
                m.contains("wheel.shaft_radius_mm") && m.contains("tooth pitch"),
                "{m}"
            )
        }
        other => panic!("not refused: {:?}", other.map(|l| l.max_pressure)),
    }
    assert!(start.elapsed().as_secs() < 5);
    let stout = WheelBending::build(&g, &geo, &settings(2), Some(&shaft(0.02)), 3, 3).unwrap();
    assert!(ltca::analyse_with(&g, &geo, &tca, &s, Some(&stout)).is_ok());
}
