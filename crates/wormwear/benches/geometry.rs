//! Geometry benchmarks (issue: 1/40 worm and wheel with a 60 x 40 grid per flank under 1 s).
//! Run: cargo bench -p wormwear --bench geometry
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;
use wormwear::geometry::{Geometry, ThreadSurface};
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
    group.bench_function("1x40 worm + wheel, 40 x 60 cells per flank", |b| {
        b.iter(|| Geometry::build_with_grid(black_box(&g140), 40, 60).unwrap())
    });
    group.bench_function("2x25 ZK worm + wheel, 40 x 60 cells per flank", |b| {
        b.iter(|| Geometry::build_with_grid(black_box(&gk), 40, 60).unwrap())
    });
    group.bench_function("ZK thread surface (grinding envelope table)", |b| {
        b.iter(|| ThreadSurface::new(black_box(&gk.worm)).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
