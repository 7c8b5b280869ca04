//! The host build of the Cortex-M4 scenario (`examples/cortex-m4/src/scenario.rs`): prints
//! the same `key index bits` lines, so `.ci/run` can compare them with QEMU's output.
//!
//! ```text
//! cargo eval device_scenario
//! ```

use sphere_quadrature_eval::scenario;

use clap::Parser;

struct Stdout;

impl scenario::Sink for Stdout {
    fn line(&mut self, args: std::fmt::Arguments<'_>) {
        println!("{args}");
    }
}

/// device_scenario: the host twin of the Cortex-M4 scenario, as `key index bits` lines
/// (no options; `--features micromath` for that backend)
#[derive(Parser)]
#[command(bin_name = "cargo eval device_scenario", verbatim_doc_comment)]
struct Args {}

fn main() {
    Args::parse();
    scenario::run(&mut Stdout);
}
