//! Six VEML7700 ambient-light sensors on a cube behind a TCA9548A multiplexer, feeding a
//! `sphere_quadrature` layout probe (README.md). `no_std`: the same code runs on the
//! firmware (`src/main.rs`, `thumbv7em-none-eabihf`) and in the host test (`tests/`).
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod board;
