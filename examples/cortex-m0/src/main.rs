//! Fixed-point vs soft-float f32 BMC weighted sums (N = 64) on an emulated Cortex-M0 (QEMU
//! `microbit`, nRF51822: ARMv6-M, no FPU, SysTick present).
//!
//! For a few deterministic radiance vectors it prints the fixed-point mean radiance
//! ([`BmcFixed::mean_radiance`], raw U16F16 bits), the f32 irradiance
//! ([`Renderer::estimate`], f32 bits) and the relative error of each against an f64 sum on the
//! device; then instruction counts measured with SysTick (lines starting with `#`). It exits
//! with failure if an error exceeds 10⁻³ or fixed point takes more than ¼ of the f32
//! instructions.
//!
//! ```text
//! cd examples/cortex-m0 && cargo run --release
//! ```
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use sphere_quadrature::bmc::Renderer;
use sphere_quadrature::fixed_point::{BmcFixed, U16F16};

const N: usize = 64;

/// Instructions per call of `f`, from SysTick ticks over `reps` calls, scaled by the
/// calibration ([`calibrate`]: `cal_instr` instructions took `cal_ticks` ticks). With
/// `-icount shift=0` QEMU retires one instruction per ns of virtual time; the microbit's
/// SysTick counts the 16 MHz core clock, so one tick is 62.5 instructions. The empty-loop
/// overhead is subtracted.
fn count<T>(reps: u32, (cal_instr, cal_ticks): (u32, u32), mut f: impl FnMut() -> T) -> u32 {
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
    let ticks = u64::from(full.saturating_sub(empty));
    (ticks * u64::from(cal_instr) / (u64::from(cal_ticks) * u64::from(reps))) as u32
}

/// Deterministic radiance vector `k` as U16F16 bits.
fn radiance_bits(k: u32, i: usize) -> u32 {
    let i = i as u32;
    match k {
        // Constant 1.
        0 => 1 << 16,
        // A smooth ramp 1 … 1.5.
        1 => (1 << 16) + (i << 16) / (2 * N as u32),
        // Pseudo-random in [0, 256).
        2 => i.wrapping_mul(0x9E37_79B9).wrapping_add(0x1234_5678) >> 8,
        // HDR: mostly dim, a few samples near the top of the range.
        _ => {
            if i % 16 == 3 {
                0xF000_0000 + (i << 20)
            } else {
                (i + 1) << 12
            }
        }
    }
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else { exit(debug::EXIT_FAILURE) };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();

    let fixed = BmcFixed::<N>::new();
    let float = Renderer::<N>::new();
    let mut ok = true;

    for k in 0..4 {
        let yq: [U16F16; N] = core::array::from_fn(|i| U16F16::from_bits(radiance_bits(k, i)));
        let yf: [f32; N] = yq.map(|y| y.to_num::<f32>());
        let q = fixed.mean_radiance(&yq);
        let e = float.estimate(&yf).unwrap_or(f32::NAN);
        // f64 reference on the device: the f32-rounded weights (6·10⁻⁸ from the f64 ones).
        let exact: f64 = yq
            .iter()
            .zip(Renderer::<N>::weights())
            .map(|(y, &w)| y.to_num::<f64>() * f64::from(w))
            .sum();
        let rel_q = (q.to_num::<f64>() - exact).abs() / exact;
        let rel_f = (f64::from(e) / core::f64::consts::PI - exact).abs() / exact;
        hprintln!(
            "vector {}: fixed mean_radiance bits=0x{:08x} ({}), f32 estimate bits=0x{:08x} ({}), \
             rel err vs f64: fixed {:e}, f32 {:e}",
            k,
            q.to_bits(),
            q.to_num::<f32>(),
            e.to_bits(),
            e,
            rel_q as f32,
            rel_f as f32
        );
        ok &= rel_q <= 1e-3 && rel_f <= 1e-3;
    }

    // Ticks per instruction, from a loop of a known instruction count rather than an
    // assumed clock.
    let cal = calibrate();
    hprintln!(
        "# systick calibration: {} instructions = {} ticks ({} instructions/tick)",
        cal.0,
        cal.1,
        cal.0 as f32 / cal.1 as f32
    );
    if cal.1 == 0 {
        hprintln!("# SysTick does not count on this machine");
        exit(debug::EXIT_FAILURE);
    }

    let yq: [U16F16; N] = core::array::from_fn(|i| U16F16::from_bits(radiance_bits(2, i)));
    let yf: [f32; N] = yq.map(|y| y.to_num::<f32>());
    let n_fixed = count(50, cal, || fixed.mean_radiance(black_box(&yq)));
    let n_float = count(50, cal, || float.estimate(black_box(&yf)));
    hprintln!("# count bmc_fixed_mean_radiance N={} {} instructions/call", N, n_fixed);
    hprintln!("# count bmc_f32_estimate N={} {} instructions/call", N, n_float);
    let ratio = n_fixed as f32 / n_float as f32;
    hprintln!("# ratio fixed/f32 = {} (target <= 0.25)", ratio);
    ok &= n_float > 0 && 4 * n_fixed <= n_float;

    exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE })
}

/// `(instructions, ticks)` of `asm::delay(ITERS)`: `ITERS + 1` iterations of `subs; bne`.
fn calibrate() -> (u32, u32) {
    const ITERS: u32 = 100_000;
    let start = SYST::get_current();
    cortex_m::asm::delay(ITERS);
    let end = SYST::get_current();
    (2 * (ITERS + 1), start.wrapping_sub(end) & 0x00FF_FFFF)
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
