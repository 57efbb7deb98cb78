//! Sub-surface stress and the equivalent pressure (MODEL §8.1) against independent truths:
//! the Hertz line and point contacts' closed-form fields on the axis (Johnson 1985, §4.2 and
//! §3.4), a uniform strip's surface stresses, Boussinesq's point load far from a small
//! rectangle, the force balance over a plane below the load, and convergence of p_eq.

use nalgebra::Vector3;
use std::ops::Range;
use wormwear::contact::ContactCell;
use wormwear::subsurface::{
    equivalent_pressures, principal_shear, principal_stresses, rectangle_stress, stress_below,
    Criterion, SubsurfaceSettings,
};

/// A flat cell of the surface z = 0 (the body below), centred at (x, y), half sides (a, b).
fn cell(x: f64, y: f64, a: f64, b: f64) -> ContactCell {
    ContactCell {
        centre: Vector3::new(x, y, 0.0),
        normal: Vector3::z(),
        axis_nu: Vector3::x(),
        axis_zeta: Vector3::y(),
        half_nu: a,
        half_zeta: b,
    }
}

/// Mean of sqrt(1 - x^2) over [x1, x2] (|x| <= 1): the Hertz line pressure's cell average.
fn ellipse_mean(x1: f64, x2: f64) -> f64 {
    let f = |x: f64| {
        let x = x.clamp(-1.0, 1.0);
        0.5 * (x * (1.0 - x * x).sqrt() + x.asin())
    };
    (f(x2) - f(x1)) / (x2 - x1)
}

/// A Hertz line contact of half-width `a` and peak `p0` on one row of `n` strips across
/// [-a, a], each `length` long: cells and cell-average pressures.
fn hertz_line(n: usize, a: f64, p0: f64, length: f64) -> (Vec<ContactCell>, Vec<f64>) {
    let h = 2.0 * a / n as f64;
    (0..n)
        .map(|k| {
            let x1 = -a + k as f64 * h;
            (
                cell(x1 + 0.5 * h, 0.0, 0.5 * h, 0.5 * length),
                p0 * ellipse_mean(x1 / a, (x1 + h) / a),
            )
        })
        .unzip()
}

/// Hertz line contact on the axis (McEwen; Johnson 1985, eq. 4.49): sigma_x and sigma_z over
/// p0 at depth zeta = z / a.
fn hertz_line_axis(zeta: f64) -> (f64, f64) {
    let s = (1.0 + zeta * zeta).sqrt();
    (-((1.0 + 2.0 * zeta * zeta) / s - 2.0 * zeta), -1.0 / s)
}

#[test]
fn the_field_below_a_hertz_line_contact_is_mcewens_and_tau1_peaks_at_0_300_p0_at_0_786_a() {
    let (a, p0) = (1e-4, 1e9);
    let (cells, pressure) = hertz_line(400, a, p0, 1e3 * a);
    let all: Vec<usize> = (0..cells.len()).collect();
    let centre = cell(0.0, 0.0, 1e-9, 1e-9);
    for nu in [0.3, 0.45] {
        let mut best = (0.0, 0.0);
        for k in 1..=200 {
            let zeta = k as f64 * 0.01;
            let s = stress_below(&cells, &pressure, &all, &centre, zeta * a, nu);
            let (sx, sz) = hertz_line_axis(zeta);
            assert!(
                (s[0] / p0 - sx).abs() < 2e-3,
                "sigma_x at {zeta}: {} vs {sx}",
                s[0] / p0
            );
            assert!(
                (s[2] / p0 - sz).abs() < 2e-3,
                "sigma_z at {zeta}: {} vs {sz}",
                s[2] / p0
            );
            // Plane strain: sigma_y = nu (sigma_x + sigma_z); no shear on the axis.
            assert!(
                (s[1] / p0 - nu * (sx + sz)).abs() < 3e-3,
                "sigma_y at {zeta}"
            );
            assert!(s[3].abs().max(s[4].abs()).max(s[5].abs()) < 1e-3 * p0);
            let t = principal_shear(&s) / p0;
            if t > best.0 {
                best = (t, zeta);
            }
        }
        assert!(
            (best.0 - 0.300).abs() < 1.5e-3,
            "tau_1 max {} (nu {nu})",
            best.0
        );
        assert!((best.1 - 0.786).abs() <= 0.011, "at {} a (nu {nu})", best.1);
    }
}

#[test]
fn the_equivalent_pressure_of_a_hertz_line_contact_is_p0_at_0_786_a_for_any_poisson_ratio() {
    let (a, p0) = (1e-4, 1e9);
    let (cells, pressure) = hertz_line(101, a, p0, 1e3 * a);
    // One row across the line.
    let rows = std::slice::from_ref(&(0..cells.len())).to_vec();
    for nu in [0.25, 0.35, 0.45] {
        let eq = equivalent_pressures(&cells, &pressure, &rows, &[0], &SubsurfaceSettings::new(nu));
        let centre = &eq[50];
        // The exact maximum of tau_1 / 0.300 is 1.0007 p0 (0.30021 p0 at 0.786 a).
        assert!(
            (centre.pressure / p0 - 1.0007).abs() < 3e-3,
            "p_eq {}",
            centre.pressure / p0
        );
        assert!(
            (centre.depth / a - 0.786).abs() < 0.02,
            "depth {}",
            centre.depth / a
        );
        // Off the centre the criterion reads less.
        assert!(eq[90].pressure < centre.pressure);
    }
    let mut orthogonal = SubsurfaceSettings::new(0.3);
    orthogonal.criterion = Criterion::OrthogonalShear;
    let eq = equivalent_pressures(&cells, &pressure, &rows, &[0], &orthogonal);
    let (best, k) = eq
        .iter()
        .enumerate()
        .map(|(k, e)| (e.pressure, k))
        .fold((0.0, 0), |b, v| if v.0 > b.0 { v } else { b });
    // |tau_xz| peaks at 0.25 p0, at x = +-0.87 a and z = 0.5 a.
    assert!((best / p0 - 1.0).abs() < 0.01, "orthogonal {}", best / p0);
    let x = cells[k].centre.x / a;
    assert!((x.abs() - 0.87).abs() < 0.03, "at x = {x} a");
    assert!(
        (eq[k].depth / a - 0.5).abs() < 0.03,
        "at z = {} a",
        eq[k].depth / a
    );
}

#[test]
fn the_field_below_a_hertz_point_contact_is_the_axisymmetric_solution() {
    // Hertz sphere: sigma_z = -p0 / (1 + zeta^2), sigma_r = -p0 [(1 + nu)(1 - zeta atan(1 /
    // zeta)) - 1 / (2 (1 + zeta^2))] on the axis (Johnson 1985, eq. 3.64); tau_1 max 0.31 p0 at
    // 0.48 a for nu = 0.3.
    let (a, p0, nu, n) = (1e-4, 1e9, 0.3, 81);
    let h = 2.0 * a / n as f64;
    let mut cells = Vec::new();
    let mut pressure = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (-a + (i as f64 + 0.5) * h, -a + (j as f64 + 0.5) * h);
            // The cell average from a 4 x 4 sub-sampling of the cell.
            let mut p = 0.0;
            for si in 0..4 {
                for sj in 0..4 {
                    let (u, v) = (
                        x + (si as f64 - 1.5) * h / 4.0,
                        y + (sj as f64 - 1.5) * h / 4.0,
                    );
                    p += (1.0 - (u * u + v * v) / (a * a)).max(0.0).sqrt() / 16.0;
                }
            }
            if p > 0.0 {
                cells.push(cell(x, y, 0.5 * h, 0.5 * h));
                pressure.push(p0 * p);
            }
        }
    }
    let all: Vec<usize> = (0..cells.len()).collect();
    let centre = cell(0.0, 0.0, 1e-9, 1e-9);
    let mut best = (0.0, 0.0);
    for k in 1..=150 {
        let zeta = k as f64 * 0.01;
        let s = stress_below(&cells, &pressure, &all, &centre, zeta * a, nu);
        let sz = -1.0 / (1.0 + zeta * zeta);
        let sr = -((1.0 + nu) * (1.0 - zeta * (1.0 / zeta).atan()) - 0.5 / (1.0 + zeta * zeta));
        assert!(
            (s[2] / p0 - sz).abs() < 5e-3,
            "sigma_z at {zeta}: {} vs {sz}",
            s[2] / p0
        );
        assert!(
            (s[0] / p0 - sr).abs() < 5e-3,
            "sigma_r at {zeta}: {} vs {sr}",
            s[0] / p0
        );
        assert!((s[1] / p0 - sr).abs() < 5e-3, "sigma_theta at {zeta}");
        let t = principal_shear(&s) / p0;
        if t > best.0 {
            best = (t, zeta);
        }
    }
    assert!((best.0 - 0.31).abs() < 0.005, "tau_1 max {}", best.0);
    assert!((best.1 - 0.48).abs() <= 0.02, "at {} a", best.1);
}

#[test]
fn a_uniform_strip_loads_its_surface_hydrostatically_in_its_plane_and_not_beside_it() {
    // Uniform p on |x| <= c, infinite along y (plane strain): at the surface below the strip
    // sigma_x = sigma_z = -p, sigma_y = -2 nu p; beside it all three vanish (Johnson 1985, §2.5).
    let (c, p, nu) = (1e-4, 1e8, 0.3);
    let z = 1e-6 * c;
    let s = rectangle_stress(0.3 * c, 0.0, z, c, 1e4 * c, nu, p);
    assert!(
        (s[0] / p + 1.0).abs() < 1e-4 && (s[2] / p + 1.0).abs() < 1e-4,
        "{s:?}"
    );
    assert!((s[1] / p + 2.0 * nu).abs() < 1e-3, "sigma_y {}", s[1] / p);
    let s = rectangle_stress(2.0 * c, 0.0, z, c, 1e4 * c, nu, p);
    assert!(s.iter().all(|v| v.abs() < 1e-3 * p), "beside: {s:?}");
}

#[test]
fn far_from_a_small_rectangle_the_field_is_boussinesqs_point_load() {
    // Boussinesq (Johnson 1985, eq. 3.20): sigma_z = -3 P z^3 / (2 pi rho^5), tau_xz = -3 P x
    // z^2 / (2 pi rho^5) (x pointing from the load to the field point).
    let (c, p) = (1e-6, 1e9);
    let force = p * 4.0 * c * c;
    for (x, y, z) in [(3e-4, 1e-4, 2e-4), (0.0, 0.0, 5e-4), (-2e-4, 4e-4, 1e-4)] {
        let s = rectangle_stress(x, y, z, c, c, 0.3, p);
        let rho: f64 = (x * x + y * y + z * z).sqrt();
        let k = 3.0 * force / (2.0 * std::f64::consts::PI * rho.powi(5));
        let sz = -k * z.powi(3);
        let txz = -k * x * z * z;
        let tyz = -k * y * z * z;
        assert!(
            (s[2] - sz).abs() < 1e-4 * sz.abs(),
            "sigma_z {} vs {sz}",
            s[2]
        );
        assert!(
            (s[4] - txz).abs() < 1e-4 * sz.abs(),
            "tau_xz {} vs {txz}",
            s[4]
        );
        assert!(
            (s[5] - tyz).abs() < 1e-4 * sz.abs(),
            "tau_yz {} vs {tyz}",
            s[5]
        );
    }
}

#[test]
fn the_normal_stress_on_any_plane_below_a_load_balances_it() {
    // Equilibrium: the integral of sigma_z over the plane at depth z is minus the applied force,
    // and that of tau_xz vanishes with a symmetric load (midpoint rule over +-40 z, tail < 1e-4).
    let (a, b, p, z) = (2e-4, 1e-4, 1e8, 3e-4);
    let n = 400;
    let half = 40.0 * z;
    let h = 2.0 * half / n as f64;
    let (mut fz, mut fx) = (0.0, 0.0);
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (-half + (i as f64 + 0.5) * h, -half + (j as f64 + 0.5) * h);
            let s = rectangle_stress(x, y, z, a, b, 0.3, p);
            fz += s[2] * h * h;
            fx += s[4] * h * h;
        }
    }
    let force = p * 4.0 * a * b;
    assert!((fz / force + 1.0).abs() < 1e-3, "{}", fz / force);
    assert!(fx.abs() < 1e-6 * force);
}

#[test]
fn principal_stresses_are_the_eigenvalues() {
    let s = [-3.0e8, 1.2e8, -7.5e8, 2.1e8, -0.4e8, 1.7e8];
    let m = nalgebra::Matrix3::new(s[0], s[3], s[4], s[3], s[1], s[5], s[4], s[5], s[2]);
    let mut e: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(|a, b| b.total_cmp(a));
    let p = principal_stresses(&s);
    for (x, y) in p.iter().zip(&e) {
        assert!((x - y).abs() < 1e-6 * 7.5e8, "{p:?} vs {e:?}");
    }
    // Equal principal stresses (hydrostatic) and a diagonal tensor.
    assert_eq!(
        principal_stresses(&[-1.0, -1.0, -1.0, 0.0, 0.0, 0.0]),
        [-1.0; 3]
    );
    let d = principal_stresses(&[-1.0, 2.0, -5.0, 0.0, 0.0, 0.0]);
    assert!((d[0] - 2.0).abs() < 1e-12 && (d[1] + 1.0).abs() < 1e-12 && (d[2] + 5.0).abs() < 1e-12);
    // The principal shear (its own closed form) is half the eigenvalues' spread, also where
    // two principal stresses coincide (cos 3 phi = +-1) or all three do.
    for t in [
        s,
        [-1.0, 2.0, -5.0, 0.0, 0.0, 0.0],
        [-1.0, -1.0, -5.0, 0.0, 0.0, 0.0],
        [-1.0, -5.0, -5.0, 0.0, 0.0, 0.0],
        [-2.0, -2.0, -2.0, 0.0, 0.0, 0.0],
        [1e8, -3e8, 2e7, -5e7, 3e7, 9e7],
    ] {
        let m = nalgebra::Matrix3::new(t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2]);
        let e = m.symmetric_eigenvalues();
        let spread = 0.5 * (e.max() - e.min());
        let size = t.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(
            (principal_shear(&t) - spread).abs() < 1e-7 * size,
            "{t:?}: {} vs {spread}",
            principal_shear(&t)
        );
    }
}

/// Rows along the line of the bands of these tests (4 a each: 164 a in all).
const ROWS: usize = 41;

/// A Hertz line contact of half-width a on a band of `n` cells across +-1.5 a, [`ROWS`] rows
/// along the line of length `length` each (the LTCA's slices): cells, pressures, rows.
fn band(n: usize, a: f64, p0: f64, length: f64) -> (Vec<ContactCell>, Vec<f64>, Vec<Range<usize>>) {
    let h = 3.0 * a / n as f64;
    let mut cells = Vec::new();
    let mut pressure = Vec::new();
    let mut rows = Vec::new();
    for row in 0..ROWS {
        let start = cells.len();
        for k in 0..n {
            let x1 = -1.5 * a + k as f64 * h;
            cells.push(cell(
                x1 + 0.5 * h,
                (row as f64 - (ROWS / 2) as f64) * length,
                0.5 * h,
                0.5 * length,
            ));
            pressure.push(
                p0 * ellipse_mean((x1 / a).clamp(-1.0, 1.0), ((x1 + h) / a).clamp(-1.0, 1.0))
                    .max(0.0)
                    * if x1 + h <= -a || x1 >= a { 0.0 } else { 1.0 },
            );
        }
        rows.push(start..cells.len());
    }
    (cells, pressure, rows)
}

#[test]
fn a_one_cell_spike_of_3_p0_moves_the_equivalent_pressure_far_less_than_its_height() {
    // The spike on the centre cell of the middle row (as long as the rows, 4 a: the LTCA's
    // cells are long along the line). The surface peak triples (+2 p0); p_eq moves by the
    // spike's force, not its height: far less, and half as much for a cell half as wide.
    let (a, p0) = (1e-4, 1e9);
    let settings = SubsurfaceSettings::new(0.3);
    let shift = |n: usize| {
        let (cells, mut pressure, rows) = band(n, a, p0, 4.0 * a);
        let max = |e: &[wormwear::subsurface::Equivalent]| {
            e[rows[ROWS / 2].clone()]
                .iter()
                .map(|e| e.pressure)
                .fold(0.0, f64::max)
        };
        let before = max(&equivalent_pressures(
            &cells, &pressure, &rows, &[0; ROWS], &settings,
        ));
        assert!((before / p0 - 1.0).abs() < 0.01, "smooth {}", before / p0);
        pressure[rows[ROWS / 2].start + n / 2] = 3.0 * p0;
        let after = max(&equivalent_pressures(
            &cells, &pressure, &rows, &[0; ROWS], &settings,
        ));
        (after - before) / p0
    };
    let (wide, narrow) = (shift(45), shift(91));
    assert!(
        wide < 0.15 * 2.0,
        "a spike 0.067 a wide moved p_eq by {wide} p0"
    );
    assert!(
        narrow < 0.6 * wide,
        "half as wide: {narrow} p0 against {wide} p0"
    );
}

#[test]
fn the_equivalent_pressure_converges_under_refinement() {
    // The band refined 15 -> 30 -> 60 cells across: the two finest levels within 1 %.
    let (a, p0) = (1e-4, 1e9);
    let settings = SubsurfaceSettings::new(0.3);
    let peak = |n: usize| {
        let (cells, pressure, rows) = band(n, a, p0, 4.0 * a);
        let eq = equivalent_pressures(&cells, &pressure, &rows, &[0; ROWS], &settings);
        eq[rows[ROWS / 2].clone()]
            .iter()
            .map(|e| e.pressure)
            .fold(0.0, f64::max)
            / p0
    };
    let (coarse, mid, fine) = (peak(15), peak(30), peak(60));
    assert!((fine - mid).abs() < 0.01 * fine, "{coarse} {mid} {fine}");
    assert!(
        (fine - mid).abs() <= (mid - coarse).abs() + 1e-4,
        "{coarse} {mid} {fine}"
    );
    assert!((fine - 1.0).abs() < 0.01, "{fine}");
}

#[test]
fn lumping_the_far_rows_changes_the_equivalent_pressure_by_less_than_half_a_percent() {
    let (a, p0) = (1e-4, 1e9);
    let (cells, pressure, rows) = band(21, a, p0, 4.0 * a);
    let lumped = SubsurfaceSettings::new(0.3);
    let exact = SubsurfaceSettings {
        reach: 1e9,
        ..lumped
    };
    let surface = [0; ROWS];
    let e1 = equivalent_pressures(&cells, &pressure, &rows, &surface, &lumped);
    let e2 = equivalent_pressures(&cells, &pressure, &rows, &surface, &exact);
    for r in [0, ROWS / 4, ROWS / 2] {
        for k in rows[r].clone().filter(|&k| pressure[k] > 0.0) {
            let d = (e1[k].pressure - e2[k].pressure).abs() / p0;
            assert!(
                d < 5e-3,
                "row {r} cell {k}: {} vs {}",
                e1[k].pressure / p0,
                e2[k].pressure / p0
            );
        }
    }
}

#[test]
fn the_section_below_a_hertz_line_contact_peaks_at_0_300_p0_at_0_786_a_below_its_centre() {
    let (a, p0) = (1e-4, 1e9);
    let (cells, pressure) = hertz_line(101, a, p0, 1e3 * a);
    let all: Vec<usize> = (0..cells.len()).collect();
    let s =
        wormwear::subsurface::section(&cells, &pressure, 0..cells.len(), &all, (60, 40, 2.0), 0.3);
    let (k, top) = s
        .tau1
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |b, v| if v.1 > b.1 { v } else { b });
    let (x, z) = (s.x[k % 60], s.z[k / 60]);
    assert!((top / p0 - 0.300).abs() < 2e-3, "tau_1 max {}", top / p0);
    // The section starts at the row's outer edge (-a): the centre is at x = a.
    assert!(
        (x - a).abs() < 0.05 * a && (z / a - 0.786).abs() < 0.05,
        "at x {x}, z {}",
        z / a
    );
}
