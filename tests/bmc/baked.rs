//! The prebaked default tables in `baked/` (`gen/cache.rs`), which `build.rs` expands instead
//! of baking: their key must be that of the current `gen/`, `tables/` and `build.rs`, and
//! their expansion must equal a fresh bake of the crate's tables byte for byte (so every
//! baked f32 is bit-identical to the generator's). `SPHERE_QUADRATURE_WRITE_BAKED=1 cargo test
//! --release --test bmc baked::` rewrites `baked/` from a fresh bake.

use crate::gen;

use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fresh() -> gen::Files {
    let read = |file: &str| {
        std::fs::read_to_string(root().join(file))
            .map_err(|e| gen::Failure { file: file.into(), message: e.to_string() })
    };
    gen::default_files(&read).unwrap_or_else(|e| panic!("{}", gen::error_line(&e.file, &e.message)))
}

const REFRESH: &str = "SPHERE_QUADRATURE_WRITE_BAKED=1 cargo test --release --test bmc baked::";

#[test]
fn baked_tables_are_current_and_equal_a_fresh_bake() {
    let key = gen::cache::key(root()).unwrap();
    if std::env::var_os("SPHERE_QUADRATURE_WRITE_BAKED").is_some() {
        gen::cache::store(root(), &key, &fresh()).unwrap();
    }
    let stored = gen::cache::stored_key(root());
    // One line each, naming what to do.
    assert!(
        stored.as_deref() == Some(key.as_str()),
        "baked/ is stale: its key {} is not {key} (gen/, tables/ or build.rs changed); refresh it: {REFRESH}",
        stored.as_deref().unwrap_or("(none)")
    );
    let cached = gen::cache::load(root(), &key).unwrap().unwrap();
    let fresh = fresh();
    let names: Vec<&str> = fresh.iter().map(|(n, _)| *n).collect();
    let cached_names: Vec<&str> = cached.iter().map(|(n, _)| n.as_str()).collect();
    assert!(
        cached_names == names,
        "baked/ holds other files than a fresh bake; refresh it: {REFRESH}"
    );
    for ((name, text), (_, expanded)) in fresh.iter().zip(&cached) {
        if let Some((no, (a, b))) =
            text.split('\n').zip(expanded.split('\n')).enumerate().find(|(_, (a, b))| a != b)
        {
            panic!("baked/{name} differs from a fresh bake at line {}: `{b}` vs `{a}`; refresh it: {REFRESH}", no + 1);
        }
        assert!(
            text == expanded,
            "baked/{name} differs from a fresh bake in length; refresh it: {REFRESH}"
        );
    }
}

#[test]
fn the_compaction_round_trips_any_text() {
    let text = "// x\n@literal\n    0x00000001, 0xdeadbeef,\n    0x00000002, 0x00000003,\n    0x4,\n    \
                f32::from_bits(0x3f80_0000), // 1.0\n    f32::from_bits(0x3f80_0000), // 2.0\n    \
                [f32::from_bits(0x0000_0000), f32::from_bits(0x8000_0000), f32::from_bits(0x7fc0_0000)], // 0.0\n";
    let mut words = Vec::new();
    let skel = gen::cache::compact(text, &mut words);
    assert_eq!(words.len(), 4 * 8);
    let mut at = 0;
    assert_eq!(gen::cache::expand(&skel, &words, &mut at).unwrap(), text);
    assert_eq!(at, words.len());
}
