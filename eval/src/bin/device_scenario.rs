//! The host build of the Cortex-M4 scenario (`examples/cortex-m4/src/scenario.rs`): prints
//! the same `key index bits` lines, so `.ci/run` can compare them with QEMU's output.
//!
//! ```text
//! cargo eval device_scenario
//! ```

#[path = "../../../examples/cortex-m4/src/scenario.rs"]
mod scenario;

struct Stdout;

impl scenario::Sink for Stdout {
    fn line(&mut self, args: std::fmt::Arguments<'_>) {
        println!("{args}");
    }
}

fn main() {
    scenario::run(&mut Stdout);
}
