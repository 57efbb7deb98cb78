//! MODEL §13's first validation: the contact's friction and mesh efficiency over sliding speeds
//! 0.3-8 m/s on the 1/40 and the K 2/25 gears, beside ISO/TR 14521's rig-fitted base friction
//! mu_0T (MODEL §9; its factors Y at 1) and the efficiency it gives, tan(gamma) /
//! tan(gamma + atan(mu_0T)). One set of inputs (the examples') for every speed and both gears;
//! unworn flanks, no bending, the lubricant's fixed temperature.
//! Also section (e) of the report: that study, the reference cases and the lives with the heat
//! balance.

use super::{example, Results, Settings, ValidationError};
use crate::friction::MeshContacts;
use crate::geometry::Geometry;
use crate::input::BendingKind;
use crate::output::plot::{self, Series};
use std::fmt::Write as _;
use std::path::Path;

/// Micrometres per metre (the report's wear and backlash unit).
const UM: f64 = 1e6;

/// The gears and worm speeds (rpm) of the study: sliding speeds from 0.3 to 8 m/s on each.
pub const SPEED_STUDY: [(&str, [f64; 7]); 2] = [
    (
        "gear-1x40-design.toml",
        [110.0, 250.0, 500.0, 900.0, 1500.0, 2200.0, 2900.0],
    ),
    (
        "gear-k-2x25.toml",
        [80.0, 180.0, 360.0, 650.0, 1100.0, 1600.0, 2100.0],
    ),
];

/// One gear at one worm speed (SI but where the name says otherwise).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SpeedPoint {
    /// The example's file name without `.toml`.
    pub gear: String,
    pub worm_speed_rpm: f64,
    /// ISO/TR 14521's sliding speed at the reference diameter, m/s.
    pub sliding_speed: f64,
    /// The contact's load-weighted mean friction coefficient and the asperities' share.
    pub friction: f64,
    pub asperity_share: f64,
    /// The contact's mesh efficiency from its loss, P2 / (P2 + P_Vz).
    pub mesh_efficiency: f64,
    /// The mesh efficiency the loaded analysis' torques carry, T2 / (u T1).
    pub torque_efficiency: f64,
    /// ISO/TR 14521's mu_0T and the worm-driving efficiency it gives.
    pub iso_friction: f64,
    pub iso_efficiency: f64,
    /// ISO/TR 14521's mesh efficiency with the gear file's factors Y (`[rating]`; 1 where it
    /// gives none): the same gear's rating.
    pub iso_efficiency_with_factors: f64,
}

/// The study's points, gear by gear in [`SPEED_STUDY`]'s order (with `settings.quick` the
/// slowest and the fastest speed of each).
pub fn over_speeds(settings: &Settings) -> Result<Vec<SpeedPoint>, ValidationError> {
    let mut points = Vec::new();
    for (name, speeds) in SPEED_STUDY {
        // The smoke run: the ends of the range only.
        let speeds = if settings.quick {
            vec![speeds[0], speeds[speeds.len() - 1]]
        } else {
            speeds.to_vec()
        };
        for rpm in speeds {
            let mut g = example(settings, name)?;
            g.bending.kind = BendingKind::None;
            g.conditions.worm_speed = rpm * std::f64::consts::PI / 30.0;
            let failed = |e: &dyn std::fmt::Display| ValidationError::Job {
                id: format!("friction-{}-{rpm:.0}", name.trim_end_matches(".toml")),
                message: e.to_string(),
            };
            let geo = Geometry::build(&g).map_err(|e| failed(&e))?;
            let tca = crate::kinematics::analyse(&g, &geo).map_err(|e| failed(&e))?;
            let l = crate::ltca::analyse(&g, &geo, &tca).map_err(|e| failed(&e))?;
            let contacts = MeshContacts::new(&g, &geo, &tca, &l);
            let f = contacts.friction(&g.lubricant, &g.friction);
            let iso = crate::rating::rate(&g);
            let mu0 = crate::rating::base_friction(iso.sliding_speed_m_s);
            let gamma = g.worm.lead_angle();
            points.push(SpeedPoint {
                gear: name.trim_end_matches(".toml").to_string(),
                worm_speed_rpm: rpm,
                sliding_speed: iso.sliding_speed_m_s,
                friction: f.mean_coefficient,
                asperity_share: f.asperity_share,
                mesh_efficiency: contacts.output_power / (contacts.output_power + f.mesh_loss_w),
                torque_efficiency: l.mesh_efficiency,
                iso_friction: mu0,
                iso_efficiency: gamma.tan() / (gamma + mu0.atan()).tan(),
                iso_efficiency_with_factors: iso.mesh_efficiency,
            });
        }
    }
    Ok(points)
}

/// The points as a Markdown table, ours beside ISO's (difference in efficiency points).
pub fn table(points: &[SpeedPoint]) -> String {
    let mut m = String::from(
        "| gear | worm speed (rpm) | v_g (m/s) | mu contact | asperity share | eta_z contact | \
         mu_0T ISO | eta_z ISO (mu_0T) | difference (points) | eta_z ISO (the gear's Y) | \
         difference (points) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for p in points {
        m.push_str(&format!(
            "| {} | {:.0} | {:.2} | {:.4} | {:.3} | {:.3} | {:.4} | {:.3} | {:+.1} | {:.3} | \
             {:+.1} |\n",
            p.gear,
            p.worm_speed_rpm,
            p.sliding_speed,
            p.friction,
            p.asperity_share,
            p.mesh_efficiency,
            p.iso_friction,
            p.iso_efficiency,
            100.0 * (p.mesh_efficiency - p.iso_efficiency),
            p.iso_efficiency_with_factors,
            100.0 * (p.mesh_efficiency - p.iso_efficiency_with_factors)
        ));
    }
    m
}

/// File names of the two charts [`charts`] writes.
pub const FRICTION_CHART: &str = "friction_over_sliding_speed.svg";
pub const EFFICIENCY_CHART: &str = "mesh_efficiency_over_sliding_speed.svg";

/// Charts of the mean friction and of the mesh efficiency over the sliding speed, ours beside
/// ISO's for each gear, written atomically into `dir`.
pub fn charts(points: &[SpeedPoint], dir: &Path) -> Result<(), crate::output::OutputError> {
    let mut gears: Vec<&str> = points.iter().map(|p| p.gear.as_str()).collect();
    gears.dedup();
    let series = |value: fn(&SpeedPoint) -> f64, iso: fn(&SpeedPoint) -> f64| {
        let mut all = Vec::new();
        for (k, gear) in gears.iter().enumerate() {
            let of = |f: fn(&SpeedPoint) -> f64| {
                points
                    .iter()
                    .filter(|p| p.gear == *gear)
                    .map(|p| (p.sliding_speed, f(p)))
                    .collect::<Vec<_>>()
            };
            all.push(Series {
                label: format!("{gear}: contact"),
                points: of(value),
                color: 2 * k,
                bold: true,
            });
            all.push(Series {
                label: format!("{gear}: ISO/TR 14521 mu_0T"),
                points: of(iso),
                color: 2 * k + 1,
                bold: false,
            });
        }
        all
    };
    type Value = fn(&SpeedPoint) -> f64;
    let charts: [(&str, &str, &str, Value, Value); 2] = [
        (
            FRICTION_CHART,
            "Mean mesh friction over the sliding speed (unworn, 60 C)",
            "mean friction coefficient",
            |p| p.friction,
            |p| p.iso_friction,
        ),
        (
            EFFICIENCY_CHART,
            "Mesh efficiency over the sliding speed (unworn, 60 C)",
            "mesh efficiency eta_z",
            |p| p.mesh_efficiency,
            |p| p.iso_efficiency,
        ),
    ];
    for (file, title, y_label, value, iso) in charts {
        let labels = (title, "sliding speed v_g (m/s)", y_label);
        plot::line_chart_marked(&dir.join(file), labels, &series(value, iso))?;
    }
    Ok(())
}

/// (e) Friction, efficiency and oil temperature from the contact (MODEL §13): the speed study
/// against ISO/TR 14521's mu_0T, the reference cases, and lives with the heat balance.
pub(super) fn section_e(
    m: &mut String,
    settings: &Settings,
    results: &Results,
    speeds: &[SpeedPoint],
) {
    let _ = writeln!(
        m,
        "## (e) Friction, efficiency and oil temperature from the contact\n\n\
         The contact's friction (MODEL §13: Greenwood & Tripp's asperity pressure at the central \
         film with Hertz's contact modulus, bounded by the wheel's hardness, at boundary friction \
         mu_b; Eyring's film shear bounded by Lambda p; the summit statistics, mu_b, tau_0 and \
         Lambda the examples' defaults; the reference gears' roughness, 1 um, assumed) on every \
         loaded cell; the loaded analysis carries it (MODEL §5.2).\n\n\
         **Against ISO/TR 14521's rig-fitted mu_0T over sliding speeds** (MODEL §13 validation \
         (1)): the 1/40 design gear and the K 2/25 gear at 60 N m on the worm, unworn, no \
         bending, oil at 60 C; ISO's eta_z = tan(gamma) / tan(gamma + atan(mu_0T)) with its \
         factors Y at 1, and ISO's mesh efficiency with the gear file's factors Y (the 1/40 \
         gear's: Y_S 0.894 of the standard, Y_W 0.95 and Y_R 0.88 assumed, the same as the \
         reference cases'; the K gear gives none, so 1). One set of inputs for every speed and \
         both gears.\n"
    );
    m.push_str(&table(speeds));
    let _ = writeln!(
        m,
        "\n![mean friction over the sliding speed]({dir}/{f})\n\n\
         ![mesh efficiency over the sliding speed]({dir}/{e})\n\n\
         **The reference cases** (unworn, FE bending, oil at 60 C) against ISO/TR 14521 with the \
         examples' factors Y and the published torques (wheel torque / (u x worm torque); \
         REFERENCE_GEARS.md derived them with ISO's total efficiency):\n",
        dir = super::FIGURES,
        f = FRICTION_CHART,
        e = EFFICIENCY_CHART,
    );
    reference_cases_table(m, settings, results);
    thermal_life_table(m, results);
}

/// The reference cases' unworn friction and efficiencies beside ISO/TR 14521 and the published
/// torques.
fn reference_cases_table(m: &mut String, settings: &Settings, results: &Results) {
    let _ = writeln!(
        m,
        "| case | mesh efficiency, contact | ISO/TR 14521 | total, contact | ISO/TR 14521 | published torques | mu contact | mu ISO |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|---|---|");
    for (name, id, file, published) in [
        (
            "design",
            "design-adaptive",
            "gear-1x40-design.toml",
            f64::NAN,
        ),
        (
            "A",
            "case-a",
            "gear-1x40-case-a.toml",
            1250.0 / (40.0 * 40.0),
        ),
        (
            "B",
            "case-b",
            "gear-1x40-case-b.toml",
            1375.0 / (40.0 * 44.0),
        ),
        (
            "C",
            "case-c",
            "gear-1x40-case-c.toml",
            1700.0 / (40.0 * 54.0),
        ),
    ] {
        let Some(first) = results.get(id).and_then(|r| r.records.first()) else {
            continue;
        };
        let Ok(gear) = super::example(settings, file) else {
            continue;
        };
        let iso = crate::rating::rate(&gear);
        let f = &first.friction;
        let _ = writeln!(
            m,
            "| {name} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {:.4} | {:.4} |",
            f.mesh_efficiency,
            iso.mesh_efficiency,
            f.total_efficiency,
            iso.efficiency,
            if published.is_nan() {
                "-".to_string()
            } else {
                format!("{published:.3}")
            },
            f.friction_coefficient_mean,
            iso.friction_coefficient
        );
    }
}

/// Case C and the speed study with the heat balance against the fixed 60 C: oil temperature
/// and efficiency at the start and the end, and the final backlash of both.
fn thermal_life_table(m: &mut String, results: &Results) {
    let _ = writeln!(
        m,
        "\nWith the oil temperature from the heat balance of the example's fan-cooled housing \
         (40 W/(m^2 K) over 1 m^2, 20 C ambient, assumed; the default housing cannot reject \
         these losses), each wear state's viscosity drives its film and local wear \
         coefficient:\n"
    );
    let _ = writeln!(
        m,
        "| worm speed | oil at start -> end (C) | total efficiency start -> end | backlash at the end, balance | at 60 C |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|");
    for (rpm, balance, fixed) in [
        (100, "speed-100-balance", "speed-100"),
        (600, "speed-600-balance", "speed-600"),
        (900, "c-balance", "case-c"),
        (1200, "speed-1200-balance", "speed-1200"),
    ] {
        let Some(r) = results.get(balance) else {
            continue;
        };
        let (Some(s), Some(e)) = (r.records.first(), r.records.last()) else {
            continue;
        };
        let fixed = results.get(fixed).and_then(|r| r.records.last());
        let _ = writeln!(
            m,
            "| {rpm} rpm | {:.1} -> {:.1} | {:.3} -> {:.3} | {:.1} um | {} |",
            s.friction.oil_temperature_k - 273.15,
            e.friction.oil_temperature_k - 273.15,
            s.friction.total_efficiency,
            e.friction.total_efficiency,
            e.backlash_increase_m * UM,
            fixed.map_or("-".to_string(), |f| format!(
                "{:.1} um",
                f.backlash_increase_m * UM
            ))
        );
    }
    m.push('\n');
}
