//! The optimal BMC sample sets of `tables/optimal_sets.txt` (issue #12 item 4, the seed's
//! step 2), written by `xtask/writers/src/bin/optimal_sets.rs`, and their loader for the renderer.
//!
//! # Format
//! `#` starts a comment; blank lines are skipped. Each set is a line
//! `set <key> <N> <l> <sigma> <var_sf> <var_opt>` followed by `N` lines `x y z`:
//! - `key`: `diffuse` (the set lives in the frame of `n`, axis = `n`) or `phong<e>` (the frame
//!   of the lobe: `t₁` towards `n`, `t₂ = r × t₁`, axis `r`; see `LobeFrame`);
//! - `l`, `sigma`: the kernel length scale (`λ = 2/l²`) and nugget σ′ the set was optimised for;
//! - `var_sf`, `var_opt`: the model's posterior variance (GLS constant mean, σ_f = 1) of the
//!   morphed SF set at phase 0 and of this set, averaged over the query distribution of `r·n`
//!   for Phong (see the file's header);
//! - `x y z`: lobe-frame coordinates `(t₁, t₂, axis)`, f32 numbers: they are parsed as f32
//!   (then widened), so that the stored set is exactly the f32 set that was written.

use crate::renderer_engine::LobeFrame;

/// One optimal set of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct OptimalSet {
    /// `diffuse` or `phong<e>`.
    pub key: String,
    /// The Phong exponent; `None` for diffuse.
    pub e: Option<f64>,
    /// Number of directions.
    pub n: usize,
    /// Kernel length scale the set was optimised for (`λ = 2/l²`).
    pub l: f64,
    /// Nugget σ′ the set was optimised for.
    pub sigma: f64,
    /// Posterior variance of the SF set (phase 0) with the same model and objective.
    pub var_sf: f64,
    /// Posterior variance of this set.
    pub var_opt: f64,
    /// Directions in the lobe frame `(t₁, t₂, axis)`, exactly as stored (f32 values; unit to
    /// f32 rounding).
    pub dirs: Vec<[f64; 3]>,
}

impl OptimalSet {
    /// Kernel sharpness `λ = 2/l²`.
    pub fn lambda(&self) -> f64 {
        2.0 / (self.l * self.l)
    }

    /// The directions in `frame`'s world coordinates, `x·t₁ + y·t₂ + z·axis`, normalised in
    /// f64.
    pub fn world(&self, frame: &LobeFrame) -> Vec<[f64; 3]> {
        self.dirs
            .iter()
            .map(|d| {
                let v: [f64; 3] = std::array::from_fn(|k| {
                    d[0] * frame.t1[k] + d[1] * frame.t2[k] + d[2] * frame.axis[k]
                });
                unit(v)
            })
            .collect()
    }

    /// The stored directions normalised in f64 (lobe frame).
    pub fn unit_dirs(&self) -> Vec<[f64; 3]> {
        self.dirs.iter().map(|&d| unit(d)).collect()
    }

    /// The set in the table's format (directions rounded to f32).
    pub fn format(&self) -> String {
        let mut s = format!(
            "set {} {} {} {} {:e} {:e}\n",
            self.key, self.n, self.l, self.sigma, self.var_sf, self.var_opt
        );
        for d in &self.dirs {
            s += &format!("{} {} {}\n", d[0] as f32, d[1] as f32, d[2] as f32);
        }
        s
    }
}

/// `v/|v|`.
pub fn unit(v: [f64; 3]) -> [f64; 3] {
    let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / r)
}

/// The exponent of a key: `Ok(None)` for `diffuse`, `Ok(Some(e))` for `phong<e>` (`e > 0`).
pub fn exponent_of(key: &str) -> Result<Option<f64>, String> {
    if key == "diffuse" {
        return Ok(None);
    }
    let e: f64 = key
        .strip_prefix("phong")
        .ok_or_else(|| format!("unknown key {key} (diffuse or phong<e>)"))?
        .parse()
        .map_err(|_| format!("unknown key {key} (diffuse or phong<e>)"))?;
    if !(e > 0.0 && e.is_finite()) {
        return Err(format!("key {key}: the exponent must be positive"));
    }
    Ok(Some(e))
}

/// Parses a table (module docs). Errors name the line.
pub fn parse(text: &str) -> Result<Vec<OptimalSet>, String> {
    let mut sets: Vec<OptimalSet> = Vec::new();
    let mut expect = 0usize;
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let err = |m: &str| format!("line {}: {m}", no + 1);
        let f: Vec<&str> = line.split_whitespace().collect();
        if expect > 0 {
            if f.len() != 3 {
                return Err(err("expected a direction `x y z`"));
            }
            let mut d = [0.0; 3];
            for (k, s) in f.iter().enumerate() {
                let v: f32 = s.parse().map_err(|e| err(&format!("direction: {e}")))?;
                if !v.is_finite() {
                    return Err(err("direction: not finite"));
                }
                d[k] = v as f64;
            }
            sets.last_mut().expect("a set is open").dirs.push(d);
            expect -= 1;
            continue;
        }
        if f[0] != "set" || f.len() != 7 {
            return Err(err("expected `set <key> <N> <l> <sigma> <var_sf> <var_opt>`"));
        }
        let e = exponent_of(f[1]).map_err(|m| err(&m))?;
        let n: usize = f[2].parse().map_err(|e| err(&format!("N: {e}")))?;
        let num = |s: &str, what: &str| -> Result<f64, String> {
            let v: f64 = s.parse().map_err(|e| err(&format!("{what}: {e}")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(&format!("{what}: not finite")))
            }
        };
        let (l, sigma) = (num(f[3], "l")?, num(f[4], "sigma")?);
        let (var_sf, var_opt) = (num(f[5], "var_sf")?, num(f[6], "var_opt")?);
        if n == 0 || l <= 0.0 || sigma < 0.0 {
            return Err(err("N and l must be positive, sigma non-negative"));
        }
        if sets.iter().any(|s| s.key == f[1] && s.n == n) {
            return Err(err(&format!("duplicate set ({}, N = {n})", f[1])));
        }
        sets.push(OptimalSet {
            key: f[1].to_string(),
            e,
            n,
            l,
            sigma,
            var_sf,
            var_opt,
            dirs: Vec::with_capacity(n),
        });
        expect = n;
    }
    if expect > 0 {
        return Err(format!("the last set lacks {expect} directions"));
    }
    Ok(sets)
}

/// The set of `key` and size `n`.
pub fn find<'a>(sets: &'a [OptimalSet], key: &str, n: usize) -> Option<&'a OptimalSet> {
    sets.iter().find(|s| s.key == key && s.n == n)
}
