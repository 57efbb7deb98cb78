//! `[conditions]` and `[[duty_cycle]]` (MODEL §14): one operating point or a load spectrum,
//! each bin's torque, speed, time share and oil temperature.

use super::*;

/// Most bins of a spectrum: each costs a loaded analysis at every state of a life.
const MAX_BINS: usize = 50;

/// How far the time shares may sum from 1 (round-off of decimal shares; they are then scaled
/// to sum to 1). Shares that do not sum to 1 are a mistake to name, not to scale away: hours
/// are for durations that need not.
const SHARE_SUM_TOLERANCE: f64 = 1e-9;

/// What the operating sections give: the conditions the gear is analysed at (with a
/// spectrum, its bin of the largest load), the spectrum's bins (empty for one point) and
/// that bin's oil temperature when it has its own, K.
pub(super) struct Operation {
    pub conditions: Conditions,
    pub bins: Vec<DutyBin>,
    pub oil_temperature: Option<f64>,
}

/// The operating point of `[conditions]` or the spectrum of `[[duty_cycle]]` (exactly one of
/// them); a spectrum of one bin is that point. `ratio` orders the bins by load (None: the
/// thread or teeth are invalid, their own errors come).
pub(super) fn operation(
    ck: &mut Checker,
    f: &GearFile,
    lubricant: Option<&Lubricant>,
    housing: Option<&Housing>,
    ratio: Option<f64>,
) -> Option<Operation> {
    let empty = Vec::new();
    let bins = f.duty_cycle.as_ref().unwrap_or(&empty);
    if f.duty_cycle.as_ref().is_some_and(|b| b.is_empty()) {
        ck.fail(
            "duty_cycle",
            "(no bins)",
            "an empty spectrum: give at least one [[duty_cycle]] table, or [conditions]",
        );
        return None;
    }
    match (&f.conditions, bins.is_empty()) {
        (Some(c), true) => Some(Operation {
            conditions: conditions(ck, "conditions", c)?,
            bins: Vec::new(),
            oil_temperature: None,
        }),
        (Some(_), false) => {
            ck.fail(
                "duty_cycle",
                format!("{} bins", bins.len()),
                "give [conditions] (one operating point) or [[duty_cycle]] (a load spectrum), \
                 not both",
            );
            None
        }
        (None, true) => {
            ck.fail(
                "conditions",
                "(missing)",
                "give [conditions] (worm_torque_nm or wheel_torque_nm, worm_speed_rpm) or a \
                 load spectrum as [[duty_cycle]] tables",
            );
            None
        }
        (None, false) => spectrum(ck, bins, f, (lubricant?, housing?), ratio?),
    }
}

/// The worm speed the housing's default heat transfer is taken at, rpm: that of
/// `[conditions]`, or of the spectrum's bin of the largest load ([`largest_load_bin`]'s
/// order on the file's values; 1 as the ratio where the thread or teeth are invalid).
pub(super) fn reference_speed_rpm(f: &GearFile, ratio: Option<f64>) -> f64 {
    if let Some(c) = &f.conditions {
        return c.worm_speed_rpm;
    }
    let u = ratio.unwrap_or(1.0);
    let load = |b: &DutyBinSpec| {
        b.wheel_torque_nm
            .or(b.worm_torque_nm.map(|t| u * t))
            .unwrap_or(0.0)
    };
    let mut best: Option<&DutyBinSpec> = None;
    for b in f.duty_cycle.iter().flatten() {
        if best.is_none_or(|x| load(b) > load(x)) {
            best = Some(b);
        }
    }
    best.map_or(0.0, |b| b.worm_speed_rpm)
}

/// The bins of `[[duty_cycle]]` (counted from 1 in messages), their shares scaled to sum to 1.
fn spectrum(
    ck: &mut Checker,
    specs: &[DutyBinSpec],
    f: &GearFile,
    (lubricant, housing): (&Lubricant, &Housing),
    ratio: f64,
) -> Option<Operation> {
    if specs.len() > MAX_BINS {
        ck.fail(
            "duty_cycle",
            format!("{} bins", specs.len()),
            format!("at most {MAX_BINS} bins (each is a loaded analysis at every state)"),
        );
        return None;
    }
    let shares = time_shares(ck, specs)?;
    let given_transfer = f.housing.heat_transfer_w_m2k.is_some();
    let mut bins = Vec::new();
    for (k, (b, share)) in specs.iter().zip(shares).enumerate() {
        let name = format!("duty_cycle[{}]", k + 1);
        let spec = ConditionsSpec {
            worm_torque_nm: b.worm_torque_nm,
            wheel_torque_nm: b.wheel_torque_nm,
            worm_speed_rpm: b.worm_speed_rpm,
        };
        let conditions = conditions(ck, &name, &spec);
        let oil = bin_oil_temperature(ck, &name, b.oil_temperature_c, housing);
        let (Some(conditions), Some(oil)) = (conditions, oil) else {
            continue;
        };
        let heat_transfer = match given_transfer {
            true => housing.heat_transfer,
            false => default_heat_transfer(b.worm_speed_rpm),
        };
        bins.push(DutyBin {
            conditions,
            time_share: share,
            oil_temperature: oil.unwrap_or(lubricant.temperature),
            heat_transfer,
        });
    }
    if bins.len() != specs.len() {
        return None;
    }
    let largest = largest_load_bin(&bins, ratio);
    let own_oil = specs[largest]
        .oil_temperature_c
        .map(|_| bins[largest].oil_temperature);
    let conditions = bins[largest].conditions.clone();
    Some(Operation {
        conditions,
        bins: if bins.len() > 1 { bins } else { Vec::new() },
        oil_temperature: own_oil,
    })
}

/// Each bin's share of the running time: `time_share` in every bin (summing to 1 within
/// [`SHARE_SUM_TOLERANCE`]) or `hours` in every bin, scaled to sum to 1.
fn time_shares(ck: &mut Checker, bins: &[DutyBinSpec]) -> Option<Vec<f64>> {
    let by_share = bins
        .iter()
        .all(|b| b.time_share.is_some() && b.hours.is_none());
    let by_hours = bins
        .iter()
        .all(|b| b.hours.is_some() && b.time_share.is_none());
    if !by_share && !by_hours {
        // The first bin with both or neither, or of another kind than the first.
        let kind = |b: &DutyBinSpec| (b.time_share.is_some(), b.hours.is_some());
        let k = bins
            .iter()
            .position(|b| kind(b).0 == kind(b).1 || kind(b) != kind(&bins[0]))
            .unwrap_or(0);
        ck.fail(
            &format!("duty_cycle[{}]", k + 1),
            "time_share / hours",
            "give every bin either time_share (shares summing to 1) or hours, one of the two",
        );
        return None;
    }
    let mut values = Vec::new();
    for (k, b) in bins.iter().enumerate() {
        let v = match by_share {
            true => ck.positive(
                &format!("duty_cycle[{}].time_share", k + 1),
                b.time_share.unwrap_or_default(),
                1.0,
                "(a share of the running time)",
            ),
            false => ck.positive(
                &format!("duty_cycle[{}].hours", k + 1),
                b.hours.unwrap_or_default(),
                1e7,
                "h",
            ),
        };
        values.push(v?);
    }
    let total: f64 = values.iter().sum();
    if by_share && (total - 1.0).abs() > SHARE_SUM_TOLERANCE {
        ck.fail(
            "duty_cycle.time_share",
            total,
            format!(
                "the bins' time shares sum to {total}; they must sum to 1 (within \
                 {SHARE_SUM_TOLERANCE:e}), or give each bin's hours instead"
            ),
        );
        return None;
    }
    Some(values.iter().map(|v| v / total).collect())
}

/// A bin's own oil temperature, K (Some(None): the lubricant's); refused with the heat
/// balance, which finds it.
fn bin_oil_temperature(
    ck: &mut Checker,
    name: &str,
    celsius: Option<f64>,
    housing: &Housing,
) -> Option<Option<f64>> {
    let Some(c) = celsius else { return Some(None) };
    let field = format!("{name}.oil_temperature_c");
    if housing.balance {
        ck.fail(
            &field,
            c,
            "a bin's oil temperature is found by the heat balance with lubricant.temperature = \
             \"balance\"; leave it out, or use a fixed oil temperature",
        );
        return None;
    }
    ck.range(&field, c, -50.0, 250.0, "degC")
        .map(|c| Some(c + 273.15))
}
