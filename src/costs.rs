//! Instructions per call, flash and RAM on a Cortex-M4F, as measured on every change.
//!
#![doc = include_str!("../docs/costs.md")]
