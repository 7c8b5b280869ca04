//! Flash cost of single calls: what one call of a function adds to a release (LTO) binary.
//!
//! The build script turns the environment variable `SQ_FLASH=KEY` into the cfg
//! `sq_flash = "KEY"`, and this program then makes exactly the calls of case `KEY` on
//! `black_box` inputs (unset: none). `.ci/m4-flash.sh` builds every case and its base case
//! (nothing, or the object the call needs, such as `Probe::new`) and prints the differences
//! of `.text` (code) and of `.rodata` + `.data` (tables and constants) as lines
//! `# flash KEY N=n CODE DATA` for `cargo writer doc_numbers`, which checks the rustdoc
//! `flash:` lines and the README against them.
//!
//! ```text
//! cd examples/cortex-m4 && SQ_FLASH=probe_update cargo build --release --bin flash
//! ```
//!
//! The difference is what the call costs on top of its base case: code and tables it shares
//! with other calls a binary makes are counted in full here, and once in that binary.
#![no_std]
#![no_main]
// Most items are used by one case only.
#![allow(dead_code, unused_imports, unused_variables)]

use core::hint::black_box;

use cortex_m_rt::entry;
use sphere_quadrature::bmc::{GlossyRenderer, Renderer};
use sphere_quadrature::footprint::Point;
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::probe::{self, Probe, Selection};
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::sg::{self, SphericalGaussian};
use sphere_quadrature::sh::ShL2;
use sphere_quadrature::{Lobe, SphericalFibonacci, Vec3};

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

fn keep<T>(x: T) {
    black_box(x);
}

fn dir() -> Vec3 {
    black_box(Vec3::new(0.3, -0.4, 0.5))
}

/// The probe every probe case starts from (the base case `probe_new`).
fn probe() -> Probe<64, f32> {
    black_box(Probe::<64, f32>::new())
}

fn samples<const N: usize>() -> [f32; N] {
    core::array::from_fn(|i| black_box(1.0 + i as f32 * 0.01))
}

/// The layout probe every layout case starts from (the base case `layout_new`): six cosine
/// photodiodes on a cube's faces, `Prior::ENVIRONMENT`, a relative noise of 1 %.
fn layout() -> Option<LayoutProbe<6, f32>> {
    let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let sensors = black_box(faces).map(Sensor::cosine);
    let noise = black_box(Noise { absolute: 0.0, relative: 0.01 });
    black_box(LayoutProbe::new(&sensors, black_box(Prior::ENVIRONMENT), noise).ok())
}

#[entry]
fn main() -> ! {
    #[cfg(sq_flash = "sf_points")]
    keep(SphericalFibonacci::<64>::new().with_phase_bits(black_box(7)).points());
    #[cfg(sq_flash = "qmc_irradiance")]
    keep(qmc::irradiance::<64, f32, _>(dir(), black_box(1), |d| black_box(d.z)));
    #[cfg(sq_flash = "qmc_estimate_from_samples")]
    if let Ok(s) = LobeSampler::new(dir(), Lobe::Cosine, black_box(64), black_box(1)) {
        keep(s.estimate(&samples::<64>()));
    }
    #[cfg(sq_flash = "nearest_index")]
    keep(SphericalFibonacci::<256>::new().nearest_index(dir()));
    #[cfg(sq_flash = "renderer_w_dot_y")]
    keep(Renderer::<64>::new().estimate(&samples::<64>()));
    #[cfg(sq_flash = "glossy_renderer_estimate")]
    keep(GlossyRenderer::<64, 50>::new().estimate(dir(), dir(), &samples::<64>()));
    #[cfg(sq_flash = "probe_new")]
    keep(probe());
    #[cfg(sq_flash = "probe_update")]
    keep(probe().update(&samples()));
    #[cfg(sq_flash = "probe_update_one_member")]
    keep(probe().update_with(&samples(), Selection::Member(black_box(1))));
    #[cfg(sq_flash = "probe_irradiance")]
    keep(probe().irradiance(dir()));
    #[cfg(sq_flash = "cosine_weighted_average")]
    keep(probe::cosine_weighted_average(probe().directions(), &samples::<64>(), dir()));
    #[cfg(sq_flash = "probe_glossy")]
    if let Ok(lobe) = SphericalGaussian::phong_moments(dir(), black_box(20.0)) {
        keep(probe().glossy(&lobe));
    }
    #[cfg(sq_flash = "probe_glossy_variance")]
    if let Ok(lobe) = SphericalGaussian::phong_moments(dir(), black_box(20.0)) {
        keep(probe().glossy_variance(&lobe));
    }
    #[cfg(sq_flash = "probe_phong")]
    keep(probe().phong(dir(), black_box(20.0)));
    #[cfg(sq_flash = "probe_phong_variance")]
    keep(probe().phong_variance(dir(), black_box(20.0)));
    #[cfg(sq_flash = "probe_radiance_sh")]
    keep(probe().radiance_sh());
    #[cfg(sq_flash = "probe_radiance_sh_variance")]
    keep(probe().radiance_sh_variance());
    #[cfg(sq_flash = "probe_sh_irradiance")]
    keep(ShL2::new(core::array::from_fn(|k| black_box(k as f32))).irradiance(dir()));
    #[cfg(sq_flash = "probe_masked_new")]
    keep(black_box(Probe::<64, f32, Point, 8>::new()));
    #[cfg(sq_flash = "probe_masked_update")]
    {
        let valid: [bool; 64] = core::array::from_fn(|i| black_box(i % 8 != 1));
        let mut p = black_box(Probe::<64, f32, Point, 8>::new());
        keep(p.update_masked(&samples(), &valid));
        keep(p);
    }
    #[cfg(sq_flash = "layout_new")]
    keep(layout());
    #[cfg(sq_flash = "layout_update")]
    if let Some(mut p) = layout() {
        keep(p.update(&samples()));
        keep(p);
    }
    #[cfg(sq_flash = "layout_irradiance")]
    if let Some(p) = layout() {
        keep(p.irradiance(dir()));
    }
    #[cfg(sq_flash = "layout_irradiance_variance")]
    if let Some(p) = layout() {
        keep(p.irradiance_variance(dir()));
    }
    #[cfg(sq_flash = "sg_clamped_cosine_fraction")]
    keep(sg::clamped_cosine_fraction(black_box(7.3), black_box(0.41)));
    #[cfg(sq_flash = "sg_hemispherical_fraction")]
    keep(sg::hemispherical_fraction(black_box(7.3), black_box(0.41)));
    loop {
        cortex_m::asm::wfi();
    }
}
