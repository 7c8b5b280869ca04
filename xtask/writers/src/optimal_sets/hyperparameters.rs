//! The hyperparameters a set is optimised for: the `err` rows of
//! `tables/renderer_hyperparameters.txt`, interpolated between keys as `build.rs` does.

use sphere_quadrature_eval::{gen, optimal};

/// One `err` row: key, N, l, σ′.
type HyperRow = (String, usize, f64, f64);

/// `(l, σ′)` of the `err` rows: `(key, N) → (l, σ′)`.
pub struct Hypers {
    rows: Vec<HyperRow>,
}

impl Hypers {
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut rows = Vec::new();
        for (no, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let f: Vec<&str> = line.split_whitespace().collect();
            let err = |m: &str| format!("hyperparameters, line {}: {m}", no + 1);
            if f.len() != 5 {
                return Err(err("expected `<method> <key> <N> <l> <sigma>`"));
            }
            if f[0] != "err" {
                continue;
            }
            let n: usize = f[2].parse().map_err(|e| err(&format!("N: {e}")))?;
            let l: f64 = f[3].parse().map_err(|e| err(&format!("l: {e}")))?;
            let s: f64 = f[4].parse().map_err(|e| err(&format!("sigma: {e}")))?;
            if !(l > 0.0 && l.is_finite() && s > 0.0 && s.is_finite()) {
                return Err(err("l and sigma must be finite and positive"));
            }
            rows.push((f[1].to_string(), n, l, s));
        }
        Ok(Self { rows })
    }

    /// `(l, σ′, where from)` for `key` at size `n` (module docs).
    pub fn get(&self, key: &str, n: usize) -> Result<(f64, f64, String), String> {
        let find = |k: &str| self.rows.iter().find(|r| r.0 == k && r.1 == n);
        let Some(e) = optimal::exponent_of(key)? else {
            let r = find("diffuse-cos")
                .ok_or_else(|| format!("no `err diffuse-cos {n}` row in the hyperparameters"))?;
            return Ok((r.2, r.3, "diffuse-cos".into()));
        };
        let mut avail: Vec<(f64, &HyperRow)> = self
            .rows
            .iter()
            .filter(|r| r.1 == n)
            .filter_map(|r| match optimal::exponent_of(&r.0) {
                Ok(Some(e)) => Some((e, r)),
                _ => None,
            })
            .collect();
        avail.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (first, last) = match (avail.first(), avail.last()) {
            (Some(f), Some(l)) => (*f, *l),
            _ => return Err(format!("no `err phong* {n}` rows in the hyperparameters")),
        };
        // The values: the build script's rule; here only the report's `from` column.
        let learned: Vec<gen::glossy::Learned> = avail
            .iter()
            .map(|&(e, r)| gen::glossy::Learned { e: e as u32, n, l: r.2, sigma: r.3 })
            .collect();
        let (l, s) = gen::glossy::interpolate(&learned, n, e as u32)?;
        let from = if let Some((_, r)) = avail.iter().find(|a| a.0 == e) {
            r.0.clone()
        } else if e <= first.0 {
            format!("{} (clamped)", first.1 .0)
        } else if e >= last.0 {
            format!("{} (clamped)", last.1 .0)
        } else {
            let k = avail.iter().position(|a| a.0 > e).expect("e below the largest key");
            format!("{}–{} in ln e", avail[k - 1].1 .0, avail[k].1 .0)
        };
        Ok((l, s, from))
    }
}
