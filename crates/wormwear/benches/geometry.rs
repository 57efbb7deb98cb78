//! Geometry and TCA benchmarks (targets: 1/40 geometry, 60 x 40 grid per flank, under 1 s;
//! full TCA of the 1/40 gear, 20 positions x 5 teeth x default grid, under 0.2 s; LTCA one
//! position under 20 ms, 20 positions under 0.5 s).
//! Run: cargo bench -p wormwear --bench geometry
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use wormwear::geometry::{Geometry, GeometryInputs, ThreadSurface};
use wormwear::input;

fn example(name: &str) -> input::GearSet {
    input::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name),
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let g140 = example("gear-1x40-design.toml");
    let gk = example("gear-k-2x25.toml");
    let mut group = c.benchmark_group("geometry");
    group.sample_size(20);
    // `generate`, not `build_with_grid`: the build would return its kept copy after the first.
    let (i140, ik) = (
        GeometryInputs::of(&g140, 40, 60),
        GeometryInputs::of(&gk, 40, 60),
    );
    group.bench_function("1x40 worm + wheel, 40 x 60 cells per flank", |b| {
        b.iter(|| Geometry::generate(black_box(&i140)).unwrap())
    });
    group.bench_function("2x25 ZK worm + wheel, 40 x 60 cells per flank", |b| {
        b.iter(|| Geometry::generate(black_box(&ik)).unwrap())
    });
    group.bench_function("ZK thread surface (grinding envelope table)", |b| {
        b.iter(|| ThreadSurface::new(black_box(&gk.worm)).unwrap())
    });
    group.finish();
    let mut group = c.benchmark_group("tca");
    group.sample_size(20);
    let geo = Geometry::build(&g140).unwrap();
    group.bench_function(
        "1x40 full TCA, 20 positions x 5 teeth x 40 x 60 grid",
        |b| b.iter(|| wormwear::kinematics::analyse(black_box(&g140), black_box(&geo)).unwrap()),
    );
    group.finish();
    let mut group = c.benchmark_group("ltca");
    group.sample_size(10);
    let tca = wormwear::kinematics::analyse(&g140, &geo).unwrap();
    group.bench_function(
        "1x40 LTCA, 20 positions, default local mesh, no bending",
        |b| {
            b.iter(|| {
                wormwear::ltca::analyse(black_box(&g140), black_box(&geo), black_box(&tca)).unwrap()
            })
        },
    );
    // The sub-surface equivalent pressure of those 20 positions (MODEL §8.1; issue 32's
    // target: under 20 % of the LTCA), positions in parallel as the LTCA computes them.
    let loaded = wormwear::ltca::analyse(&g140, &geo, &tca).unwrap();
    let subsurface = wormwear::ltca::LtcaSettings::from_gear(&g140).subsurface;
    group.bench_function(
        "1x40 equivalent pressure below the flank, 20 positions",
        |b| {
            b.iter(|| {
                use rayon::prelude::*;
                loaded
                    .positions
                    .par_iter()
                    .map(|p| wormwear::ltca::position_equivalents(black_box(p), &subsurface).len())
                    .sum::<usize>()
            })
        },
    );
    let mut one = g140.clone();
    one.analysis.positions = 1;
    let tca1 = wormwear::kinematics::analyse(&one, &geo).unwrap();
    group.bench_function("1x40 LTCA, one position", |b| {
        b.iter(|| {
            wormwear::ltca::analyse(black_box(&one), black_box(&geo), black_box(&tca1)).unwrap()
        })
    });
    group.finish();
    let mut group = c.benchmark_group("bending");
    group.sample_size(10);
    let mesh = wormwear::bending::wheel_mesh::SectorMeshSettings {
        across: 4,
        height: 6,
        rim: 2,
        space: 2,
        face_step: 6,
        rim_thickness: 0.02,
        web: None,
    };
    group.bench_function(
        "1x40 wheel bending model (sector FE 6117 nodes, 2 x 30 load cases, 5 x 6 basis)",
        |b| {
            b.iter(|| {
                wormwear::bending::wheel_model::WheelBending::build(
                    black_box(&g140),
                    black_box(&geo),
                    &mesh,
                    None,
                    5,
                    6,
                )
                .unwrap()
            })
        },
    );
    group.finish();
    // One wear step of the design case (target 0.5 s): loaded analysis on a worn flank, wear of
    // one cycle, backlash, geometry update.
    let mut group = c.benchmark_group("wear");
    group.sample_size(10);
    let tca = wormwear::kinematics::analyse(&g140, &geo).unwrap();
    let wf = geo.wheel_flank(tca.loaded_flank);
    let backlash = wormwear::wear::Backlash::new(&g140, &geo, &tca);
    let settings = wormwear::ltca::LtcaSettings::from_gear(&g140);
    let mut removal = wormwear::geometry::FlankField::zeros(wf);
    let l = wormwear::ltca::analyse(&g140, &geo, &tca).unwrap();
    let first = wormwear::wear::per_cycle(
        &g140,
        &geo,
        &tca,
        &l,
        wormwear::input::FilmLoad::LoadedAnalysis,
    );
    for (h, d) in removal.values.iter_mut().zip(&first.depth.values) {
        *h = 5000.0 * d;
    }
    group.bench_function(
        "1x40 one wear step (LTCA on the worn flank + wear + backlash)",
        |b| {
            b.iter(|| {
                let l = wormwear::ltca::analyse_worn(
                    black_box(&g140),
                    &geo,
                    &tca,
                    &settings,
                    None,
                    Some(&removal),
                    None,
                )
                .unwrap();
                let w = wormwear::wear::per_cycle(
                    &g140,
                    &geo,
                    &tca,
                    &l,
                    wormwear::input::FilmLoad::LoadedAnalysis,
                );
                let mut next = removal.clone();
                for (h, d) in next.values.iter_mut().zip(&w.depth.values) {
                    *h += 1000.0 * d;
                }
                backlash.stats(&next)
            })
        },
    );
    // A state of a wear life: the loaded analysis of a worn flank started from the previous
    // state's loads (what the life loop does at every state after the first).
    let previous =
        wormwear::ltca::analyse_worn(&g140, &geo, &tca, &settings, None, Some(&removal), None)
            .unwrap();
    let warm = previous.warm_start();
    let rate = wormwear::wear::per_cycle(
        &g140,
        &geo,
        &tca,
        &previous,
        wormwear::input::FilmLoad::LoadedAnalysis,
    );
    let mut worn = removal.clone();
    for (h, d) in worn.values.iter_mut().zip(&rate.depth.values) {
        *h += 1000.0 * d;
    }
    group.bench_function(
        "1x40 LTCA of a wear-life state (worn flank, warm start, 20 positions)",
        |b| {
            b.iter(|| {
                wormwear::ltca::analyse_worn(
                    black_box(&g140),
                    &geo,
                    &tca,
                    &settings,
                    None,
                    Some(&worn),
                    Some(&warm),
                )
                .unwrap()
            })
        },
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
