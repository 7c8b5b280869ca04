//! A probe size the crate does not ship (N = 48), baked from `lighting/probe.txt` through
//! `SPHERE_QUADRATURE_PROBE_TABLE` (set in `.cargo/config.toml`): `cargo run` here.

use sphere_quadrature::{probe::Probe, Vec3};

fn main() {
    let mut p = Probe::<48>::new();
    let samples = p.directions().map(|d| 2.0 + d.z);
    p.update(&samples).expect("finite samples");
    let e = p.irradiance(Vec3::Z).expect("unit normal").value;
    let exact = core::f32::consts::PI * (2.0 + 2.0 / 3.0);
    let family: Vec<f32> = Probe::<48>::family().map(|m| m.lambda).collect();
    println!("N = 48, family λ = {family:?}: E(+z) = {e} (exact {exact})");
    assert_eq!(family, [2.0, 8.0, 32.0], "the user's family was not baked");
    assert!((e - exact).abs() < 1e-3 * exact, "E(+z) = {e}, exact {exact}");
}
