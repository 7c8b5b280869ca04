//! The board's firmware for a Cortex-M4F (`thumbv7em-none-eabihf`): start the six sensors,
//! read them, print the irradiance with its error bar at a few normals, exit.
//!
//! ```text
//! cargo run --release --target thumbv7em-none-eabihf    # QEMU mps2-an386, semihosting
//! cargo run --release                                   # the same on the host
//! ```
//!
//! QEMU has no VEML7700: the bus here is [`StandIn`], which answers as six sensors in the host
//! test's lobby map would. On a board, pass the HAL's I2C peripheral (any
//! `embedded_hal::i2c::I2c`) and delay instead.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![forbid(unsafe_code)]

use embedded_hal::i2c::{ErrorKind, ErrorType, I2c, NoAcknowledgeSource, Operation};
use sensor_board::board::{Board, Wiring, FACES};
use sphere_quadrature::layout::Noise;
use sphere_quadrature::Vec3;
use xca9548a::{SlaveAddr, Xca9548a};

/// The multiplexer's and the sensors' addresses.
const MUX: u8 = 0x70;
const ALS: u8 = 0x10;
/// ALS register 4, per channel: the host test's counts for `examples/envmaps/lobby.hdr`.
const COUNTS: [u16; FACES] = [1206, 1100, 1545, 909, 1345, 716];

/// An I2C bus with a TCA9548A and a VEML7700 on each of its channels 0–5, in constant light.
struct StandIn {
    selected: u8,
    register: u8,
}

impl ErrorType for StandIn {
    type Error = ErrorKind;
}

impl I2c for StandIn {
    fn transaction(&mut self, address: u8, ops: &mut [Operation<'_>]) -> Result<(), ErrorKind> {
        let nack = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
        for op in ops {
            match op {
                Operation::Write(bytes) if address == MUX && bytes.len() == 1 => {
                    self.selected = bytes[0];
                }
                Operation::Write(bytes) if address == ALS => {
                    self.register = *bytes.first().ok_or(nack)?;
                }
                Operation::Read(buffer) if address == ALS && self.register == 4 => {
                    let channel = self.selected.trailing_zeros() as usize;
                    if self.selected.count_ones() != 1 || channel >= FACES || buffer.len() != 2 {
                        return Err(nack);
                    }
                    buffer.copy_from_slice(&COUNTS[channel].to_le_bytes());
                }
                _ => return Err(nack),
            }
        }
        Ok(())
    }
}

/// Waits by spinning: `cycles_per_us` core cycles per microsecond.
struct Spin {
    #[cfg_attr(not(target_os = "none"), allow(dead_code))]
    cycles_per_us: u32,
}

impl embedded_hal::delay::DelayNs for Spin {
    fn delay_ns(&mut self, ns: u32) {
        #[cfg(target_os = "none")]
        cortex_m::asm::delay(ns.div_ceil(1000).saturating_mul(self.cycles_per_us));
        #[cfg(not(target_os = "none"))]
        std::thread::sleep(std::time::Duration::from_nanos(u64::from(ns)));
    }
}

/// Runs the board on `bus`, printing through `line`; `false` on any error.
fn run(bus: impl I2c, delay: &mut Spin, mut line: impl FnMut(core::fmt::Arguments<'_>)) -> bool {
    let mux = Xca9548a::new(bus, SlaveAddr::default());
    // Quantisation (0.2304 lx per count, uniform: 0.2304/√12) and 2 % of each reading.
    let noise = Noise { absolute: 0.0665, relative: 0.02 };
    let Ok(mut board) = Board::new(&mux, &Wiring::CUBE, noise) else { return false };
    if board.start(delay).is_err() {
        return false;
    }
    let Ok(lux) = board.update() else { return false };
    line(format_args!("faces (lx): {lux:?}"));
    let normals = [Vec3::Z, Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 1.0, 1.0)];
    for n in normals {
        let (Ok(e), Ok(v)) = (board.irradiance(n), board.irradiance_variance(n)) else {
            return false;
        };
        line(format_args!(
            "E({:.3}, {:.3}, {:.3}) = {:.1} lx, variance {:.1} lx² (averaged {:.1})",
            n.x, n.y, n.z, e.value, v, e.variance
        ));
    }
    true
}

#[cfg(target_os = "none")]
mod device {
    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};

    #[entry]
    fn main() -> ! {
        // QEMU mps2-an386: a 25 MHz core clock.
        let mut delay = super::Spin { cycles_per_us: 25 };
        let bus = super::StandIn { selected: 0, register: 0 };
        let ok = super::run(bus, &mut delay, |args| hprintln!("{}", args));
        exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE })
    }

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
}

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    let mut delay = Spin { cycles_per_us: 0 };
    let bus = StandIn { selected: 0, register: 0 };
    if run(bus, &mut delay, |args| println!("{args}")) {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
