//! One H and one C table lookup against the closed forms they replace, in one run:
//! `cargo bench -p sphere-quadrature-eval --bench sg_lookup`. The closed forms are written here in f32 with the same
//! `libm` functions the library uses, so both sides pay for the same math.

#![allow(missing_docs)] // `criterion_group!` expands to an undocumented `pub fn`

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use sphere_quadrature::sg;

/// Tokuyoshi 2022: H/F (hemispherical integral over the full-sphere integral), f32.
#[inline(never)]
fn tokuyoshi2022_hemi(lambda: f32, t: f32) -> f32 {
    const A: f32 = 0.651_732_9;
    const B: f32 = 1.341_828;
    const C: f32 = 7.221_669;
    let s = lambda * libm::sqrtf((0.5 * lambda + A) / ((lambda + B) * lambda + C));
    let v = 0.5 + 0.5 * libm::erff(s * t.clamp(-1.0, 1.0)) / libm::erff(s);
    let e = libm::expf(-lambda);
    (e + v * (1.0 - e)) / (1.0 + e)
}

/// Tokuyoshi et al. 2024: C/F (SG × clamped cosine over the full-sphere integral), f32, for
/// λ > 0.5 (the branch the benchmark's inputs take).
#[inline(never)]
fn tokuyoshi2024_clamped(lambda: f32, t: f32) -> f32 {
    const A: f32 = 2.736_083;
    const B: f32 = 17.021_297;
    const C: f32 = 4.010_083;
    const D: f32 = 15.219_156;
    const E: f32 = 76.087_9;
    let l = lambda;
    let tau = l * libm::sqrtf(0.5 * ((l + A) * l + B) / (((l + C) * l + D) * l + E));
    let tz = tau * t;
    let v = 0.5 * (t * libm::erfcf(-tz) + libm::erfcf(tau))
        - 0.5
            * 0.564_189_6 // 1/√π
            * libm::expf(-tz * tz)
            * libm::expm1f(tau * tau * (t * t - 1.0))
            / tau;
    let e = libm::expf(-l);
    let em = -libm::expm1f(-l) / l;
    let upper = (1.0 - em) / l;
    let lower = e * (em - e) / l;
    // Over 2π, then over the full-sphere integral / 2π = (1 − e^(−2λ))/λ.
    (lower + v * (upper - lower)) * l / -libm::expm1f(-2.0 * l)
}

fn inputs() -> Vec<(f32, f32)> {
    // Sharpness 1…10⁴ log-spaced, cosines over [−1, 1]; fixed, so both sides see the same data.
    (0..1024)
        .map(|i| {
            let l = 10f32.powf(4.0 * ((i * 37) % 1024) as f32 / 1024.0);
            let t = -1.0 + 2.0 * ((i * 101) % 1021) as f32 / 1021.0;
            (l, t)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let pts = inputs();
    let mut g = c.benchmark_group("sg_lookup (1024 (λ, t) per iteration)");
    g.bench_function("table H/F", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, t) in black_box(&pts) {
                s += sg::hemispherical_fraction(l, t).unwrap_or(0.0);
            }
            s
        })
    });
    g.bench_function("Tokuyoshi 2022 H/F", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, t) in black_box(&pts) {
                s += tokuyoshi2022_hemi(l, t);
            }
            s
        })
    });
    g.bench_function("table C/F", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, t) in black_box(&pts) {
                s += sg::clamped_cosine_fraction(l, t).unwrap_or(0.0);
            }
            s
        })
    });
    g.bench_function("Tokuyoshi 2024 C/F", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(l, t) in black_box(&pts) {
                s += tokuyoshi2024_clamped(l, t);
            }
            s
        })
    });
    g.finish();
    // Sanity: the f32 closed forms are the ones the tests compare (to their own accuracy).
    for &(l, t) in &pts {
        let h = sg::hemispherical_fraction(l, t).unwrap();
        let c = sg::clamped_cosine_fraction(l, t).unwrap();
        assert!((tokuyoshi2022_hemi(l, t) - h).abs() < 1e-2, "{l} {t}");
        assert!((tokuyoshi2024_clamped(l, t) - c).abs() < 3e-3, "{l} {t}");
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
