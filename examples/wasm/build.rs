//! Gives the WebAssembly module a 4 MiB stack instead of rustc's default 1 MiB:
//! `map_footprint_samples` copies the map (up to 512×256 RGB, 1.5 MiB) and builds its mip
//! pyramid (0.5 MiB) on the stack, because the crate borrows plain slices and the module has
//! no allocator and no `unsafe` to lend it its static buffers.
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CARGO_CFG_TARGET_ARCH").as_deref() == Ok("wasm32") {
        println!("cargo:rustc-link-arg=-zstack-size=4194304");
    }
}
