//! Helpers shared by the modules of this test binary (`#[macro_use] mod common;` in `main.rs`,
//! before the modules that use them).

/// The BMC sizes baked by default (`tables/bmc.txt`).
/// Runs `$body` with `$n` bound to each baked size as a const.
macro_rules! for_each_size {
    ($n:ident => $body:block) => {{
        {
            const $n: usize = 16;
            $body
        }
        {
            const $n: usize = 32;
            $body
        }
        {
            const $n: usize = 64;
            $body
        }
        {
            const $n: usize = 80;
            $body
        }
        {
            const $n: usize = 128;
            $body
        }
        {
            const $n: usize = 256;
            $body
        }
    }};
}
