//! `wormwear compare`: finished runs side by side.

use crate::Failure;
use std::path::{Path, PathBuf};
use wormwear::output::compare::{compare as gather, write_comparison, CompareError};

/// Compares the runs of `dirs` into `output` (compare.html, compare.csv, the overlaid curves)
/// and prints the key results.
pub fn compare(dirs: &[PathBuf], output: &Path, quiet: bool) -> Result<(), Failure> {
    let comparison = gather(dirs).map_err(|e| match e {
        CompareError::TooFew(_) | CompareError::NotARun { .. } | CompareError::Summary { .. } => {
            Failure::Input(e.into())
        }
    })?;
    let page = write_comparison(&comparison, output).map_err(|e| Failure::Run(e.into()))?;
    if !quiet {
        let first = &comparison.runs[0].label;
        for r in &comparison.runs {
            match &r.differences {
                Some(d) if d.is_empty() => println!("{}: the inputs of {first}", r.label),
                Some(d) => println!(
                    "{}: inputs that differ from {first}: {}",
                    r.label,
                    d.join("; ")
                ),
                None => {}
            }
        }
        let labels: Vec<&str> = comparison.runs.iter().map(|r| r.label.as_str()).collect();
        println!("{:<40} {:<12} {}", "quantity", "unit", labels.join("  "));
        for row in &comparison.rows {
            let values: Vec<String> = row
                .values
                .iter()
                .map(|v| v.map_or("-".into(), wormwear::output::text::number))
                .collect();
            println!(
                "{:<40} {:<12} {}",
                row.quantity,
                row.unit,
                values.join("  ")
            );
        }
        println!("comparison in {}", page.display());
    }
    Ok(())
}
