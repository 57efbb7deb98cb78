//! Bending benchmarks (issue 5 targets: FE bending coefficients of both members of the 1/40 gear
//! under 15 s from a cold cache and under 50 ms from the cache).
//! Run: cargo bench -p wormwear --bench bending
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use wormwear::bending::model::{build_in, compute};
use wormwear::geometry::Geometry;
use wormwear::input::{self, BendingKind};
use wormwear::ltca::{self, LtcaSettings};

fn bench(c: &mut Criterion) {
    let mut g = input::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/gear-1x40-design.toml"),
    )
    .unwrap();
    g.bending.kind = BendingKind::Fe;
    let geo = Geometry::build(&g).unwrap();
    let mut group = c.benchmark_group("bending");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    group.bench_function("1x40 FE bending of worm and wheel, cold (no cache)", |b| {
        b.iter(|| compute(black_box(&g), &geo).unwrap())
    });
    let dir = tempfile::tempdir().unwrap();
    let (built, _) = build_in(&g, &geo, Some(dir.path())).unwrap();
    group.bench_function("1x40 FE bending of worm and wheel, from the cache", |b| {
        b.iter(|| build_in(black_box(&g), &geo, Some(dir.path())).unwrap())
    });
    let tca = wormwear::kinematics::analyse(&g, &geo).unwrap();
    let settings = LtcaSettings::from_gear(&g);
    group.bench_function("1x40 LTCA 20 positions with FE bending", |b| {
        b.iter(|| {
            ltca::analyse_with(black_box(&g), &geo, &tca, &settings, Some(&built.model)).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
