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
    bench_geometry(c, &g140, &gk);
    let geo = Geometry::build(&g140).unwrap();
    bench_tca(c, &g140, &geo);
    bench_ltca(c, &g140, &geo);
    bench_bending(c, &g140, &geo);
    bench_wear(c, &g140, &geo);
}

/// The hobbing simulation and the ZK thread surface.
fn bench_geometry(c: &mut Criterion, g140: &input::GearSet, gk: &input::GearSet) {
    let mut group = c.benchmark_group("geometry");
    group.sample_size(20);
    // `generate`, not `build_with_grid`: the build would return its kept copy after the first.
    let (i140, ik) = (
        GeometryInputs::of(g140, 40, 60),
        GeometryInputs::of(gk, 40, 60),
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
}

/// The unloaded meshing analysis of the 1/40 gear.
fn bench_tca(c: &mut Criterion, g140: &input::GearSet, geo: &Geometry) {
    let mut group = c.benchmark_group("tca");
    group.sample_size(20);
    group.bench_function(
        "1x40 full TCA, 20 positions x 5 teeth x 40 x 60 grid",
        |b| b.iter(|| wormwear::kinematics::analyse(black_box(g140), black_box(geo)).unwrap()),
    );
    group.finish();
}

/// The loaded analysis of the 1/40 gear (20 positions and one), and the sub-surface
/// equivalent pressure of its 20 positions.
fn bench_ltca(c: &mut Criterion, g140: &input::GearSet, geo: &Geometry) {
    let mut group = c.benchmark_group("ltca");
    group.sample_size(10);
    let tca = wormwear::kinematics::analyse(g140, geo).unwrap();
    group.bench_function(
        "1x40 LTCA, 20 positions, default local mesh, no bending",
        |b| {
            b.iter(|| {
                wormwear::ltca::analyse(black_box(g140), black_box(geo), black_box(&tca)).unwrap()
            })
        },
    );
    // The sub-surface equivalent pressure of those 20 positions (MODEL §8.1; issue 32's
    // target: under 20 % of the LTCA), positions in parallel as the LTCA computes them.
    let loaded = wormwear::ltca::analyse(g140, geo, &tca).unwrap();
    let subsurface = wormwear::ltca::LtcaSettings::from_gear(g140).subsurface;
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
    let tca1 = wormwear::kinematics::analyse(&one, geo).unwrap();
    group.bench_function("1x40 LTCA, one position", |b| {
        b.iter(|| {
            wormwear::ltca::analyse(black_box(&one), black_box(geo), black_box(&tca1)).unwrap()
        })
    });
    group.finish();
}

/// The wheel's FE bending model of the 1/40 gear on a coarse sector mesh.
fn bench_bending(c: &mut Criterion, g140: &input::GearSet, geo: &Geometry) {
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
                    black_box(g140),
                    black_box(geo),
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
}

/// The flank change `scale` times the per-cycle wear depth of the loaded analysis `l`, added
/// to `removal`, m.
fn worn_by(
    g140: &input::GearSet,
    geo: &Geometry,
    tca: &wormwear::kinematics::Tca,
    l: &wormwear::ltca::Ltca,
    removal: &mut wormwear::geometry::FlankField,
    scale: f64,
) {
    let w = wormwear::wear::per_cycle(g140, geo, tca, l, wormwear::input::FilmLoad::LoadedAnalysis);
    for (h, d) in removal.values.iter_mut().zip(&w.depth.values) {
        *h += scale * d;
    }
}

/// One wear step of the design case (target 0.5 s: loaded analysis on a worn flank, wear of
/// one cycle, backlash, geometry update), and the loaded analysis of a life's state.
fn bench_wear(c: &mut Criterion, g140: &input::GearSet, geo: &Geometry) {
    let mut group = c.benchmark_group("wear");
    group.sample_size(10);
    let tca = wormwear::kinematics::analyse(g140, geo).unwrap();
    let wf = geo.wheel_flank(tca.loaded_flank);
    let backlash = wormwear::wear::Backlash::new(g140, geo, &tca);
    let settings = wormwear::ltca::LtcaSettings::from_gear(g140);
    let mut removal = wormwear::geometry::FlankField::zeros(wf);
    let l = wormwear::ltca::analyse(g140, geo, &tca).unwrap();
    worn_by(g140, geo, &tca, &l, &mut removal, 5000.0);
    let worn_analysis = |removal: &wormwear::geometry::FlankField, warm| {
        wormwear::ltca::analyse_worn(
            black_box(g140),
            geo,
            &tca,
            &settings,
            None,
            Some(removal),
            warm,
        )
        .unwrap()
    };
    group.bench_function(
        "1x40 one wear step (LTCA on the worn flank + wear + backlash)",
        |b| {
            b.iter(|| {
                let l = worn_analysis(&removal, None);
                let mut next = removal.clone();
                worn_by(g140, geo, &tca, &l, &mut next, 1000.0);
                backlash.stats(&next)
            })
        },
    );
    // A state of a wear life: the loaded analysis of a worn flank started from the previous
    // state's loads (what the life loop does at every state after the first).
    let previous = worn_analysis(&removal, None);
    let warm = previous.warm_start();
    let mut worn = removal.clone();
    worn_by(g140, geo, &tca, &previous, &mut worn, 1000.0);
    group.bench_function(
        "1x40 LTCA of a wear-life state (worn flank, warm start, 20 positions)",
        |b| b.iter(|| worn_analysis(&worn, Some(&warm))),
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
