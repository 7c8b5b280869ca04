//! The hyperparameter file (`tables/renderer_hyperparameters.txt`): its rows per method,
//! key and N.

use std::collections::BTreeMap;

use super::KEYS;
use crate::renderer_engine::Brdf;

#[derive(Clone, Copy, Debug)]
pub struct Hyper {
    pub l: f64,
    pub sigma: f64,
}

impl Hyper {
    pub fn lambda(self) -> f64 {
        2.0 / (self.l * self.l)
    }
}

pub type HyperMap = BTreeMap<(String, usize), Hyper>;

/// Reads `<method> <key> <N> <l> <sigma>` rows of one method; `#` starts a comment.
pub fn parse_hyper(text: &str, method: &str) -> Result<HyperMap, String> {
    let mut map = HyperMap::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let err = |m: &str| format!("line {}: {m}", no + 1);
        if f.len() != 5 {
            return Err(err("expected `<method> <key> <N> <l> <sigma>`"));
        }
        if !["ml", "cov", "err"].contains(&f[0]) {
            return Err(err("method must be ml, cov or err"));
        }
        if !KEYS.iter().any(|k| k.0 == f[1]) {
            return Err(err(&format!("unknown key {}", f[1])));
        }
        let n: usize = f[2].parse().map_err(|e| err(&format!("N: {e}")))?;
        let l: f64 = f[3].parse().map_err(|e| err(&format!("l: {e}")))?;
        let sigma: f64 = f[4].parse().map_err(|e| err(&format!("sigma: {e}")))?;
        if !(l > 0.0 && l.is_finite() && sigma > 0.0 && sigma.is_finite()) {
            return Err(err("l and sigma must be finite and positive"));
        }
        if f[0] == method {
            map.insert((f[1].to_string(), n), Hyper { l, sigma });
        }
    }
    Ok(map)
}

/// The key of BMC-SF's set for `brdf`: the set morphed onto the BRDF's lobe (the cosine
/// for diffuse), as the crate's renderers and `qmc-sf` sample.
pub fn key_sf(brdf: Brdf) -> String {
    match brdf {
        Brdf::Diffuse => "diffuse-cos".into(),
        b => b.name(),
    }
}

pub fn hyper(h: &HyperMap, key: &str, n: usize) -> Result<Hyper, String> {
    h.get(&(key.to_string(), n)).copied().ok_or_else(|| {
        format!("no hyperparameters for ({key}, N = {n}): run `cargo xtask regen renderer-hyperparameters`")
    })
}
