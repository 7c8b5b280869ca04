//! Probe and renderer costs in one run (issue #6): `cargo bench -p sphere-quadrature-eval --bench probe`.
//!
//! - probe `irradiance` (O(N)) against the cosine-weighted average query it competes with, at
//!   N = 64 and 256, on the same samples and normals;
//! - probe `update` (per-probe selection over the whole family, and one fixed member);
//! - the renderer form's `w·Y` (`bmc::Renderer::estimate`).
//!
//! Compare the ratios within one run; the machine is shared.

#![allow(missing_docs)] // `criterion_group!` expands to an undocumented `pub fn`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sphere_quadrature::bmc::{Renderer, Size};
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize, Selection};
use sphere_quadrature::Vec3;

fn normals() -> Vec<Vec3> {
    (0..64)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f32 / 64.0;
            let phi = i as f32 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect()
}

fn samples<const N: usize>(dirs: &[Vec3; N]) -> [f32; N] {
    core::array::from_fn(|i| {
        let d = dirs[i];
        1.0 + 0.5 * d.z + 2.0 * (8.0 * (d.x - 1.0)).exp() + 0.1 * (17.0 * d.y).sin()
    })
}

fn probe_group<const N: usize>(c: &mut Criterion)
where
    Size<N>: ProbeSize,
{
    let mut probe = Probe::<N>::new();
    let y = samples(probe.directions());
    probe.update(&y).unwrap();
    let ns = normals();
    let mut g = c.benchmark_group(format!("probe N={N} (64 queries per iteration)"));
    g.bench_function("BMC probe irradiance", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &n in black_box(&ns) {
                s += probe.irradiance(n).map(|e| e.value).unwrap_or(0.0);
            }
            s
        })
    });
    g.bench_function("cosine-weighted average", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &n in black_box(&ns) {
                s += cosine_weighted_average(probe.directions(), &y, n).unwrap_or(0.0);
            }
            s
        })
    });
    g.finish();
    let mut g = c.benchmark_group(format!("probe N={N} update"));
    g.bench_function("update (max-likelihood selection over the family)", |b| {
        b.iter(|| black_box(&mut probe).update(black_box(&y)))
    });
    g.bench_function("update_with one member", |b| {
        b.iter(|| black_box(&mut probe).update_with(black_box(&y), Selection::Member(1)))
    });
    g.finish();
}

fn renderer(c: &mut Criterion) {
    let r = Renderer::<64>::new();
    let y: [f32; 64] = core::array::from_fn(|i| 1.0 + i as f32 * 0.01);
    c.bench_function("renderer N=64 w·Y", |b| b.iter(|| r.estimate(black_box(&y))));
}

fn bench(c: &mut Criterion) {
    probe_group::<64>(c);
    probe_group::<256>(c);
    renderer(c);
}

criterion_group!(benches, bench);
criterion_main!(benches);
