//! `wormwear rating`: the safety table from the model (MODEL §9.1) of the loaded analysis and,
//! with a life plan, the life; printed and written with the run's files.
use super::{analyse, load, planned_request, Failure, LifeArgs};
use std::path::Path;

/// The safety table (MODEL §9.1): the loaded analysis and, with a life plan, the life.
pub(crate) fn rating(
    file: &Path,
    dir: &Path,
    args: &LifeArgs,
    quiet: bool,
    verbose: bool,
) -> Result<(), Failure> {
    use wormwear::Stage;
    let gear = load(file)?;
    let request = planned_request(
        dir,
        &gear,
        args,
        (&[Stage::Ltca, Stage::Wear], &[Stage::Ltca]),
    )?;
    let (results, _) = analyse(file, &gear, (dir, args.force), request, quiet, verbose)?;
    if let (Some(table), false) = (&results.safety, quiet) {
        if let Some(s) = &results.spectrum {
            println!("{}", duty_cycle_lines(s));
        }
        print_safety(table);
        // Beside the table: whether the wheel can drive the worm (MODEL §15).
        if let Some(lock) = results
            .thermal
            .as_ref()
            .and_then(|t| t.self_locking.as_ref())
        {
            println!("{}", self_locking_line(lock));
        }
        println!("results in {}", dir.display());
    }
    Ok(())
}

/// The safety table on stdout, one line per row.
pub(crate) fn print_safety(table: &wormwear::safety::SafetyTable) {
    let cell = |v: Option<f64>| match v {
        Some(x) if x.is_finite() => format!("{x:.4}"),
        Some(_) => "inf".into(),
        None => "-".into(),
    };
    println!(
        "safety (MODEL §9.1; K_A {}, required life {}):",
        table.application_factor,
        table
            .required_cycles
            .map_or("not given".into(), |n| format!("{n:.4e} wheel cycles"))
    );
    println!(
        "  {:<8} {:>12} {:>12} {:>8} {:>8}  {:<6} verdict",
        "symbol", "value", "allowable", "safety", "minimum", "unit"
    );
    for r in &table.rows {
        println!(
            "  {:<8} {:>12} {:>12} {:>8} {:>8}  {:<6} {}",
            r.symbol,
            cell(r.value),
            cell(r.allowable),
            cell(r.safety),
            r.minimum,
            r.unit,
            r.verdict.text()
        );
        if !r.assumed.is_empty() {
            println!("  {:<8} on assumed inputs: {}", "", r.assumed.join(", "));
        }
    }
}

/// The back-driving line (MODEL §15): eta' at rest and running, each with its verdict.
pub(crate) fn self_locking_line(lock: &wormwear::friction::SelfLocking) -> String {
    let verdict = |locked: bool| {
        if locked {
            "self-locking"
        } else {
            "back-drivable"
        }
    };
    format!(
        "back-driving (MODEL §15): static eta' {:.3}, {} (boundary friction {} against the \
         {:.4} it locks from); running eta' {:.3}, {}",
        lock.static_efficiency,
        verdict(lock.static_self_locking),
        lock.boundary_friction,
        lock.locking_friction,
        lock.dynamic_efficiency,
        verdict(lock.dynamic_self_locking)
    )
}

/// The duty cycle's lines (MODEL §14): the spectrum's energy-weighted efficiency and Miner's
/// pitting life, then one line per bin.
pub(crate) fn duty_cycle_lines(spectrum: &wormwear::spectrum::Spectrum) -> String {
    let life = spectrum
        .pitting_life_cycles
        .map_or("none".to_string(), |n| format!("{n:.3e} wheel cycles"));
    let mut text = format!(
        "duty cycle (MODEL §14; {} bins, the analysis above is bin {} of the largest load): \
         efficiency {:.4} (mesh {:.4}) over the energy; first pit by Miner's sum {life} \
         (damage-equivalent p_eq {:.0} MPa); mean worm speed {:.0} rpm\n",
        spectrum.bins.len(),
        spectrum.largest_load_bin,
        spectrum.total_efficiency,
        spectrum.mesh_efficiency,
        spectrum.equivalent_pressure_pa * 1e-6,
        spectrum.mean_worm_speed_rpm
    );
    text.push_str(
        "  bin  worm N m  wheel N m     rpm   time  cycles  oil C    eta  wear %  damage %\n",
    );
    for b in &spectrum.bins {
        text.push_str(&format!(
            "  {:>3}  {:>8.2}  {:>9.1}  {:>6.0}  {:>5.3}  {:>6.3}  {:>5.1}  {:>5.3}  {:>6.1}  {:>8.1}\n",
            b.bin,
            b.worm_torque_nm,
            b.wheel_torque_nm,
            b.worm_speed_rpm,
            b.time_share,
            b.cycle_share,
            b.oil_temperature_c,
            b.total_efficiency,
            100.0 * b.wear_share,
            100.0 * b.damage_share
        ));
    }
    text.trim_end().to_string()
}
