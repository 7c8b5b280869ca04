//! The board on a mocked I2C bus (`embedded-hal-mock`, embedded-hal 1.0), its registers holding
//! what six VEML7700s on a rotated cube would read in a real environment map; the probe's
//! irradiance is checked against the map's exact irradiance.
//!
//! The simulated sensors: the map is `examples/envmaps/lobby.hdr` (held out of the prior's
//! training maps), its linear RGB taken as radiance in units of 100 cd/m² and weighted by
//! the Rec. 709 luminance (the VEML7700's spectral response is close to the eye's). Face `i`
//! of the cube, turned by [`mounting`] into the map's frame, sees the exact cosine-weighted
//! irradiance of the map's nearest-pixel radiance (`reference::truth::irradiance`, f64), in
//! lux; its ALS register holds that over the resolution of gain ×1/4 and 100 ms
//! (0.2304 lx per count, Vishay's resolution table as the driver uses it), rounded to u16.

use embedded_hal::i2c::{ErrorKind, NoAcknowledgeSource};
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction};
use reference::envmap::{luminance, EnvMap};
use sensor_board::board::{Board, BoardError, Wiring, FACES};
use sphere_quadrature::layout::Noise;
use sphere_quadrature::Vec3;
use xca9548a::{SlaveAddr, Xca9548a};

/// The multiplexer's address (A2 = A1 = A0 = 0) and the VEML7700's (fixed).
const MUX: u8 = 0x70;
const ALS: u8 = 0x10;
/// Lux per count at gain ×1/4 and 100 ms (linear up to 1 000 lx).
const LUX_PER_COUNT: f64 = 0.2304;
/// Map radiance unit in cd/m².
const NITS: f64 = 100.0;

/// The cube's mounting in the map's frame: turned 30° about z, then tilted 20° about x
/// (a rotation that maps no face onto an axis of the map).
fn mounting(d: [f64; 3]) -> [f64; 3] {
    let (s, c) = 30f64.to_radians().sin_cos();
    let (x, y, z) = (c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]);
    let (s, c) = 20f64.to_radians().sin_cos();
    [x, c * y - s * z, s * y + c * z]
}

const CUBE: [[f64; 3]; FACES] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

fn vec3(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// The bundled maps that the probe's prior (`Prior::ENVIRONMENT`) was not learned from.
const HELD_OUT: [&str; 6] = ["lobby", "hall", "city", "dawn", "night", "park"];
/// The maps it was learned from.
const TRAINING: [&str; 4] = ["apartment", "bridge", "forest", "lab"];

fn load(name: &str) -> EnvMap {
    let path = format!("{}/../envmaps/{name}.hdr", env!("CARGO_MANIFEST_DIR"));
    EnvMap::load(path).expect("load the map")
}

/// The exact illuminance (lux) on a surface of the map's frame facing `n`.
fn true_lux(map: &EnvMap, n: [f64; 3]) -> f64 {
    NITS * luminance(reference::truth::irradiance(map, n))
}

/// The ALS counts the sensor of each face reads: its lux over the resolution, rounded.
fn counts(map: &EnvMap) -> [u16; FACES] {
    CUBE.map(|d| {
        let lux = true_lux(map, mounting(d));
        // The simulated sensor is linear: as the VEML7700 at this gain, below 1 000 lx.
        assert!((0.0..1000.0).contains(&lux), "{lux} lx: outside the linear range");
        (lux / LUX_PER_COUNT).round() as u16
    })
}

/// What the board says on the bus, channel by channel in the order it was told: start (per
/// sensor: select its channel, then the ALS_CONF writes of gain ×1/4 (bits 12:11 = 0b11), 100 ms
/// (bits 9:6 = 0) with the sensor still shut down (bit 0), and powered on), then one reading
/// (select, read ALS: register 4, little-endian) answered by whichever face is soldered to
/// that channel (`soldered[i]`: the channel of face `i`).
fn transactions(
    told: [u8; FACES],
    soldered: [u8; FACES],
    counts: [u16; FACES],
) -> Vec<Transaction> {
    let mut t = Vec::new();
    for &c in &told {
        t.push(Transaction::write(MUX, vec![1 << c]));
        t.push(Transaction::write(ALS, vec![0x00, 0x01, 0x18]));
        t.push(Transaction::write(ALS, vec![0x00, 0x01, 0x18]));
        t.push(Transaction::write(ALS, vec![0x00, 0x00, 0x18]));
    }
    for &c in &told {
        let face = soldered.iter().position(|&s| s == c).expect("a sensor on every channel told");
        t.push(Transaction::write(MUX, vec![1 << c]));
        t.push(Transaction::write_read(ALS, vec![0x04], counts[face].to_le_bytes().to_vec()));
    }
    t
}

/// Query directions of the map's frame: the 6 sensors' (where the probe's answer is their
/// reading, within the noise: a swapped pair of sensors shows here), then the map's 6 axes,
/// 12 edge and 8 corner directions.
fn queries() -> Vec<[f64; 3]> {
    let mut q: Vec<[f64; 3]> = CUBE.map(mounting).to_vec();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    let n = ((x * x + y * y + z * z) as f64).sqrt();
                    q.push([x as f64 / n, y as f64 / n, z as f64 / n]);
                }
            }
        }
    }
    q
}

/// One query's outcome: the truth, the board's answer, its direction-averaged and exact
/// standard deviations.
struct Row {
    n: [f64; 3],
    truth: f64,
    value: f64,
    sigma_avg: f64,
    sigma_exact: f64,
}

/// Runs the board on the mocked bus: face `i` soldered to channel `soldered[i]`, the board
/// told `wiring`.
fn run(map: &EnvMap, soldered: [u8; FACES], wiring: &Wiring) -> Vec<Row> {
    let counts = counts(map);
    println!("ALS counts, face by face: {counts:?}");
    let bus = Mock::new(&transactions(wiring.channels, soldered, counts));
    let mux = Xca9548a::new(bus, SlaveAddr::default());
    let noise = Noise { absolute: (LUX_PER_COUNT / 12f64.sqrt()) as f32, relative: 0.0 };
    let mut board = Board::new(&mux, wiring, noise).expect("board");
    board.start(&mut NoopDelay).expect("start");
    let lux = board.update().expect("update");
    if soldered == wiring.channels {
        for (i, (&l, &n)) in lux.iter().zip(&counts).enumerate() {
            // The driver's conversion of the counts (checked independently: counts × resolution).
            let expected = f64::from(n) * LUX_PER_COUNT;
            assert!((f64::from(l) - expected).abs() <= 1e-6 * expected, "face {i}: {l} lx");
        }
    }
    let rows = queries()
        .into_iter()
        .map(|n| {
            let e = board.irradiance(vec3(n)).expect("irradiance");
            let exact = board.irradiance_variance(vec3(n)).expect("variance");
            Row {
                n,
                truth: true_lux(map, n),
                value: f64::from(e.value),
                sigma_avg: f64::from(e.variance).sqrt(),
                sigma_exact: f64::from(exact).sqrt(),
            }
        })
        .collect();
    // Every expected transaction happened, and no other.
    mux.destroy().done();
    rows
}

/// The board's wiring: channel `i` on face `i`, the faces turned by the mounting.
fn mounted() -> Wiring {
    Wiring { channels: Wiring::CUBE.channels, directions: CUBE.map(|d| vec3(mounting(d))) }
}

/// Whether every answer is within 2σ of the truth, by both standard deviations.
fn all_within(rows: &[Row]) -> bool {
    coverage(rows) == (rows.len(), rows.len())
}

/// How many answers are within 2σ of the truth (direction-averaged σ, exact σ), printing each.
fn coverage(rows: &[Row]) -> (usize, usize) {
    let (mut avg, mut exact) = (0, 0);
    for r in rows {
        let err = r.value - r.truth;
        avg += usize::from(err.abs() <= 2.0 * r.sigma_avg);
        exact += usize::from(err.abs() <= 2.0 * r.sigma_exact);
        println!(
            "n = ({:+.3}, {:+.3}, {:+.3}): truth {:8.2} lx, board {:8.2} lx, error {:+7.2} lx = \
             {:+.2} σ (averaged σ {:.2}), {:+.2} σ (exact σ {:.2})",
            r.n[0],
            r.n[1],
            r.n[2],
            r.truth,
            r.value,
            err,
            err / r.sigma_avg,
            r.sigma_avg,
            err / r.sigma_exact,
            r.sigma_exact,
        );
    }
    println!("within 2σ: {avg}/{} (averaged σ), {exact}/{} (exact σ)", rows.len(), rows.len());
    (avg, exact)
}

/// Every held-out map: all 32 answers within 2σ, by either standard deviation.
#[test]
fn irradiance_of_real_maps_within_two_sigma() {
    for name in HELD_OUT {
        println!("{name}");
        let rows = run(&load(name), Wiring::CUBE.channels, &mounted());
        assert!(all_within(&rows), "{name}");
    }
}

/// The coverage on every bundled map, training maps included (README.md's table):
/// `cargo test --test host -- --ignored --nocapture`.
#[test]
#[ignore = "prints the README's table"]
fn coverage_on_every_map() {
    let mut table = Vec::new();
    for name in HELD_OUT.iter().chain(&TRAINING) {
        println!("{name}");
        let rows = run(&load(name), Wiring::CUBE.channels, &mounted());
        let (avg, exact) = coverage(&rows);
        let worst = |f: fn(&Row) -> f64| rows.iter().map(f).fold(0.0, f64::max);
        let max_avg = worst(|r| (r.value - r.truth).abs() / r.sigma_avg);
        let max_exact = worst(|r| (r.value - r.truth).abs() / r.sigma_exact);
        let truth = rows.iter().map(|r| r.truth);
        let (lo, hi) = (truth.clone().fold(f64::MAX, f64::min), truth.fold(0.0, f64::max));
        table.push(format!(
            "| {name} | {lo:.0}–{hi:.0} | {avg}/{n} | {max_avg:.2} | {exact}/{n} | {max_exact:.2} |",
            n = rows.len()
        ));
    }
    println!("| map | truth (lx) | within 2σ (averaged σ) | worst \\|error\\|/σ | within 2σ (exact σ) | worst \\|error\\|/σ |");
    println!("|---|---|---|---|---|---|");
    for line in table {
        println!("{line}");
    }
}

/// The check can fail: faces soldered to other channels than the board is told.
#[test]
fn a_wrong_channel_order_fails_the_check() {
    let map = load("lobby");
    for soldered in [[0, 1, 2, 3, 5, 4], [1, 0, 2, 3, 4, 5], [1, 2, 3, 4, 5, 0]] {
        println!("soldered {soldered:?}");
        assert!(!all_within(&run(&map, soldered, &mounted())), "{soldered:?}");
    }
}

/// The check can fail: the board told the cube's own face normals, not the mounted ones.
#[test]
fn a_wrong_orientation_fails_the_check() {
    let map = load("lobby");
    assert!(!all_within(&run(&map, Wiring::CUBE.channels, &Wiring::CUBE)));
}

/// Bad wiring is refused before anything is sent on the bus.
#[test]
fn bad_wiring_is_refused() {
    let mux = Xca9548a::new(Mock::new(&[]), SlaveAddr::default());
    let noise = Noise::NONE;
    for channels in [[0, 0, 1, 2, 3, 4], [0, 1, 2, 3, 4, 8]] {
        let wiring = Wiring { channels, ..Wiring::CUBE };
        let board = Board::new(&mux, &wiring, noise);
        assert!(matches!(board, Err(BoardError::InvalidWiring)), "{channels:?}");
    }
    let mut directions = Wiring::CUBE.directions;
    directions[2] = Vec3::ZERO;
    let board = Board::new(&mux, &Wiring { directions, ..Wiring::CUBE }, noise);
    assert!(matches!(board, Err(BoardError::Probe(sphere_quadrature::Error::InvalidDirection))));
    mux.destroy().done();
}

/// A saturated sensor or a bus error leaves the probe and the last readings as they were.
#[test]
fn a_saturated_sensor_or_a_bus_error_keeps_the_state() {
    let first = [900, 1000, 1100, 1200, 1300, 1400];
    let mut t = transactions(Wiring::CUBE.channels, Wiring::CUBE.channels, first);
    // A second reading: face 3 saturates (the reading stops there).
    for (c, n) in [(0, 900), (1, 1000), (2, 1100), (3, u16::MAX)] {
        t.push(Transaction::write(MUX, vec![1 << c]));
        t.push(Transaction::write_read(ALS, vec![0x04], u16::to_le_bytes(n).to_vec()));
    }
    // A third: face 1's sensor does not answer.
    t.push(Transaction::write(MUX, vec![1 << 0]));
    t.push(Transaction::write_read(ALS, vec![0x04], vec![0x84, 0x03]));
    t.push(Transaction::write(MUX, vec![1 << 1]));
    t.push(
        Transaction::write_read(ALS, vec![0x04], vec![0, 0])
            .with_error(ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address)),
    );
    let mux = Xca9548a::new(Mock::new(&t), SlaveAddr::default());
    let mut board = Board::new(&mux, &Wiring::CUBE, Noise::NONE).expect("board");
    board.start(&mut NoopDelay).expect("start");
    let lux = board.update().expect("update");
    let before = board.irradiance(Vec3::Z).expect("irradiance");
    assert!(matches!(board.update(), Err(BoardError::Saturated(3))));
    assert!(matches!(board.update(), Err(BoardError::Bus(_))));
    assert_eq!(board.last_lux(), lux);
    let after = board.irradiance(Vec3::Z).expect("irradiance");
    assert_eq!((after.value, after.variance), (before.value, before.variance));
    mux.destroy().done();
}
