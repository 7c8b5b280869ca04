//! QMC-SF against the estimators a user would pick instead, on a real environment map
//! (`examples/envmaps/apartment.hdr`, CC0), with ground truth integrated over every pixel.
//!
//! The comparison is seeded, so it is deterministic; it guards the claim the README makes
//! with the numbers of `cargo run --release --example qmc_compare`.

#[path = "../../examples/common/compare.rs"]
#[allow(dead_code)] // the example also uses the clamp tier
mod compare;

use compare::{evaluate, truths, weights, Kind};
use reference::envmap::EnvMap;
use reference::rng::Rng;

#[test]
fn sf_beats_sobol_and_monte_carlo_on_a_real_map_at_64_and_256() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/envmaps/apartment.hdr");
    let map = EnvMap::load(path).expect("bundled map");
    let mut rng = Rng::new(2024);
    let axes: Vec<[f64; 3]> = (0..64).map(|_| rng.uniform_sphere()).collect();
    for kind in [Kind::Diffuse, Kind::Glossy(20.0)] {
        let truth = truths(&map, &weights(kind, &axes, map.width, map.height));
        for n in [64, 256] {
            let e = evaluate(&map, kind, &axes, &truth, n, 16, 11);
            println!(
                "{kind:?} N = {n}: relative RMSE MC {:.3}%, Sobol {:.3}%, QMC-SF {:.3}%",
                100.0 * e.mc,
                100.0 * e.sobol,
                100.0 * e.sf
            );
            assert!(e.sf < e.sobol && e.sf < e.mc, "{kind:?} N = {n}: {e:?}");
        }
    }
}
