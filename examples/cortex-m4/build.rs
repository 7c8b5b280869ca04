//! Puts `memory.x` where the `cortex-m-rt` linker script finds it, and turns `SQ_FLASH=KEY`
//! into the cfg `sq_flash = "KEY"` for `src/bin/flash.rs`.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("copy memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=SQ_FLASH");
    println!("cargo::rustc-check-cfg=cfg(sq_flash, values(any()))");
    if let Ok(key) = env::var("SQ_FLASH") {
        println!("cargo:rustc-cfg=sq_flash=\"{key}\"");
    }
}
