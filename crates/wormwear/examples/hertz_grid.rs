//! The Hertz sphere on a plane (R 10 mm, 100 N, steel on bronze) on an n x n grid spanning
//! +-`span` Hertz radii, solved by the LTCA's PK solver; prints one JSON line: cells, the
//! operator used, set-up and solve times (s), PK iterations, peak pressure and contact radius
//! over Hertz's, load residual and the process's peak resident memory (MB, VmHWM).
//! The benchmark beside Tamaas (`scripts/hertz-vs-tamaas`) runs it.
//!
//! Usage: `cargo run --release -p wormwear --example hertz_grid -- N [SPAN] [auto|assembled]`
//! (SPAN default 1.4; `assembled` and `fft` force an operator, `auto` is the program's choice).

use std::time::Instant;
use wormwear::contact::{GridInfluence, InfluenceRows};
use wormwear::ltca::solver::{solve, Block, BlockMatrix, SolverSettings};
use wormwear::validation::analytic::{flat_cells, flat_problem, steel_on_bronze};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(64);
    let span: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1.4);
    let forced = args.get(2).map(String::as_str).unwrap_or("auto");
    let (radius, load) = (10e-3, 100.0);
    let pair = steel_on_bronze();
    let a = (3.0 * load * radius / (4.0 * pair.effective_modulus)).cbrt();
    let p0 = 3.0 * load / (2.0 * std::f64::consts::PI * a * a);
    let h = span * a / n as f64;
    let started = Instant::now();
    let cells = flat_cells(n, n, h, h);
    let mut problem = flat_problem(&cells, |c| (c.x * c.x + c.y * c.y) / (2.0 * radius), load);
    let levers = vec![1.0; cells.len()];
    let matrix = match forced {
        "assembled" => Some(BlockMatrix::Lazy(Box::new(InfluenceRows::new(
            &pair, &cells, &levers,
        )))),
        "fft" => GridInfluence::new(&pair, &cells, &levers).map(|g| BlockMatrix::Grid(Box::new(g))),
        _ => None,
    };
    if let Some(matrix) = matrix {
        problem.blocks = vec![Block {
            start: 0,
            size: cells.len(),
            matrix,
        }];
    }
    let operator = match problem.blocks[0].matrix {
        BlockMatrix::Grid(_) => "fft",
        _ => "assembled",
    };
    let set_up = started.elapsed().as_secs_f64();
    let settings = SolverSettings::default();
    let solution = solve(&problem, &settings, None).expect("the Hertz problem solves");
    let solve_s = started.elapsed().as_secs_f64() - set_up;
    let area = cells[0].area();
    let p_max = solution.q.iter().copied().fold(0.0, f64::max) / area;
    // Contact radius from the second moment of the load: <r^2> = 2 a^2 / 5 for Hertz.
    let r2: f64 = cells
        .iter()
        .zip(&solution.q)
        .map(|(c, q)| q * (c.centre.x.powi(2) + c.centre.y.powi(2)))
        .sum::<f64>()
        / load;
    let peak_mb = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0);
    println!(
        "{}",
        serde_json::json!({
            "cells": cells.len(),
            "operator": operator,
            "set_up_s": set_up,
            "solve_s": solve_s,
            "iterations": solution.residuals.iterations,
            "p_max_over_p0": p_max / p0,
            "radius_over_a": (2.5 * r2).sqrt() / a,
            "load_residual": solution.residuals.load,
            "complementarity": solution.residuals.complementarity,
            "peak_memory_mb": peak_mb,
        })
    );
}
