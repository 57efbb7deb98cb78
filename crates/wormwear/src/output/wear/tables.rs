//! The tables of a life: `wear_steps.csv` (one row per state), `wear_positions.csv` (TE and load
//! sharing per state and position), the node table of a map state, and the `wear` values of
//! summary.json.

use super::*;

/// The tables and curves over the states so far: `wear_steps.csv`, `wear_positions.csv`, the
/// `wear` section of summary.json and the curves over cycles.
pub(super) fn write_tables(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    view: &StepView,
    dir: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let state = view.state;
    let mut files = Vec::new();
    // Steps table and summary.
    let csv = steps_table(state);
    let path = dir.join("wear_steps.csv");
    csv.write(&path)?;
    files.push(path);
    let path = dir.join("wear_positions.csv");
    position_table(tca, &state.records).write(&path)?;
    files.push(path);
    let path = dir.join("wear_te_orders.csv");
    te_orders_table(&state.records).write(&path)?;
    files.push(path);
    update_summary(dir, "wear", summary_value(gear, geo, tca, plan, view)?)?;
    let limit = crate::wear::WearLimits::backlash_limit(gear, &crate::rating::rate(gear), plan);
    let charts = life_charts(&state.records, limit);
    for (name, title, y, series) in charts {
        let path = dir.join(name);
        line_chart(&path, &title, "wheel cycles (millions)", y, &series, false)?;
        files.push(path);
    }
    Ok(files)
}

/// The title of the TE-over-life chart: the range of the mean TE it leaves out, urad.
fn te_title(records: &[crate::wear::StepRecord]) -> String {
    let (m0, m1) = records
        .iter()
        .map(|r| r.te_mean_rad * UM)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    format!("Loaded TE peak to peak over life (mean TE {m0:.0} to {m1:.0} urad)")
}

/// The curves over cycles: (file, title, y label, series) of the backlash, wear depth,
/// transmission error, its mesh orders (MODEL §16), pressure, efficiency and oil temperature
/// charts.
fn life_charts(
    records: &[crate::wear::StepRecord],
    backlash_limit: (f64, f64),
) -> [(&'static str, String, &'static str, Vec<Series>); 7] {
    let curve = |f: &dyn Fn(&crate::wear::StepRecord) -> f64, label: &str, color: usize| Series {
        label: label.to_string(),
        points: records.iter().map(|r| (r.cycles * 1e-6, f(r))).collect(),
        color,
        bold: true,
    };
    [
        (
            "wear_backlash.svg",
            "Backlash increase (tangential at r2, mean over positions)".to_string(),
            "backlash increase (um)",
            with_limit_line(backlash_series(records), records, backlash_limit),
        ),
        (
            "wear_depth.svg",
            "Wear depth".to_string(),
            "depth (um)",
            vec![
                curve(&|r| r.max_wear_m * UM, "max (one node, mesh-dependent)", 1),
                curve(&|r| r.wear_patch_max_m * UM, "max over a patch", 2),
                curve(&|r| r.mean_wear_m * UM, "mean over the flank", 0),
            ],
        ),
        (
            "wear_transmission_error.svg",
            te_title(records),
            "TE peak to peak (urad, wheel)",
            vec![
                curve(&|r| r.te_p2p_rad * UM, "peak-to-peak", 2),
                curve(
                    &|r| r.te_p2p_relative_rad * UM,
                    "peak-to-peak relative to the wear's rigid lag",
                    4,
                ),
            ],
        ),
        (
            "wear_te_orders.svg",
            "Loaded TE by mesh order over life (amplitudes of the first harmonics of the \
             tooth-mesh frequency)"
                .to_string(),
            "amplitude (urad, wheel)",
            te_order_curves(records),
        ),
        (
            "wear_pressure.svg",
            "Contact pressure over life".to_string(),
            "pressure (MPa)",
            vec![
                curve(&|r| r.max_pressure_pa * MPA, "P_max (raw)", 1),
                curve(
                    &|r| r.pressure_patch_max_pa * MPA,
                    "P_patch (largest mean over a patch)",
                    2,
                ),
                curve(&|r| r.mean_pressure_pa * MPA, "P_mean", 0),
            ],
        ),
        (
            "wear_efficiency.svg",
            "Efficiency over life, from the contact's friction (MODEL §13)".to_string(),
            // A fraction, as the tables and summary.json give it.
            "efficiency (output / input power)",
            vec![
                curve(&|r| r.friction.mesh_efficiency, "mesh", 0),
                curve(&|r| r.friction.total_efficiency, "total", 1),
            ],
        ),
        (
            "wear_oil_temperature.svg",
            "Oil temperature over life (fixed, or the heat balance of each state)".to_string(),
            "oil temperature (C)",
            vec![curve(&|r| r.friction.oil_temperature_k - 273.15, "sump", 4)],
        ),
    ]
}

/// The loaded TE's mesh orders 1-4 over cycles (1e6, urad; MODEL §16).
fn te_order_curves(records: &[crate::wear::StepRecord]) -> Vec<Series> {
    let orders: Vec<(f64, Vec<f64>)> = records
        .iter()
        .map(|r| (r.cycles * 1e-6, r.te_orders().loaded_rad))
        .collect();
    (0..4)
        .map(|h| Series {
            label: format!("order {}", h + 1),
            points: orders
                .iter()
                .filter_map(|(x, a)| a.get(h).map(|v| (*x, v * UM)))
                .collect(),
            color: h,
            bold: true,
        })
        .filter(|s| !s.points.is_empty())
        .collect()
}

/// Per state and position: TE, TE relative to the wear's rigid lag, largest pressure and the
/// normal force on each studied tooth (load sharing over life, MODEL §7.7).
pub fn position_table(tca: &Tca, records: &[crate::wear::StepRecord]) -> Csv {
    let tooth_columns: Vec<String> = tca
        .teeth
        .iter()
        .map(|k| format!("tooth{k}_load_n"))
        .collect();
    let mut header = vec![
        "step",
        "cycles",
        "position",
        "te_rad",
        "te_relative_rad",
        "max_pressure_pa",
    ];
    header.extend(tooth_columns.iter().map(String::as_str));
    let mut csv = Csv::new(&header);
    for r in records {
        for (n, p) in r.positions.iter().enumerate() {
            let mut row = vec![
                r.step as f64,
                r.cycles,
                n as f64,
                p.te_rad,
                p.te_relative_rad,
                p.max_pressure_pa,
            ];
            row.extend(
                (0..tooth_columns.len()).map(|t| p.tooth_load_n.get(t).copied().unwrap_or(0.0)),
            );
            csv.row(&row);
        }
    }
    csv
}

/// Per state: step, cycles and the amplitudes of the mesh orders 1..k of the loaded TE and of
/// the unloaded KE, rad (MODEL §16; NaN where a state does not have them).
pub fn te_orders_table(records: &[crate::wear::StepRecord]) -> Csv {
    let orders: Vec<crate::ltca::TeOrders> = records.iter().map(|r| r.te_orders()).collect();
    let k = orders.iter().map(|o| o.loaded_rad.len()).max().unwrap_or(0);
    let mut header = vec!["step".to_string(), "cycles".to_string()];
    header.extend((1..=k).map(|h| format!("loaded_te_order{h}_rad")));
    header.extend((1..=k).map(|h| format!("kinematic_error_order{h}_rad")));
    let mut csv = Csv::new(&header.iter().map(String::as_str).collect::<Vec<_>>());
    for (r, o) in records.iter().zip(&orders) {
        let at = |v: &[f64], h: usize| v.get(h).copied().unwrap_or(f64::NAN);
        let mut row = vec![r.step as f64, r.cycles];
        row.extend((0..k).map(|h| at(&o.loaded_rad, h)));
        row.extend((0..k).map(|h| at(&o.unloaded_rad, h)));
        csv.row(&row);
    }
    csv
}

/// The columns of `wear_steps.csv` (units in the names) and how each reads a record.
type StepColumn = (&'static str, fn(&crate::wear::StepRecord) -> f64);

const STEP_COLUMNS: [StepColumn; 46] = [
    ("step", |r| r.step as f64),
    ("cycles", |r| r.cycles),
    ("step_cycles", |r| r.step_cycles),
    ("max_wear_m", |r| r.max_wear_m),
    ("wear_patch_max_m", |r| r.wear_patch_max_m),
    ("mean_wear_m", |r| r.mean_wear_m),
    ("worn_volume_m3", |r| r.worn_volume_m3),
    ("backlash_m", |r| r.backlash_m),
    ("backlash_increase_m", |r| r.backlash_increase_m),
    ("max_pressure_pa", |r| r.max_pressure_pa),
    ("mean_pressure_pa", |r| r.mean_pressure_pa),
    ("contact_area_fraction", |r| r.contact_area_fraction),
    ("s1", |r| r.s1),
    ("s2", |r| r.s2),
    ("te_mean_rad", |r| r.te_mean_rad),
    ("te_p2p_rad", |r| r.te_p2p_rad),
    ("mesh_stiffness_mean_nm_per_rad", |r| {
        r.mesh_stiffness_mean_nm_per_rad
    }),
    ("max_wear_per_cycle_m", |r| r.max_wear_per_cycle_m),
    ("lambda_min", |r| r.lambda_min),
    ("substeps", |r| r.substeps as f64),
    ("loaded_analyses", |r| r.loaded_analyses as f64),
    ("pressure_patch_max_pa", |r| r.pressure_patch_max_pa),
    ("rigid_lag_rad", |r| r.rigid_lag_rad),
    ("te_mean_relative_rad", |r| r.te_mean_relative_rad),
    ("te_p2p_relative_rad", |r| r.te_p2p_relative_rad),
    ("n_li_model_cycles", |r| {
        r.n_li_model_cycles.unwrap_or(f64::NAN)
    }),
    ("pitted_area_fraction", |r| r.pitted_area_fraction),
    ("thinnest_tooth_um", |r| r.thinnest_tooth_m * UM),
    ("worn_through_loaded", |r| {
        f64::from(u8::from(r.worn_through_loaded))
    }),
    ("power_balance", |r| r.power_balance),
    ("max_damage", |r| r.max_damage),
    ("max_plastic_set_m", |r| r.max_plastic_set_m),
    ("max_plastic_indentation_m", |r| r.max_plastic_indentation_m),
    ("yielded_area_fraction", |r| r.yielded_area_fraction),
    ("equivalent_pressure_max_pa", |r| {
        r.equivalent_pressure_max_pa
    }),
    ("equivalent_pressure_first_pitting_pa", |r| {
        r.equivalent_pressure_first_pitting_pa
    }),
    ("first_pitting_edge_share", |r| r.first_pitting_edge_share),
    ("area_damage", |r| r.area_damage),
    ("friction_coefficient_mean", |r| {
        r.friction.friction_coefficient_mean
    }),
    ("mesh_loss_w", |r| r.friction.mesh_loss_w),
    ("mesh_efficiency", |r| r.friction.mesh_efficiency),
    ("total_efficiency", |r| r.friction.total_efficiency),
    ("oil_temperature_c", |r| {
        r.friction.oil_temperature_k - 273.15
    }),
    ("viscosity_pa_s", |r| r.friction.viscosity_pa_s),
    ("roughness_mean_m", |r| r.roughness_mean_m),
    ("roughness_min_m", |r| r.roughness_min_m),
];

/// The table of states (`wear_steps.csv`): one row per record ([`STEP_COLUMNS`]).
pub fn steps_table(state: &WearState) -> Csv {
    let names: Vec<&str> = STEP_COLUMNS.iter().map(|c| c.0).collect();
    let mut csv = Csv::new(&names);
    for r in &state.records {
        let row: Vec<f64> = STEP_COLUMNS.iter().map(|c| (c.1)(r)).collect();
        csv.row(&row);
    }
    csv
}

/// The `wear` section of summary.json after the state of `view`.
pub fn summary_value(
    gear: &GearSet,
    geo: &Geometry,
    tca: &Tca,
    plan: &WearPlan,
    view: &StepView,
) -> Result<serde_json::Value, OutputError> {
    let state = view.state;
    let summary = WearSummary {
        life_cycles: plan.life_cycles,
        step_control: &plan.step,
        bending_model: &view.ltca.bending_model,
        film_load: plan.film_load,
        pit_depth: plan.pit_depth,
        damage_node_reading: plan.damage_node_reading,
        states: state.records.len(),
        loaded_analyses: state.records.last().map_or(0, |r| r.loaded_analyses),
        max_pressure_definition: MAX_PRESSURE_DEFINITION,
        mesh_dependent: MESH_DEPENDENT,
        limits: LimitsSummary::new(gear, geo, tca, plan, state),
        pitting: plan.pitting,
        phases: crate::wear::forecast::phase_spans(&state.records),
        area_first_pitting_cycles: crate::wear::forecast::area_first_pitting_cycles(
            &state.records,
            &plan.endurance,
        ),
        found_phases: &state.found_phases,
        warnings: state.warnings(
            geo.wheel_flank(tca.loaded_flank),
            plan.pitting_onset_share,
            &plan.endurance,
        ),
        steps: state
            .records
            .iter()
            .map(|r| crate::wear::StepRecord {
                positions: Vec::new(),
                ..r.clone()
            })
            .collect(),
        te_orders: state
            .records
            .iter()
            .map(|r| StateTeOrders {
                step: r.step,
                cycles: r.cycles,
                orders: r.te_orders(),
            })
            .collect(),
    };
    serde_json::to_value(&summary).map_err(|e| OutputError::Encode {
        what: "wear summary".into(),
        message: e.to_string(),
    })
}

/// The backlash increase over cycles (1e6, um): the whole curve, and its pitting phases drawn
/// over it in orange (no wear: flat).
/// The backlash curves with the life's backlash limit as a line across the
/// cycles, when the curve reaches a quarter of it (else the limit would flatten the curve; the
/// legend then gives it in words). `(limit, per)`: the tangential backlash limit, m, and the
/// normal flank loss per unit of it ([`crate::wear::WearLimits::backlash_limit`]), so that the
/// legend also gives it as the flank loss the safety table reads.
fn with_limit_line(
    mut series: Vec<Series>,
    records: &[crate::wear::StepRecord],
    (limit, per): (f64, f64),
) -> Vec<Series> {
    let (Some(first), Some(last)) = (records.first(), records.last()) else {
        return series;
    };
    let reached = records
        .iter()
        .map(|r| r.backlash_increase_m)
        .fold(0.0, f64::max);
    let label = format!(
        "backlash limit {:.0} um (tangential; {:.0} um of normal flank loss)",
        limit * UM,
        limit * per * UM
    );
    if reached >= 0.25 * limit {
        series.push(Series {
            label,
            points: vec![
                (first.cycles * 1e-6, limit * UM),
                (last.cycles * 1e-6, limit * UM),
            ],
            color: 3,
            bold: false,
        });
    } else if let Some(s) = series.first_mut() {
        let note = format!("{label}: above the scale");
        s.label = if s.label.is_empty() {
            format!("increase ({note})")
        } else {
            format!("{} ({note})", s.label)
        };
    }
    series
}

pub(super) fn backlash_series(records: &[crate::wear::StepRecord]) -> Vec<Series> {
    let points = |rs: &[crate::wear::StepRecord]| -> Vec<(f64, f64)> {
        rs.iter()
            .map(|r| (r.cycles * 1e-6, r.backlash_increase_m * UM))
            .collect()
    };
    let spans = crate::wear::forecast::phase_spans(records);
    let pitting: Vec<_> = spans.iter().filter(|s| s.kind == "pitting").collect();
    let mut series = vec![Series {
        label: if pitting.is_empty() {
            String::new()
        } else {
            "wear".into()
        },
        points: points(records),
        color: 0,
        bold: true,
    }];
    for (k, s) in pitting.iter().enumerate() {
        let inside: Vec<_> = records
            .iter()
            .filter(|r| r.cycles >= s.start_cycles && r.cycles <= s.end_cycles)
            .cloned()
            .collect();
        series.push(Series {
            label: if k == 0 {
                "pitting phase".into()
            } else {
                String::new()
            },
            points: points(&inside),
            color: 4,
            bold: true,
        });
    }
    series
}

/// The node table of a state (`wear_map.csv`): per loaded-flank node (i up the height, j
/// across the face) its (r, z) mm, cumulative wear m, wear per cycle m, film ratio and film
/// thickness m, damage, the plastic set m once the state has run in
/// ([`WearState::plastic_set_after`], read at the nodes), and the equivalent pressure of the
/// state's analysis `l` at the node, Pa (MODEL §8.1: the largest of its cells', the damage's
/// default node reading).
pub fn node_table(
    wf: &crate::geometry::WheelFlank,
    state: &WearState,
    cycle: &crate::wear::CycleWear,
    plastic_set: &FlankField,
    l: &crate::ltca::Ltca,
) -> Csv {
    let plastic_set = plastic_set.with_rows(wf.cells_height);
    let mut csv = Csv::new(&[
        "i",
        "j",
        "r_mm",
        "z_mm",
        "wear_m",
        "wear_per_cycle_m",
        "lambda",
        "film_m",
        "damage",
        "plastic_set_m",
        "equivalent_pressure_pa",
    ]);
    for j in 0..=wf.cells_face {
        for i in 0..=wf.cells_height {
            let k = j * (wf.cells_height + 1) + i;
            let n = wf.node(i, j);
            csv.row(&[
                i as f64,
                j as f64,
                n.r * 1e3,
                n.z * 1e3,
                state.removal.values[k],
                cycle.depth.values[k],
                cycle.lambda.values[k],
                cycle.film.values[k],
                state.damage.get(k).copied().unwrap_or(0.0),
                plastic_set.values.get(k).copied().unwrap_or(0.0),
                crate::wear::forecast::node_equivalent(
                    wf,
                    l,
                    k,
                    crate::input::NodeReading::Largest,
                )
                .0,
            ]);
        }
    }
    csv
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mesh_dependent_field_is_a_column_of_the_states_table() {
        // `mesh_dependent` names fields of the per-state records (a qualifier in brackets, such
        // as "(worn states)", after the name): each must be a column readers can find.
        let names: Vec<&str> = STEP_COLUMNS.iter().map(|c| c.0).collect();
        for entry in super::super::MESH_DEPENDENT {
            let field = entry.split(" (").next().unwrap();
            assert!(names.contains(&field), "{entry}: no such column");
        }
    }
}
