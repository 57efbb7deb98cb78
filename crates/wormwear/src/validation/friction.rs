//! MODEL §13's first validation: the contact's friction and mesh efficiency over sliding speeds
//! 0.3-8 m/s on the 1/40 and the K 2/25 gears, beside ISO/TR 14521's rig-fitted base friction
//! mu_0T (MODEL §9; its factors Y at 1) and the efficiency it gives, tan(gamma) /
//! tan(gamma + atan(mu_0T)). One set of inputs (the examples') for every speed and both gears;
//! unworn flanks, no bending, the lubricant's fixed temperature.

use super::{example, Settings, ValidationError};
use crate::friction::MeshContacts;
use crate::geometry::Geometry;
use crate::input::BendingKind;
use crate::output::plot::{self, Series};
use std::path::Path;

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
            });
        }
    }
    Ok(points)
}

/// The points as a Markdown table, ours beside ISO's (difference in efficiency points).
pub fn table(points: &[SpeedPoint]) -> String {
    let mut m = String::from(
        "| gear | worm speed (rpm) | v_g (m/s) | mu contact | asperity share | eta_z contact | \
         mu_0T ISO | eta_z ISO (mu_0T) | difference (points) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for p in points {
        m.push_str(&format!(
            "| {} | {:.0} | {:.2} | {:.4} | {:.3} | {:.3} | {:.4} | {:.3} | {:+.1} |\n",
            p.gear,
            p.worm_speed_rpm,
            p.sliding_speed,
            p.friction,
            p.asperity_share,
            p.mesh_efficiency,
            p.iso_friction,
            p.iso_efficiency,
            100.0 * (p.mesh_efficiency - p.iso_efficiency)
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
