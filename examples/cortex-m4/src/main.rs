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
use sphere_quadrature::qmc::{self, LobeSampler};
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

    exit(debug::EXIT_SUCCESS)
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
