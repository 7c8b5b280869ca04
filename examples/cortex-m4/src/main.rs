//! sphere-quadrature on an emulated Cortex-M4F (QEMU `mps2-an386`).
//!
//! Prints the shared scenario (`scenario.rs`, compared bit for bit with the host by
//! `.ci/run`), then instruction counts measured with SysTick (lines starting with `#`).
//!
//! ```text
//! cd examples/cortex-m4 && cargo run --release
//! ```
#![no_std]
#![no_main]

mod scenario;

use core::hint::black_box;

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Kind, Point};
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::{bmc, probe, sg, sh, temporal};
use sphere_quadrature::{Lobe, SphericalFibonacci, Vec3};

struct Semihosting;

impl scenario::Sink for Semihosting {
    fn line(&mut self, args: core::fmt::Arguments<'_>) {
        hprintln!("{}", args);
    }
}

/// Instructions per call of `f`, from SysTick ticks over `reps` calls. With
/// `-icount shift=0` QEMU retires one instruction per ns and SysTick runs at 25 MHz: one
/// tick per 40 instructions. The empty-loop overhead is subtracted.
fn count<T>(reps: u32, mut f: impl FnMut() -> T) -> u32 {
    let run = |f: &mut dyn FnMut()| {
        let start = SYST::get_current();
        for _ in 0..reps {
            f();
        }
        let end = SYST::get_current();
        start.wrapping_sub(end) & 0x00FF_FFFF
    };
    let empty = run(&mut || {
        black_box(());
    });
    let full = run(&mut || {
        black_box(f());
    });
    (full.saturating_sub(empty) as u64 * 40 / reps as u64) as u32
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else { exit(debug::EXIT_FAILURE) };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();

    scenario::run(&mut Semihosting);

    let n = black_box(Vec3::new(0.3, -0.4, 0.5));
    let sky = |d: Vec3| black_box(d.z);
    macro_rules! report {
        ($name:literal, $n:literal, $reps:literal, $f:expr) => {
            hprintln!("# count {} N={} {} instructions/call", $name, $n, count($reps, $f));
        };
    }
    report!("sf_points", 16, 20, || SphericalFibonacci::<16>::new().points());
    report!("sf_points", 64, 10, || SphericalFibonacci::<64>::new().points());
    report!("sf_points", 256, 4, || SphericalFibonacci::<256>::new().points());
    report!("qmc_irradiance", 16, 20, || qmc::irradiance::<16, f32, _>(n, 1, sky));
    report!("qmc_irradiance", 64, 10, || qmc::irradiance::<64, f32, _>(n, 1, sky));
    report!("qmc_irradiance", 256, 4, || qmc::irradiance::<256, f32, _>(n, 1, sky));
    let ys = [black_box(1.5f32); 256];
    if let (Ok(s16), Ok(s64), Ok(s256)) = (
        LobeSampler::new(n, Lobe::Cosine, 16, 1),
        LobeSampler::new(n, Lobe::Cosine, 64, 1),
        LobeSampler::new(n, Lobe::Cosine, 256, 1),
    ) {
        report!("qmc_estimate_from_samples", 16, 200, || s16.estimate(black_box(&ys[..16])));
        report!("qmc_estimate_from_samples", 64, 100, || s64.estimate(black_box(&ys[..64])));
        report!("qmc_estimate_from_samples", 256, 50, || s256.estimate(black_box(&ys[..256])));
    }
    let sf256 = SphericalFibonacci::<256>::new();
    let sf4096 = SphericalFibonacci::<4096>::new();
    report!("nearest_index", 256, 50, || sf256.nearest_index(black_box(n)));
    report!("nearest_index", 4096, 50, || sf4096.nearest_index(black_box(n)));

    // Issue #6 calls: renderer w·Y, probe update and irradiance against the cosine-weighted
    // average query, and one SG table lookup.
    let r16 = bmc::Renderer::<16>::new();
    let r64 = bmc::Renderer::<64>::new();
    let r256 = bmc::Renderer::<256>::new();
    let y16: &[f32; 16] = ys.first_chunk().unwrap_or(&[1.0; 16]);
    let y64: &[f32; 64] = ys.first_chunk().unwrap_or(&[1.0; 64]);
    report!("renderer_w_dot_y", 16, 200, || r16.estimate(black_box(y16)));
    report!("renderer_w_dot_y", 64, 100, || r64.estimate(black_box(y64)));
    report!("renderer_w_dot_y", 256, 50, || r256.estimate(black_box(&ys)));
    // Issue #12: the glossy renderer's estimate (weight interpolation in θₙ + w·Y), Phong
    // e = 50, next to the QMC slice-form estimate above.
    // The directions are opaque to the optimiser (constants would fold the interval search
    // away); each call loads them.
    let (gn, gr) = black_box((Vec3::new(0.0, 0.3, 0.95), Vec3::new(0.5, 0.1, 0.86)));
    let g16 = bmc::GlossyRenderer::<16, 50>::new();
    let g64 = bmc::GlossyRenderer::<64, 50>::new();
    let g80 = bmc::GlossyRenderer::<80, 50>::new();
    let y80: &[f32; 80] = ys.first_chunk().unwrap_or(&[1.0; 80]);
    report!("glossy_renderer_estimate", 16, 100, || g16.estimate(gn, gr, black_box(y16)));
    report!("glossy_renderer_estimate", 64, 50, || g64.estimate(gn, gr, black_box(y64)));
    report!("glossy_renderer_estimate", 80, 50, || g80.estimate(gn, gr, black_box(y80)));
    // The footprint renderer at the same N, query and exponent: the estimate, and the estimate
    // with its error bar (lookups that vary, so that no channel is constant).
    let f64r = bmc::FootprintRenderer::<64, bmc::footprint::Phong<50>>::new();
    let yv: [f32; 64] = core::array::from_fn(|j| 1.0 + 0.01 * j as f32);
    report!("footprint_renderer_estimate", 64, 50, || f64r.estimate(gn, gr, black_box(y64)));
    report!("footprint_renderer_estimate_with_variance", 64, 10, || {
        f64r.estimate_with_variance(gn, gr, black_box(&yv))
    });
    probe_counts::<16, Point>("probe", 20, 200);
    probe_counts::<64, Point>("probe", 4, 100);
    probe_counts::<256, Point>("probe", 1, 50);
    // Footprint probes (issue #11), next to the point probe of the same N: photodiodes
    // (`CosinePower<1>`) at N = 16 and 32, the Gaussian footprint of sharpness 8 at N = 64.
    probe_counts::<32, Point>("probe", 10, 100);
    probe_counts::<16, CosinePower<1>>("photodiode_probe", 20, 200);
    probe_counts::<32, CosinePower<1>>("photodiode_probe", 10, 100);
    probe_counts::<64, Gaussian<8>>("gaussian8_probe", 4, 100);
    // Issue #14: the SH query of an RGB expansion, and the rotation.
    let rgb = sh::ShL2::new(core::array::from_fn(|k| {
        let v = 1.0 / (1.0 + k as f32);
        [v, 0.5 * v, -0.25 * v]
    }));
    let rgb = black_box(rgb);
    let unit = black_box(n.try_normalize().unwrap_or(Vec3::Z));
    report!("sh_irradiance_rgb", 9, 2000, || black_box(&rgb).irradiance(unit));
    let m = black_box(sphere_quadrature::Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0), 0.4));
    report!("sh_rotated_rgb", 9, 200, || black_box(&rgb).rotated(&m));
    // Issue #14: masked updates at N = 64 with capacity 8 and 16 (8 and 16 samples missing,
    // and none), and the queries after one.
    masked_counts::<8>(&[0, 8]);
    masked_counts::<16>(&[0, 16]);
    // The temporal probe at a budget of N rays (N − S rotated, S sentinels): update and the
    // irradiance query, and without sentinels at N = 64.
    temporal_counts::<15, 1>(16, 10, 200);
    temporal_counts::<62, 2>(64, 4, 100);
    temporal_counts::<252, 4>(256, 1, 50);
    temporal_counts::<64, 0>(64, 4, 100);
    // Sensor layouts built at run time: the scenario's cube of six photodiodes and the 16 on
    // the photodiode probe's directions, with their noisy readings.
    let readings = &scenario::sensor_readings::NOISY_READINGS_16;
    let sf16 = *probe::Probe::<16, f32, CosinePower<1>>::new().directions();
    layout_counts(&scenario::sensor_readings::CUBE, &scenario::sensor_readings::CUBE_READINGS);
    layout_counts(&sf16, readings);
    report!("sg_clamped_cosine_fraction", 1, 200, || {
        sg::clamped_cosine_fraction(black_box(7.3), black_box(0.41))
    });
    report!("sg_hemispherical_fraction", 1, 200, || {
        sg::hemispherical_fraction(black_box(7.3), black_box(0.41))
    });

    exit(debug::EXIT_SUCCESS)
}

/// Probe `update` (selection over the family, and one member), `irradiance`, `glossy` and
/// `glossy_variance` for footprint `F` (lines `# count {label}_update N=…`), and for point
/// samples the cosine-weighted average query on the same samples.
fn probe_counts<const N: usize, F: Footprint>(label: &str, update_reps: u32, query_reps: u32)
where
    bmc::Size<N>: probe::ProbeTables<F>,
{
    let mut p = probe::Probe::<N, f32, F>::new();
    let y: [f32; N] = p.directions().map(|d| 1.0 + 0.5 * d.z + 0.25 * d.x * d.y);
    let n = black_box(Vec3::new(0.3, -0.4, 0.5));
    let update = count(update_reps, || black_box(&mut p).update(black_box(&y)));
    let one = count(update_reps, || {
        black_box(&mut p).update_with(black_box(&y), probe::Selection::Member(1))
    });
    let _ = p.update(&y);
    let query = count(query_reps, || black_box(&p).irradiance(n));
    hprintln!("# count {}_update N={} {} instructions/call", label, N, update);
    hprintln!("# count {}_update_one_member N={} {} instructions/call", label, N, one);
    hprintln!("# count {}_irradiance N={} {} instructions/call", label, N, query);
    if F::KIND == Kind::Point {
        let cwa =
            count(query_reps, || probe::cosine_weighted_average(p.directions(), black_box(&y), n));
        hprintln!("# count cosine_weighted_average N={} {} instructions/call", N, cwa);
    }
    let lobe = sg::SphericalGaussian::phong_moments(Vec3::new(0.6, 0.0, 0.8), 20.0);
    if let Ok(lobe) = lobe {
        let glossy = count(query_reps, || black_box(&p).glossy(black_box(&lobe)));
        let variance = count(update_reps, || black_box(&p).glossy_variance(black_box(&lobe)));
        hprintln!("# count {}_glossy N={} {} instructions/call", label, N, glossy);
        hprintln!("# count {}_glossy_variance N={} {} instructions/call", label, N, variance);
    }
    // Issue #14: the SH L2 export, its variances, and the O(9) query on the exported
    // coefficients (one channel here; RGB in `main`).
    let sh = count(query_reps, || black_box(&p).radiance_sh());
    let sh_variance = count(update_reps, || black_box(&p).radiance_sh_variance());
    let coefficients = p.radiance_sh();
    // A unit normal (what a renderer passes), and the probe queries' normal of length 0.71.
    let unit = black_box(n.try_normalize().unwrap_or(Vec3::Z));
    let sh_query = count(2000, || black_box(&coefficients).irradiance(unit));
    let sh_query_any = count(2000, || black_box(&coefficients).irradiance(n));
    hprintln!("# count {}_radiance_sh N={} {} instructions/call", label, N, sh);
    hprintln!("# count {}_radiance_sh_variance N={} {} instructions/call", label, N, sh_variance);
    hprintln!("# count {}_sh_irradiance N={} {} instructions/call", label, N, sh_query);
    hprintln!(
        "# count {}_sh_irradiance_non_unit N={} {} instructions/call",
        label,
        N,
        sh_query_any
    );
    let r = Vec3::new(0.6, 0.0, 0.8);
    let phong = count(query_reps, || black_box(&p).phong(black_box(r), black_box(20.0)));
    let exact = count(update_reps, || black_box(&p).phong_variance(black_box(r), black_box(20.0)));
    hprintln!("# count {}_phong N={} {} instructions/call", label, N, phong);
    hprintln!("# count {}_phong_variance N={} {} instructions/call", label, N, exact);
}

/// `Probe<64, f32, Point, M>::update_masked` with `m` of the samples missing for each `m` in
/// `counts` (every `64/m`-th; `m = 0` is `update` through the mask), one member, and after
/// it `irradiance` and `irradiance_variance` (lines `# count probe_masked_…_M{M}_m{m} N=64`).
fn masked_counts<const M: usize>(counts: &[usize]) {
    let mut p = probe::Probe::<64, f32, Point, M>::new();
    let y: [f32; 64] = p.directions().map(|d| 1.0 + 0.5 * d.z + 0.25 * d.x * d.y);
    let n = black_box(Vec3::new(0.3, -0.4, 0.5));
    for &m in counts {
        let valid: [bool; 64] = core::array::from_fn(|i| m == 0 || i % (64 / m.max(1)) != 1);
        let update = count(2, || black_box(&mut p).update_masked(black_box(&y), &valid));
        let one = count(2, || {
            black_box(&mut p).update_masked_with(black_box(&y), &valid, probe::Selection::Member(1))
        });
        let _ = p.update_masked(&y, &valid);
        let query = count(100, || black_box(&p).irradiance(n));
        let exact = count(4, || black_box(&p).irradiance_variance(n));
        for (what, c) in [
            ("update", update),
            ("update_one_member", one),
            ("irradiance", query),
            ("irradiance_variance", exact),
        ] {
            hprintln!("# count probe_masked_{}_M{}_m{} N=64 {} instructions/call", what, M, m, c);
        }
    }
}

/// `TemporalProbe<NR, f32, Point, S>::pool` and `irradiance` (lines
/// `# count temporal_{update,irradiance}_S{S} N={rays}`), on a probe warmed by three updates.
fn temporal_counts<const NR: usize, const S: usize>(
    rays: usize,
    update_reps: u32,
    query_reps: u32,
) {
    let mut p = temporal::TemporalProbe::<NR, f32, Point, S>::new(1);
    let sky = |d: Vec3| 1.0 + 0.5 * d.z + 0.25 * d.x * d.y;
    for _ in 0..3 {
        let (y, s) = (p.directions().map(sky), p.sentinels().map(sky));
        let _ = p.pool(&y, &s);
    }
    let (y, s) = (p.directions().map(sky), p.sentinels().map(sky));
    let n = black_box(Vec3::new(0.3, -0.4, 0.5));
    let update = count(update_reps, || black_box(&mut p).pool(black_box(&y), black_box(&s)));
    let query = count(query_reps, || black_box(&p).irradiance(n));
    hprintln!("# count temporal_update_S{} N={} {} instructions/call", S, rays, update);
    hprintln!("# count temporal_irradiance_S{} N={} {} instructions/call", S, rays, query);
}

/// `LayoutProbe<K, f32>` of cosine photodiodes at `directions` (`Prior::ENVIRONMENT`, the
/// scenario's relative noise of 1 %, the green channel of `readings`): `new`, `update`,
/// `irradiance` and `irradiance_variance` (lines `# count layout_{init,update,…} K=…`), the
/// RGB update, and the probes' sizes in RAM (lines `# ram layout_{f32,rgb} K=… B`).
fn layout_counts<const K: usize>(directions: &[Vec3; K], readings: &[[f32; 3]; K]) {
    let sensors = directions.map(Sensor::cosine);
    let noise = scenario::LAYOUT_NOISE;
    let new = || {
        LayoutProbe::<K, f32>::new(
            black_box(&sensors),
            black_box(Prior::ENVIRONMENT),
            black_box(noise),
        )
    };
    let init = count(2, new);
    let (Ok(mut p), Ok(mut rgb)) =
        (new(), LayoutProbe::<K, [f32; 3]>::new(&sensors, Prior::ENVIRONMENT, noise))
    else {
        hprintln!("# layout K={} failed", K);
        return;
    };
    let y: [f32; K] = readings.map(|r| r[1]);
    let n = black_box(Vec3::new(0.3, -0.4, 0.5));
    let update = count(4, || black_box(&mut p).update(black_box(&y)));
    let update_rgb = count(2, || black_box(&mut rgb).update(black_box(readings)));
    // The same readings with an absolute noise only (one noise level for all sensors: no
    // per-reading solve).
    let absolute = Noise { absolute: 0.01 * y.iter().sum::<f32>() / K as f32, relative: 0.0 };
    let update_absolute = match LayoutProbe::<K, f32>::new(&sensors, Prior::ENVIRONMENT, absolute) {
        Ok(mut q) => count(4, || black_box(&mut q).update(black_box(&y))),
        Err(_) => 0,
    };
    // And without any noise declared (exact readings).
    let exact = Noise { absolute: 0.0, relative: 0.0 };
    let update_exact = match LayoutProbe::<K, f32>::new(&sensors, Prior::ENVIRONMENT, exact) {
        Ok(mut q) => count(4, || black_box(&mut q).update(black_box(&y))),
        Err(_) => 0,
    };
    let _ = p.update(&y);
    let query = count(200, || black_box(&p).irradiance(n));
    let variance = count(50, || black_box(&p).irradiance_variance(n));
    hprintln!("# count layout_init K={} {} instructions/call", K, init);
    hprintln!("# count layout_update K={} {} instructions/call", K, update);
    hprintln!("# count layout_update_rgb K={} {} instructions/call", K, update_rgb);
    hprintln!("# count layout_update_absolute K={} {} instructions/call", K, update_absolute);
    hprintln!("# count layout_update_exact K={} {} instructions/call", K, update_exact);
    hprintln!("# count layout_irradiance K={} {} instructions/call", K, query);
    hprintln!("# count layout_irradiance_variance K={} {} instructions/call", K, variance);
    hprintln!("# ram layout_f32 K={} {}", K, core::mem::size_of::<LayoutProbe<K, f32>>());
    hprintln!("# ram layout_rgb K={} {}", K, core::mem::size_of::<LayoutProbe<K, [f32; 3]>>());
}

/// Ends the QEMU run with a status.
fn exit(status: debug::ExitStatus) -> ! {
    debug::exit(status);
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    exit(debug::EXIT_FAILURE)
}
