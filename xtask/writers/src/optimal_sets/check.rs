//! `--check`: recompute every set of a stored table.

use std::error::Error;
use std::path::Path;
use std::time::Instant;

use super::objective::{brdf_of, sf_start, Problem};
use super::{CHECK_TOL, UNIT_TOL};
use sphere_quadrature_eval::optimal;
use sphere_quadrature_eval::parallel::parallel_map;

/// Recomputes every set of `path`; `Err` lists the failures.
pub fn check(path: &Path, threads: usize) -> Result<(), Box<dyn Error>> {
    let clock = Instant::now();
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let sets = optimal::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if sets.is_empty() {
        return Err(format!("{}: no sets", path.display()).into());
    }
    // Largest first, for the workers' balance.
    let mut order: Vec<usize> = (0..sets.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(sets[i].n));
    let results = parallel_map(&order, threads, |_, &i| -> Vec<String> {
        let s = &sets[i];
        let mut bad = Vec::new();
        let what = format!("({}, N = {})", s.key, s.n);
        if s.dirs.len() != s.n {
            bad.push(format!("{what}: {} directions, not {}", s.dirs.len(), s.n));
            return bad;
        }
        for (j, d) in s.dirs.iter().enumerate() {
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if (r - 1.0).abs() > UNIT_TOL {
                bad.push(format!("{what}: direction {j} has length {r} (not a unit vector)"));
            }
        }
        let brdf = match brdf_of(&s.key) {
            Ok(b) => b,
            Err(e) => {
                bad.push(e);
                return bad;
            }
        };
        let p = Problem::new(brdf, s.n, s.l, s.sigma);
        let sf = sf_start(brdf, s.n, 0.0);
        for (name, stored, got) in [
            ("var_sf", s.var_sf, p.variance(&sf)),
            ("var_opt", s.var_opt, p.variance(&s.unit_dirs())),
        ] {
            match got {
                None => bad.push(format!("{what}: {name}: Q is not positive definite")),
                Some(v) => {
                    let rel = (v - stored).abs() / stored.abs().max(1e-300);
                    if rel.is_nan() || rel > CHECK_TOL {
                        bad.push(format!(
                            "{what}: {name} = {v:e} recomputed, {stored:e} stored \
                             (relative difference {rel:.1e} > {CHECK_TOL:e})"
                        ));
                    }
                }
            }
        }
        bad
    });
    let bad: Vec<String> = results.into_iter().flatten().collect();
    let secs = clock.elapsed().as_secs_f64();
    if bad.is_empty() {
        println!(
            "{}: {} sets checked (var_sf, var_opt within {CHECK_TOL:e} relative; unit \
             directions) in {secs:.1} s",
            path.display(),
            sets.len()
        );
        Ok(())
    } else {
        for b in &bad {
            eprintln!("FAIL {b}");
        }
        Err(format!("{}: {} failures ({secs:.1} s)", path.display(), bad.len()).into())
    }
}
