//! Six VEML7700 ambient-light sensors on the faces of a cube, each on its own channel of a
//! TCA9548A I2C multiplexer (the sensors share one fixed address, 0x10), feeding a
//! [`LayoutProbe`] that answers irradiance with an error bar for any direction.
//!
//! Generic over [`embedded_hal::i2c::I2c`]: the multiplexer is driven by `xca9548a`, each
//! sensor by `veml6030` (which drives the VEML7700 too) through its channel of the
//! multiplexer; the lux values are the driver's own conversion of the raw counts
//! ([`veml6030::Veml6030::read_lux`]).
//!
//! # Model
//! A VEML7700 under its flat window is modelled as a cosine sensor (the probe's
//! `Sensor::cosine`): it reads the illuminance `E(d)` in lux on its face, `d` its outward
//! normal. The probe takes `E(d)/π` (the mean radiance under a normalised cosine response), so
//! its irradiance answers are lux: `E(n)` is the illuminance a surface facing `n` would receive.
//! The VEML7700's published angular response is a plot, not a table; the cosine response is an
//! assumption of this example, not a measurement.

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::probe::Estimate;
use sphere_quadrature::Vec3;
use veml6030::{Gain, IntegrationTime, SlaveAddr, Veml6030};
use xca9548a::{I2cSlave, Xca9548a};

/// Sensors on the board.
pub const FACES: usize = 6;

/// The sensors' gain: ×1/4 (×1 and ×2 are meant for dim light, below about 100 lx). With [`INTEGRATION_TIME`], 0.2304 lx per count (the driver's
/// resolution table), linear up to 1 000 lx; above, the driver applies Vishay's correction
/// polynomial. The full scale, 65 535 counts (15 099 lx before the correction), is
/// [`BoardError::Saturated`].
pub const GAIN: Gain = Gain::OneQuarter;

/// The sensors' integration time: 100 ms.
pub const INTEGRATION_TIME: IntegrationTime = IntegrationTime::Ms100;

/// What [`Board::start`] waits after enabling the sensors: one integration time and 5 ms.
pub const SETTLE_MS: u32 = 105;

/// Where each sensor is: the multiplexer channel it hangs on and the direction its face looks
/// along, in the frame the board's answers are wanted in (the room's, if the cube's mounting
/// is known: rotate the cube's face normals by it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wiring {
    /// Multiplexer channel (0–7) of face `i`; each channel at most once.
    pub channels: [u8; FACES],
    /// Outward normal of face `i`.
    pub directions: [Vec3; FACES],
}

impl Wiring {
    /// Channel `i` on the face along the `i`-th of `+x, −x, +y, −y, +z, −z` of the cube's own
    /// frame.
    pub const CUBE: Wiring = Wiring {
        channels: [0, 1, 2, 3, 4, 5],
        directions: [
            Vec3::X,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::Y,
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::Z,
            Vec3::new(0.0, 0.0, -1.0),
        ],
    };
}

/// What can go wrong on the board.
#[derive(Debug)]
pub enum BoardError<E: core::fmt::Debug> {
    /// The bus (or the multiplexer's, or a sensor's, answer on it).
    Bus(veml6030::Error<xca9548a::Error<E>>),
    /// A channel above 7 or used twice in the [`Wiring`].
    InvalidWiring,
    /// The sensor of this face read the full scale (65 535 counts): its light is brighter than
    /// [`GAIN`] and [`INTEGRATION_TIME`] can measure. The probe keeps its previous readings.
    Saturated(usize),
    /// The probe refused the layout or the readings.
    Probe(sphere_quadrature::Error),
}

impl<E: core::fmt::Debug> From<sphere_quadrature::Error> for BoardError<E> {
    fn from(e: sphere_quadrature::Error) -> Self {
        BoardError::Probe(e)
    }
}

type Channel<'a, I2C> = Veml6030<I2cSlave<'a, Xca9548a<I2C>, I2C>>;

/// The six sensors, each behind its channel of the multiplexer, and the probe they feed.
pub struct Board<'a, I2C> {
    sensors: [Channel<'a, I2C>; FACES],
    probe: LayoutProbe<FACES, f32>,
    lux: [f32; FACES],
}

impl<'a, I2C, E> Board<'a, I2C>
where
    I2C: I2c<Error = E>,
    E: embedded_hal::i2c::Error,
{
    /// The board on this multiplexer: a driver per face on its channel, and a probe with
    /// cosine sensors along the faces, [`Prior::for_layout`] (for a cube,
    /// `Prior::ENVIRONMENT`) and this noise. `noise` is in lux: `absolute` the standard
    /// deviation of a reading, `relative` a fraction of it. Nothing is sent on the bus.
    pub fn new(
        mux: &'a Xca9548a<I2C>,
        wiring: &Wiring,
        noise: Noise,
    ) -> Result<Self, BoardError<E>> {
        let mut seen = 0u8;
        for &c in &wiring.channels {
            if c > 7 || seen & (1 << c) != 0 {
                return Err(BoardError::InvalidWiring);
            }
            seen |= 1 << c;
        }
        let sensors = wiring.directions.map(Sensor::cosine);
        // Readings are E/π: the absolute noise in those units.
        let noise = Noise { absolute: noise.absolute / core::f32::consts::PI, ..noise };
        let probe = LayoutProbe::new(&sensors, Prior::for_layout(&sensors), noise)?;
        let parts = mux.split();
        let mut slots = [
            Some(parts.i2c0),
            Some(parts.i2c1),
            Some(parts.i2c2),
            Some(parts.i2c3),
            Some(parts.i2c4),
            Some(parts.i2c5),
            Some(parts.i2c6),
            Some(parts.i2c7),
        ];
        let [Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)] =
            wiring.channels.map(|c| slots[usize::from(c)].take())
        else {
            return Err(BoardError::InvalidWiring);
        };
        let sensors = [a, b, c, d, e, f].map(|bus| Veml6030::new(bus, SlaveAddr::default()));
        Ok(Board { sensors, probe, lux: [0.0; FACES] })
    }

    /// Configures every sensor ([`GAIN`], [`INTEGRATION_TIME`]), powers it on and waits
    /// [`SETTLE_MS`] for its first measurement.
    pub fn start(&mut self, delay: &mut impl DelayNs) -> Result<(), BoardError<E>> {
        for sensor in &mut self.sensors {
            sensor.set_gain(GAIN).map_err(BoardError::Bus)?;
            sensor.set_integration_time(INTEGRATION_TIME).map_err(BoardError::Bus)?;
            sensor.enable().map_err(BoardError::Bus)?;
        }
        delay.delay_ms(SETTLE_MS);
        Ok(())
    }

    /// Reads every sensor (raw counts through the driver's lux conversion) and updates the
    /// probe. Returns the six illuminances in lux, face by face. A saturated sensor is
    /// [`BoardError::Saturated`] and a bus error [`BoardError::Bus`]; either way the probe
    /// keeps its previous state.
    pub fn update(&mut self) -> Result<[f32; FACES], BoardError<E>> {
        let mut lux = [0.0f32; FACES];
        for (i, sensor) in self.sensors.iter_mut().enumerate() {
            let raw = sensor.read_raw().map_err(BoardError::Bus)?;
            if raw == u16::MAX {
                return Err(BoardError::Saturated(i));
            }
            lux[i] = sensor.convert_raw_als_to_lux(raw);
        }
        let readings = lux.map(|e| e / core::f32::consts::PI);
        self.probe.update(&readings)?;
        self.lux = lux;
        Ok(lux)
    }

    /// The illuminances of the last [`Board::update`], in lux.
    pub fn last_lux(&self) -> [f32; FACES] {
        self.lux
    }

    /// Irradiance (illuminance, lux) on a surface facing `normal`, with the probe's
    /// direction-averaged posterior variance (lux²). `InvalidDirection` for a zero or
    /// non-finite normal; before the first update, zero with zero variance.
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<f32>, BoardError<E>> {
        Ok(self.probe.irradiance(normal)?)
    }

    /// The exact posterior variance (lux²) of [`Board::irradiance`] at `normal`.
    pub fn irradiance_variance(&self, normal: Vec3) -> Result<f32, BoardError<E>> {
        Ok(self.probe.irradiance_variance(normal)?)
    }

    /// The probe the readings feed (for its other queries: lobes, SH export).
    pub fn probe(&self) -> &LayoutProbe<FACES, f32> {
        &self.probe
    }
}
