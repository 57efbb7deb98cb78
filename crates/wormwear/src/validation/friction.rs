//! MODEL §13's first validation: the contact's friction and mesh efficiency over sliding speeds
//! 0.3-8 m/s on the 1/40 and the K 2/25 gears, beside ISO/TR 14521's rig-fitted base friction
//! mu_0T (MODEL §9; its factors Y at 1) and the efficiency it gives, tan(gamma) /
//! tan(gamma + atan(mu_0T)). One set of inputs (the examples') for every speed and both gears;
//! unworn flanks, no bending, the lubricant's fixed temperature.
//! Also section (e) of the report: that study, the reference cases and the lives with the heat
//! balance.

use super::{example, Results, Settings, ValidationError};
use crate::friction::MeshContacts;
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
/// slowest and the fastest speed of each), with the examples' own friction inputs; each unworn
/// analysis read from `store` when it holds one of the same inputs ([`Store`]).
pub fn over_speeds(settings: &Settings, store: &Store) -> Result<Vec<SpeedPoint>, ValidationError> {
    speed_points(settings, store, None)
}

/// [`over_speeds`] with the film's limiting shear coefficient Lambda set to `limiting_shear`
/// on both gears (None: the examples' own).
fn speed_points(
    settings: &Settings,
    store: &Store,
    limiting_shear: Option<f64>,
) -> Result<Vec<SpeedPoint>, ValidationError> {
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
            if let Some(lambda) = limiting_shear {
                g.friction.limiting_shear = lambda;
            }
            let mut id = format!("friction-{}-{rpm:.0}", name.trim_end_matches(".toml"));
            if let Some(lambda) = limiting_shear {
                id.push_str(&format!("-lambda-{lambda}"));
            }
            let unworn = store.unworn_friction(&g, &id)?;
            let iso = crate::rating::rate(&g);
            let mu0 = crate::rating::base_friction(iso.sliding_speed_m_s);
            points.push(SpeedPoint {
                gear: name.trim_end_matches(".toml").to_string(),
                worm_speed_rpm: rpm,
                sliding_speed: iso.sliding_speed_m_s,
                friction: unworn.friction,
                asperity_share: unworn.asperity_share,
                mesh_efficiency: unworn.mesh_efficiency,
                torque_efficiency: unworn.torque_efficiency,
                iso_friction: mu0,
                iso_efficiency: crate::rating::base_mesh_efficiency(&g),
                iso_efficiency_with_factors: iso.mesh_efficiency,
            });
        }
    }
    Ok(points)
}

/// The unworn gear's friction from its loaded analysis (with its bending model, from the
/// cache when built before).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct UnwornFriction {
    friction: f64,
    asperity_share: f64,
    /// P2 / (P2 + P_Vz) from the contact's loss.
    mesh_efficiency: f64,
    /// T2 / (u T1), the loaded analysis' torques.
    torque_efficiency: f64,
}

/// Where the friction studies keep their unworn analyses between calls of the study: one
/// sealed file per analysis (`<id>.json`, [`crate::integrity`]) with the text of its inputs
/// (gear, study version, program), read back only when that text is the same, as the jobs'
/// results are ([`super::run`]). Counts what it read and what it computed.
pub struct Store {
    dir: Option<std::path::PathBuf>,
    read: std::cell::Cell<usize>,
    computed: std::cell::Cell<usize>,
}

/// A stored unworn analysis: its inputs' text and its friction.
#[derive(serde::Serialize, serde::Deserialize)]
struct Stored {
    key: String,
    friction: UnwornFriction,
}

impl Store {
    /// A store in the folder `dir` (made when first written); None: every analysis computed,
    /// nothing kept.
    pub fn new(dir: Option<&Path>) -> Self {
        Store {
            dir: dir.map(Path::to_path_buf),
            read: std::cell::Cell::new(0),
            computed: std::cell::Cell::new(0),
        }
    }

    /// The analyses read from the store and computed so far.
    pub fn counts(&self) -> (usize, usize) {
        (self.read.get(), self.computed.get())
    }

    /// [`unworn_friction`] of `g`, from the store when it holds the same inputs under `id`,
    /// else computed and stored.
    fn unworn_friction(
        &self,
        g: &crate::input::GearSet,
        id: &str,
    ) -> Result<UnwornFriction, ValidationError> {
        let key = serde_json::json!({
            "version": super::STUDY_VERSION,
            "program": crate::PROGRAM,
            "gear": g,
        })
        .to_string();
        let path = self.dir.as_ref().map(|d| d.join(format!("{id}.json")));
        let stored = path.as_ref().and_then(|p| {
            let text = crate::files::read_text(p, crate::files::OWN_FILE_LIMIT).ok()?;
            // (A file that fails its checksum is computed again.)
            let s: Stored = crate::integrity::open(&text).ok()?;
            (s.key == key).then_some(s.friction)
        });
        if let Some(friction) = stored {
            self.read.set(self.read.get() + 1);
            return Ok(friction);
        }
        let friction = unworn_friction(g, id)?;
        self.computed.set(self.computed.get() + 1);
        if let Some(path) = path {
            let text = crate::integrity::seal(&Stored {
                key,
                friction: friction.clone(),
            })
            .map_err(|e| ValidationError::Job {
                id: id.to_string(),
                message: e.to_string(),
            })?;
            crate::output::write_atomic(&path, text.as_bytes())?;
        }
        Ok(friction)
    }
}

/// The unworn loaded analysis of `g` ([`super::Unworn`]) and its contact's friction (MODEL
/// §13); a failure is reported as the job `id`'s.
fn unworn_friction(g: &crate::input::GearSet, id: &str) -> Result<UnwornFriction, ValidationError> {
    let u = super::Unworn::analyse(g, id)?;
    let contacts = MeshContacts::new(g, &u.geo, &u.tca, &u.ltca);
    let f = contacts.friction(&g.lubricant, &g.friction);
    Ok(UnwornFriction {
        friction: f.mean_coefficient,
        asperity_share: f.asperity_share,
        mesh_efficiency: contacts.output_power / (contacts.output_power + f.mesh_loss_w),
        torque_efficiency: u.ltca.mesh_efficiency,
    })
}

/// The film's limiting shear coefficients Lambda of the window study (MODEL §13; the
/// default [`crate::input::DEFAULT_LIMITING_SHEAR`] and the former default 0.02 among them).
pub const LIMITING_SHEAR_STUDY: [f64; 9] =
    [0.012, 0.013, 0.014, 0.015, 0.016, 0.018, 0.02, 0.022, 0.025];

/// One Lambda of the window study: the speed study's largest departures from ISO/TR 14521
/// on each gear, and case C's unworn mesh efficiency beside ISO's.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LimitingShearRow {
    /// Lambda, the limiting shear stress over pressure.
    pub limiting_shear: f64,
    /// Per gear of [`SPEED_STUDY`], in its order: (gear, the largest departure of the
    /// contact's mesh efficiency from ISO's with the gear's factors Y, the same with the
    /// factors at 1), in efficiency points, signed (the departure of largest magnitude).
    pub departures: Vec<(String, f64, f64)>,
    /// Case C unworn (its example: FE bending, 54 N m, 900 rpm): the contact's mesh
    /// efficiency and ISO/TR 14521's with the example's factors Y.
    pub case_c_efficiency: f64,
    pub case_c_iso_efficiency: f64,
    /// The speed study at this Lambda.
    pub points: Vec<SpeedPoint>,
}

/// The window study: for each Lambda of [`LIMITING_SHEAR_STUDY`] (with `settings.quick` the
/// smallest only), the speed study on both gears and case C unworn, the other
/// inputs the examples'. Lambda is the input that sets the film's friction where the film
/// shears at its limit (most of the loaded flank at these pressures).
pub fn limiting_shear_window(
    settings: &Settings,
    store: &Store,
) -> Result<Vec<LimitingShearRow>, ValidationError> {
    let lambdas = if settings.quick {
        // The smoke run: the machinery on one value (the test command runs it twice).
        vec![LIMITING_SHEAR_STUDY[0]]
    } else {
        LIMITING_SHEAR_STUDY.to_vec()
    };
    let mut rows = Vec::new();
    for lambda in lambdas {
        let points = speed_points(settings, store, Some(lambda))?;
        let largest = |gear: &str, iso: fn(&SpeedPoint) -> f64| {
            points
                .iter()
                .filter(|p| p.gear == gear)
                .map(|p| 100.0 * (p.mesh_efficiency - iso(p)))
                .fold(0.0, |a: f64, d| if d.abs() > a.abs() { d } else { a })
        };
        let departures = SPEED_STUDY
            .iter()
            .map(|(name, _)| {
                let gear = name.trim_end_matches(".toml");
                let with_factors = largest(gear, |p| p.iso_efficiency_with_factors);
                (
                    gear.to_string(),
                    with_factors,
                    largest(gear, |p| p.iso_efficiency),
                )
            })
            .collect();
        let mut c = example(settings, "gear-1x40-case-c.toml")?;
        c.friction.limiting_shear = lambda;
        let unworn = store.unworn_friction(&c, &format!("friction-case-c-lambda-{lambda}"))?;
        rows.push(LimitingShearRow {
            limiting_shear: lambda,
            departures,
            case_c_efficiency: unworn.mesh_efficiency,
            case_c_iso_efficiency: crate::rating::rate(&c).mesh_efficiency,
            points,
        });
    }
    Ok(rows)
}

/// The window study as a Markdown table (departures in efficiency points).
pub fn limiting_shear_table(rows: &[LimitingShearRow]) -> String {
    let mut m = String::from("| Lambda |");
    let mut rule = String::from("|---|");
    if let Some(first) = rows.first() {
        for (gear, _, _) in &first.departures {
            let _ = write!(
                m,
                " {gear}: largest departure, ISO with the gear's Y | with Y = 1 |"
            );
            rule.push_str("---|---|");
        }
    }
    m.push_str(" case C unworn, contact | ISO (the example's Y) | difference |\n");
    rule.push_str("---|---|---|\n");
    m.push_str(&rule);
    for r in rows {
        let _ = write!(m, "| {} |", r.limiting_shear);
        for (_, with_factors, at_one) in &r.departures {
            let _ = write!(m, " {with_factors:+.1} | {at_one:+.1} |");
        }
        let _ = writeln!(
            m,
            " {:.3} | {:.3} | {:+.1} |",
            r.case_c_efficiency,
            r.case_c_iso_efficiency,
            100.0 * (r.case_c_efficiency - r.case_c_iso_efficiency)
        );
    }
    m
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
    (speeds, window): (&[SpeedPoint], &[LimitingShearRow]),
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
         reference cases'; the K gear's: Y_S 0.868 from its centre distance the same way, Y_W \
         and Y_R assumed as the 1/40's, the same bronze and worm finish). One set of inputs \
         for every speed and both gears.\n"
    );
    m.push_str(&table(speeds));
    let _ = writeln!(
        m,
        "\n**The film's limiting shear Lambda** (MODEL §13; the default {}, 0.02 before session 55: \
         within the 0.009-0.027 measured for polyglycols, README, and set on ISO's level with the \
         gears' factors Y by this study, one value for every gear and speed): where \
         the film shears at its limit Lambda p, as it does on most of the loaded flank at these \
         pressures, Lambda sets the film's friction, so it is the input that decides the level \
         of the friction at speed; the asperities decide its rise at low speed. The same study \
         at each Lambda, the other inputs the examples': on each gear the largest departure of \
         the contact's mesh efficiency from ISO's over the seven speeds (points, signed), with \
         the gear's factors Y and with Y = 1, and case C unworn (FE bending) beside ISO's with \
         its example's factors (issue 53 asks for 3 points in each column).\n",
        crate::input::DEFAULT_LIMITING_SHEAR
    );
    m.push_str(&limiting_shear_table(window));
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
    const BALANCE: [&str; 4] = [
        "speed-100-balance",
        "speed-600-balance",
        "c-balance",
        "speed-1200-balance",
    ];
    // (A --jobs run without them: no table.)
    if !BALANCE.iter().any(|id| results.contains_key(*id)) {
        return;
    }
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
