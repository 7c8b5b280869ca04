//! f32 against f64 on the accuracy benchmark's maps: the baked f32 probe
//! (`Probe::update` with per-probe selection, then `Probe::irradiance`) against the same
//! model solved in f64 (the generator's own `gen/probe.rs` member: f64 block inverses and
//! f64 `π·z` tables), for the member the f32 probe picked. Also whether an f64 selection would
//! pick the same member.
//!
//! ```text
//! cargo eval precision                 # ten maps, writes target/eval/precision/precision.md
//! cargo eval precision -- --out docs    # regenerates docs/precision.md
//! cargo eval precision -- --quick --out target/precision
//! cargo eval precision -- a.hdr b.hdr --csv rows.csv
//! ```
//!
//! Per map (`clamp` and `smooth` tiers, luminance), N ∈ {16, …, 256}, 32 seeded rotations × 256 seeded
//! normals: relative RMS difference = RMS(E₃₂ − E₆₄) / mean |E₆₄|, the issue's bar being 10⁻⁵.

use sphere_quadrature_eval::{cli, compare, gen, tiers};

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{Probe, ProbeSize};
use sphere_quadrature::{Mat3, Vec3};

/// Per member: squared differences, Σ|E₆₄|, count; and selection agreements.
#[derive(Clone, Default)]
struct Tally {
    sq: Vec<f64>,
    abs: Vec<f64>,
    count: Vec<usize>,
    agree: usize,
    probes: usize,
}

fn run<const N: usize>(
    maps: &[EnvMap],
    rotations: &[Mat3],
    normals: &[Vec3],
) -> Result<Vec<Tally>, Box<dyn Error>>
where
    Size<N>: ProbeSize,
{
    let members: Vec<gen::probe::Member> = Probe::<N>::family()
        .map(|m| gen::probe::bake_member(N, m.lambda, m.sigma))
        .collect::<Result<_, _>>()?;
    let tables: Vec<Vec<[f64; 3]>> =
        members.iter().map(|m| gen::probe::z_table(m.lambda)).collect();
    let k = members.len();
    let mut out = Vec::new();
    for map in maps {
        let mut t =
            Tally { sq: vec![0.0; k], abs: vec![0.0; k], count: vec![0; k], ..Tally::default() };
        for &rot in rotations {
            let mut probe = Probe::<N>::new();
            probe.set_rotation(rot)?;
            let xs: Vec<[f64; 3]> =
                probe.directions().iter().map(|d| [d.x as f64, d.y as f64, d.z as f64]).collect();
            let y: [f32; N] = std::array::from_fn(|j| luminance(map.radiance(xs[j])) as f32);
            probe.update(&y)?;
            let y64: Vec<f64> = y.iter().map(|&v| v as f64).collect();
            // f64: α, β and the REML likelihood of every member.
            let fits: Vec<(Vec<f64>, f64, f64)> = members
                .iter()
                .map(|m| {
                    let qy = m.solve(&y64);
                    let q1 = m.solve(&vec![1.0; N]);
                    let beta = qy.iter().sum::<f64>() / m.s1;
                    let alpha: Vec<f64> = qy.iter().zip(&q1).map(|(a, b)| a - beta * b).collect();
                    let r2: f64 = y64.iter().zip(&alpha).map(|(a, b)| a * b).sum();
                    let ll = m.likelihood_constant() - 0.5 * (N as f64 - 1.0) * r2.max(1e-300).ln();
                    (alpha, beta, ll)
                })
                .collect();
            let best = (0..k).max_by(|&a, &b| fits[a].2.total_cmp(&fits[b].2)).unwrap_or(0);
            let s = probe.selected();
            t.agree += usize::from(best == s);
            t.probes += 1;
            let (alpha, beta, _) = &fits[s];
            for &n in normals {
                let e32 = probe.irradiance(n)?.value as f64;
                let nv = [n.x as f64, n.y as f64, n.z as f64];
                let e64 = std::f64::consts::PI * beta
                    + xs.iter()
                        .zip(alpha)
                        .map(|(x, a)| {
                            let c = x[0] * nv[0] + x[1] * nv[1] + x[2] * nv[2];
                            gen::probe::z_interpolate(&tables[s], c) * a
                        })
                        .sum::<f64>();
                t.sq[s] += (e32 - e64).powi(2);
                t.abs[s] += e64.abs();
                t.count[s] += 1;
            }
        }
        out.push(t);
    }
    Ok(out)
}

/// precision: the baked f32 probe against the same model solved in f64 (issue #6)
#[derive(Parser)]
#[command(bin_name = "cargo eval precision --")]
struct Args {
    /// Equirectangular .hdr maps (default: the ten in examples/envmaps/)
    #[arg(value_name = "MAPS", value_parser = cli::map_file)]
    maps: Vec<PathBuf>,
    /// Write DIR/precision.md (default target/eval/precision; `--out docs` regenerates
    /// the repository's docs)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Also write rows precision,<tier>,<n>,<map>,<rel_diff> (relative RMS difference
    /// RMS(E₃₂ − E₆₄) / mean |E₆₄| of one map and tier over every member)
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// 2 maps, 4 rotations, 32 normals (CI)
    #[arg(long)]
    quick: bool,
}

fn main() -> Result<(), Box<dyn Error>> {
    let raw_args: Vec<String> = std::env::args().skip(1).collect();
    let args = Args::parse();
    let quick = args.quick;
    let out = args.out.unwrap_or_else(|| cli::default_out("precision"));
    let paths = if args.maps.is_empty() { cli::named_maps(quick) } else { args.maps };
    let names: Vec<String> = paths.iter().map(|p| cli::map_name(p)).collect();
    let (n_rot, n_normals) = if quick { (4, 32) } else { (32, 256) };
    let start = std::time::Instant::now();
    // `clamp` then `smooth` of every map.
    let mut maps: Vec<EnvMap> = Vec::new();
    let mut labels: Vec<(String, &str)> = Vec::new();
    for (path, n) in paths.iter().zip(&names) {
        let map = EnvMap::load(path).map_err(|e| format!("cannot load a map: {e}"))?;
        let clamp = compare::clamped(&map);
        let smooth = tiers::smooth(&clamp);
        maps.push(clamp);
        labels.push((n.clone(), "clamp"));
        maps.push(smooth);
        labels.push((n.clone(), "smooth"));
    }
    let mut rng = Rng::new(0x9EC1_0001);
    let v = |d: [f64; 3]| Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    let rotations: Vec<Mat3> = (0..n_rot)
        .map(|_| {
            let r = rng.uniform_rotation();
            Mat3::from_rows(v(r[0]), v(r[1]), v(r[2]))
        })
        .collect();
    let normals: Vec<Vec3> = (0..n_normals).map(|_| v(rng.uniform_sphere())).collect();
    let results = [
        (16, run::<16>(&maps, &rotations, &normals)?, Probe::<16>::family().collect::<Vec<_>>()),
        (32, run::<32>(&maps, &rotations, &normals)?, Probe::<32>::family().collect()),
        (64, run::<64>(&maps, &rotations, &normals)?, Probe::<64>::family().collect()),
        (128, run::<128>(&maps, &rotations, &normals)?, Probe::<128>::family().collect()),
        (256, run::<256>(&maps, &rotations, &normals)?, Probe::<256>::family().collect()),
    ];

    let mut md = String::new();
    writeln!(md, "# f32 probe against the f64 model on the benchmark's maps\n")?;
    writeln!(
        md,
        "`{}` ({:.0} s): `clamp` and `smooth` tiers of {}, {n_rot} \
         rotations × {n_normals} normals per map; relative RMS difference of the irradiance \
         RMS(E₃₂ − E₆₄) / mean |E₆₄|, pooled over the maps, per selected member (the f64 side \
         uses the member the f32 probe selected). Issue #6's bar: 10⁻⁵.\n",
        command(&raw_args),
        start.elapsed().as_secs_f64(),
        names.join(", ")
    )?;
    writeln!(
        md,
        "| N | all queries | worst map | per member: λ (cond(Q)): share of probes, difference | \
         f64 selection agrees |"
    )?;
    writeln!(md, "| ---: | ---: | --- | --- | ---: |")?;
    let mut csv = String::from("benchmark,tier,n,map,rel_diff\n");
    for (n, tallies, family) in &results {
        let k = family.len();
        let (mut sq, mut abs, mut count) = (vec![0.0; k], vec![0.0; k], vec![0usize; k]);
        let (mut agree, mut probes) = (0, 0);
        let mut worst = (0.0f64, String::new());
        for (t, (name, tier)) in tallies.iter().zip(&labels) {
            let (s, a, c): (f64, f64, usize) =
                (t.sq.iter().sum(), t.abs.iter().sum(), t.count.iter().sum());
            let rel = (s / c as f64).sqrt() / (a / c as f64);
            let _ = writeln!(csv, "precision,{tier},{n},{name},{rel:.6e}");
            if rel > worst.0 {
                worst = (rel, format!("{name} {tier}"));
            }
            for j in 0..k {
                sq[j] += t.sq[j];
                abs[j] += t.abs[j];
                count[j] += t.count[j];
            }
            agree += t.agree;
            probes += t.probes;
        }
        let total: usize = count.iter().sum();
        let all = (sq.iter().sum::<f64>() / total as f64).sqrt()
            / (abs.iter().sum::<f64>() / total as f64);
        let per: Vec<String> = family
            .iter()
            .enumerate()
            .map(|(j, m)| {
                let share = count[j] as f64 / total as f64;
                if count[j] == 0 {
                    format!("{} ({:.0e}): 0 %", m.lambda, m.condition)
                } else {
                    let rel = (sq[j] / count[j] as f64).sqrt() / (abs[j] / count[j] as f64);
                    format!("{} ({:.0e}): {:.0} %, {rel:.1e}", m.lambda, m.condition, 100.0 * share)
                }
            })
            .collect();
        writeln!(
            md,
            "| {n} | {all:.2e} | {:.2e} ({}) | {} | {agree}/{probes} |",
            worst.0,
            worst.1,
            per.join("; ")
        )?;
    }
    if let Some(path) = &args.csv {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, &csv)?;
        eprintln!("wrote {}", path.display());
    }
    std::fs::create_dir_all(&out)?;
    let path = out.join("precision.md");
    std::fs::write(&path, &md)?;
    print!("{md}");
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// The command line as the report records it.
fn command(raw_args: &[String]) -> String {
    if raw_args.is_empty() {
        "cargo eval precision".to_string()
    } else {
        format!("cargo eval precision -- {}", raw_args.join(" "))
    }
}
