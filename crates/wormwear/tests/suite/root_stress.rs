//! The wheel's tooth root stress (MODEL §9.1) on the FE sector with filleted roots: a valid
//! mesh, linear in the loads, close to linear in the torque, converged under refinement inside
//! the face, and a fillet that does not fit refused with the input named.

use crate::common;

use wormwear::bending::fe::element_stiffness;
use wormwear::bending::fe::Elastic;
use wormwear::bending::root_mesh::fillet_sector_mesh;
use wormwear::bending::wheel_root::{
    forget_kept_sector, root_mesh_settings, root_stress, root_stress_cached, RootStressError,
};
use wormwear::geometry::Geometry;
use wormwear::input::{BendingKind, GearSet, Torque};
use wormwear::ltca::Ltca;

/// The design gear at `torque` N m on the worm, rigid bodies (the root stress's sector is its
/// own FE model), its geometry, loaded flank and loaded analysis.
fn loaded(torque: f64) -> (GearSet, Geometry, wormwear::geometry::Flank, Ltca) {
    let mut g = common::example("gear-1x40-design.toml");
    g.bending.kind = BendingKind::None;
    g.conditions.torque = Torque::Worm(torque);
    let geo = Geometry::build(&g).unwrap();
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let settings = wormwear::ltca::LtcaSettings::from_gear(&g);
    let ltca = wormwear::ltca::analyse_with(&g, &geo, &tca, &settings, None).unwrap();
    (g, geo, tca.loaded_flank, ltca)
}

const FILLET: f64 = 1.0e-3;

#[test]
fn every_element_of_the_filleted_sector_is_valid_at_every_refinement() {
    let (g, geo, _, _) = loaded(60.0);
    let material = Elastic {
        youngs_modulus: 1e11,
        poisson_ratio: 0.3,
    };
    for level in 1..=3 {
        let s = root_mesh_settings(&g, level, FILLET);
        let m = fillet_sector_mesh(&geo, &s, g.hob.tip_radius, g.cutting.centre_distance).unwrap();
        for e in 0..m.mesh.elements.len() {
            element_stiffness(&m.mesh, e, &material)
                .unwrap_or_else(|err| panic!("level {level}, element {e}: {err}"));
        }
        // Each layer's root section spans the central tooth.
        assert!(m.root_section.iter().all(|row| row.len() == s.across));
    }
}

#[test]
fn the_root_stress_is_linear_in_the_pressures_and_nearly_so_in_the_torque() {
    let (g, geo, flank, ltca) = loaded(60.0);
    let base = root_stress(&g, &geo, &ltca, flank, (1, FILLET)).unwrap();
    // The FE sector is linear: twice the pressures, twice the stress.
    let mut doubled = ltca.clone();
    for p in &mut doubled.positions {
        for pr in &mut p.pressure {
            *pr *= 2.0;
        }
    }
    let twice = root_stress(&g, &geo, &doubled, flank, (1, FILLET)).unwrap();
    let ratio = twice.interior.stress / base.interior.stress;
    assert!((ratio - 2.0).abs() < 1e-9, "{ratio}");
    assert_eq!(twice.interior.position, base.interior.position);
    // Twice the worm torque: the wheel torque grows a little more (the mesh efficiency rises
    // with the load), and the contact spreads as it is loaded (Hertz: the loaded area grows),
    // so per unit wheel torque the stress grows by slightly less than the load; measured
    // 0.989 at level 1.
    let (_, _, _, heavy_ltca) = loaded(120.0);
    let heavy = root_stress(&g, &geo, &heavy_ltca, flank, (1, FILLET)).unwrap();
    let torque_ratio = heavy_ltca.wheel_torque / ltca.wheel_torque;
    let ratio = heavy.interior.stress / base.interior.stress / torque_ratio;
    assert!(torque_ratio > 2.0 && torque_ratio < 2.1, "{torque_ratio}");
    assert!((0.975..1.0).contains(&ratio), "{ratio}");
    // The tensile fibre is on the loaded flank's side (the tooth bends away from the load).
    assert!(base.interior.tension_on_loaded_side);
}

/// A spread's samples move the worm, not the wheel: the sector and its factorised stiffness
/// are built once and kept. The kept sector gives the root stress a fresh build gives, to the
/// bit; another fillet (another sector) is not served the kept one.
#[test]
fn a_kept_sector_gives_the_fresh_root_stress_and_another_fillet_builds_its_own() {
    let (g, geo, flank, ltca) = loaded(60.0);
    // The worm moved along the wheel axis: the same wheel, another load.
    let mut moved = g.clone();
    moved.operating.offset += 0.05e-3;
    let tca = wormwear::kinematics::analyse(&moved, &geo).unwrap();
    let settings = wormwear::ltca::LtcaSettings::from_gear(&moved);
    let moved_ltca = wormwear::ltca::analyse_with(&moved, &geo, &tca, &settings, None).unwrap();
    forget_kept_sector();
    let first = root_stress(&g, &geo, &ltca, flank, (1, FILLET)).unwrap();
    let kept = root_stress(&moved, &geo, &moved_ltca, flank, (1, FILLET)).unwrap();
    forget_kept_sector();
    let fresh = root_stress(&moved, &geo, &moved_ltca, flank, (1, FILLET)).unwrap();
    assert_eq!(kept, fresh);
    assert_ne!(kept.interior.stress, first.interior.stress);
    let other = root_stress(&g, &geo, &ltca, flank, (1, 0.8e-3)).unwrap();
    forget_kept_sector();
    let other_fresh = root_stress(&g, &geo, &ltca, flank, (1, 0.8e-3)).unwrap();
    assert_eq!(other, other_fresh);
    assert_ne!(other.interior.stress, first.interior.stress);
}

#[test]
fn a_fillet_reaching_above_the_lowest_contact_is_refused_naming_the_input() {
    let (g, geo, flank, ltca) = loaded(60.0);
    let err = root_stress(&g, &geo, &ltca, flank, (1, 3.0e-3)).unwrap_err();
    assert!(
        matches!(err, RootStressError::ContactOnFillet { .. }),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(text.contains("rating.root_fillet_radius_mm = 3"), "{text}");
}

#[test]
fn the_root_stress_is_cached_checked_and_recomputed_when_its_entry_is_damaged() {
    let (g, geo, flank, ltca) = loaded(60.0);
    let dir = tempfile::tempdir().unwrap();
    let args = (flank, 1, FILLET);
    let (first, w) = root_stress_cached(&g, &geo, &ltca, args, Some(dir.path())).unwrap();
    assert!(w.is_empty(), "{w:?}");
    let entries: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
    assert_eq!(entries.len(), 1);
    let (again, w) = root_stress_cached(&g, &geo, &ltca, args, Some(dir.path())).unwrap();
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(again, first);
    // Another fillet radius is another entry, not this one's value.
    let other = (flank, 1, 0.8e-3);
    let (smaller, _) = root_stress_cached(&g, &geo, &ltca, other, Some(dir.path())).unwrap();
    assert_ne!(smaller.interior.stress, first.interior.stress);
    // The same gear under other loads (a loaded analysis moved by the model's code or
    // defaults, not by the file) is another entry, not this one's value: linear elasticity
    // scales the stress with the loads.
    let mut heavier = ltca.clone();
    for p in &mut heavier.positions {
        p.pressure.iter_mut().for_each(|x| *x *= 1.1);
    }
    let (scaled, _) = root_stress_cached(&g, &geo, &heavier, args, Some(dir.path())).unwrap();
    let ratio = scaled.interior.stress / first.interior.stress;
    assert!((ratio - 1.1).abs() < 1e-6, "{ratio}");
    // A damaged entry fails its checksum: recomputed, with a warning, to the same value.
    let path = entries[0].path();
    let text = std::fs::read_to_string(&path).unwrap();
    let digit = text.find("\"stress\":").unwrap() + 10;
    let mut bytes = text.into_bytes();
    bytes[digit] = if bytes[digit] == b'1' { b'2' } else { b'1' };
    std::fs::write(&path, bytes).unwrap();
    let (fixed, w) = root_stress_cached(&g, &geo, &ltca, args, Some(dir.path())).unwrap();
    assert_eq!(fixed, first);
    assert!(w.iter().any(|m| m.contains("not used")), "{w:?}");
}

/// Refinement study (heavy: level 4 takes ~40 s and 6 GB): the root stress inside the face
/// converges, < 5 % between the two finest levels. Measured 72.22, 73.62, 74.36 MPa at
/// levels 2-4 (design case, 60 N m, fillet 1 mm).
#[test]
#[ignore = "heavy validation: scripts/validate-heavy runs it"]
fn the_root_stress_inside_the_face_converges_under_refinement() {
    let (g, geo, flank, ltca) = loaded(60.0);
    let stresses: Vec<f64> = (2..=4)
        .map(|level| {
            root_stress(&g, &geo, &ltca, flank, (level, FILLET))
                .unwrap()
                .interior
                .stress
        })
        .collect();
    eprintln!("root stress at levels 2-4: {stresses:?} Pa");
    let last = (stresses[2] - stresses[1]).abs() / stresses[2];
    assert!(last < 0.05, "{stresses:?}");
    let before = (stresses[1] - stresses[0]).abs() / stresses[1];
    assert!(last < before, "not converging: {stresses:?}");
}
