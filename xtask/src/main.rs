//! `cargo xtask`: the data pipeline of sphere-quadrature as tools (the alias is in
//! `.cargo/config.toml`).
//!
//! ```text
//! cargo xtask regen                  # regenerate every generated and learned file, in order
//! cargo xtask regen NAME...          # only these generators (in dependency order)
//! cargo xtask regen --check [NAME...]  # regenerate, compare with the committed files, restore
//! cargo xtask list                   # the generators, their outputs and commands
//! ```
//!
//! Each generator is the program that owns the computation: a writer of `xtask/writers/`
//! (`cargo writer NAME`, the programs that write library inputs and read nothing else's
//! output but the maps and the measurements), a benchmark of `eval/` with its explicit write
//! flag where the table is fitted by the benchmark's own run, or the bake test. This tool runs
//! them in dependency order so that a change to an input is followed by every file downstream
//! of it. `--check` keeps the
//! committed bytes of every output in memory, runs the generators, compares, puts the committed
//! bytes back (whatever happened), and fails with one line naming the files that differ.
//!
//! A file that a generator rewrites with the bytes it already held keeps its modification
//! time (and `--check` leaves every file with the time it had): cargo reruns the library's
//! build script when a file of `tables/` is newer than its last run, so a regeneration that
//! reproduces the tables costs no rebuild of everything that depends on them.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::SystemTime;

/// One generator: what it writes, and the command that writes it.
struct Generator {
    name: &'static str,
    /// Files (or directories, every file under them) the command writes.
    outputs: &'static [&'static str],
    /// The command, from the repository root.
    command: &'static [&'static str],
    /// Environment variables of the command.
    env: &'static [(&'static str, &'static str)],
    /// What it reads that another generator writes (documentation of the order).
    after: &'static str,
}

/// The generators in dependency order: the learned families before the calibration that is
/// fitted on them, the tables before the bake that compiles them, the bake last.
const GENERATORS: &[Generator] = &[
    Generator {
        name: "hyperparameters",
        outputs: &["tables/probe.txt", "tables/bmc_smooth.txt", "docs/hyperparameters.md"],
        command: &["cargo", "writer", "learn_hyperparameters", "--", "--write"],
        env: &[],
        after: "the maps",
    },
    Generator {
        name: "calibration",
        outputs: &["tables/probe.txt"],
        command: &["cargo", "writer", "probe_calibration", "--", "--write"],
        env: &[],
        after: "hyperparameters (the families of tables/probe.txt)",
    },
    Generator {
        name: "renderer-hyperparameters",
        outputs: &["tables/renderer_hyperparameters.txt"],
        command: &["cargo", "writer", "renderer_hyperparameters", "--", "--write"],
        env: &[],
        after: "the maps",
    },
    Generator {
        name: "optimal-sets",
        outputs: &["tables/optimal_sets.txt", "docs/optimal_sets.md"],
        command: &["cargo", "writer", "optimal_sets", "--", "--write", "--out", "docs"],
        env: &[],
        after: "renderer-hyperparameters",
    },
    Generator {
        name: "sensor-priors",
        outputs: &["tables/sensor_priors.rs"],
        command: &["cargo", "writer", "sensor_priors", "--", "--write"],
        env: &[],
        after: "the maps",
    },
    Generator {
        name: "sensor-readings",
        outputs: &["examples/cortex-m4/src/sensor_readings.rs"],
        command: &["cargo", "writer", "sensor_readings", "--", "--write"],
        env: &[],
        after: "sensor-priors (the crate's layout probes)",
    },
    Generator {
        name: "doc-numbers",
        outputs: &["README.md", "docs/costs.md"],
        command: &["cargo", "writer", "doc_numbers", "--", "--write"],
        env: &[],
        after: "the Cortex-M4 measurements in target/ci/ (`.ci/run embedded`)",
    },
    Generator {
        name: "baked",
        outputs: &["baked"],
        command: &["cargo", "test", "--release", "--test", "bmc", "baked::"],
        env: &[("SPHERE_QUADRATURE_WRITE_BAKED", "1")],
        after: "every table above (gen/, tables/, build.rs)",
    },
];

fn usage() -> String {
    let names: Vec<&str> = GENERATORS.iter().map(|g| g.name).collect();
    format!(
        "usage: cargo xtask regen [--check] [NAME...]\n       cargo xtask list\n\n\
         regen            regenerate every generated and learned file, in dependency order\n\
         regen NAME...    only these generators (still in dependency order)\n\
         regen --check    regenerate, compare with the committed files, put them back; \
         fail with one line if any differs\n\
         list             the generators, their outputs and commands\n\n\
         generators: {}",
        names.join(", ")
    )
}

/// The repository root: the parent of this crate's directory.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask/ has a parent").to_path_buf()
}

/// Every file at `path` (itself, or every file under it), sorted.
fn files(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = fs::read_dir(path)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        entries.sort();
        for e in entries {
            files(&e, out);
        }
    } else if path.exists() {
        out.push(path.to_path_buf());
    }
}

/// A file's bytes and modification time.
type Snapshot = BTreeMap<PathBuf, (Vec<u8>, Option<SystemTime>)>;

/// The bytes and modification time of every output file of `gens`, by path.
fn snapshot(root: &Path, gens: &[&Generator]) -> Snapshot {
    let mut map = BTreeMap::new();
    for g in gens {
        for o in g.outputs {
            let mut fs_ = Vec::new();
            files(&root.join(o), &mut fs_);
            for f in fs_ {
                if let Ok(bytes) = fs::read(&f) {
                    let time = fs::metadata(&f).and_then(|m| m.modified()).ok();
                    map.insert(f, (bytes, time));
                }
            }
        }
    }
    map
}

/// Gives back its modification time in `before` to every file whose bytes are those of
/// `before` (a generator that rewrote a file with the same bytes leaves it as it was).
fn keep_times(before: &Snapshot) {
    for (path, (bytes, time)) in before {
        let Some(time) = time else { continue };
        if fs::read(path).ok().as_ref() == Some(bytes) {
            if let Ok(f) = fs::File::options().write(true).open(path) {
                let _ = f.set_modified(*time);
            }
        }
    }
}

/// Runs the generators in order; after each, the files it reproduced keep their times.
fn run_all(root: &Path, gens: &[&Generator]) -> Result<(), String> {
    for g in gens {
        let before = snapshot(root, &[g]);
        let result = run(root, g);
        keep_times(&before);
        result?;
    }
    Ok(())
}

/// Runs one generator; `Err` with a one-line reason if it fails.
fn run(root: &Path, g: &Generator) -> Result<(), String> {
    eprintln!("xtask regen {}: {}", g.name, g.command.join(" "));
    let status = Command::new(g.command[0])
        .args(&g.command[1..])
        .envs(g.env.iter().copied())
        .current_dir(root)
        .status()
        .map_err(|e| format!("{}: cannot run {}: {e}", g.name, g.command[0]))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{}: `{}` failed ({status})", g.name, g.command.join(" ")))
    }
}

/// Lines of `a` not in `b` and of `b` not in `a`, counted as a multiset difference.
fn line_changes(a: &[u8], b: &[u8]) -> (usize, usize) {
    let text = |x: &[u8]| String::from_utf8_lossy(x).lines().map(str::to_owned).collect::<Vec<_>>();
    let mut count: BTreeMap<String, i64> = BTreeMap::new();
    for l in text(a) {
        *count.entry(l).or_default() += 1;
    }
    for l in text(b) {
        *count.entry(l).or_default() -= 1;
    }
    let removed = count.values().filter(|&&c| c > 0).sum::<i64>() as usize;
    let added = count.values().filter(|&&c| c < 0).map(|c| -c).sum::<i64>() as usize;
    (added, removed)
}

/// `text` with every duration (`12 s`, `3.5 s`: digits, an optional fraction, a space and an
/// `s` that ends a word) replaced by `T s`.
fn without_times(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        let starts =
            c[i].is_ascii_digit() && (i == 0 || !(c[i - 1].is_alphanumeric() || c[i - 1] == '.'));
        if starts {
            let mut j = i;
            while j < c.len() && c[j].is_ascii_digit() {
                j += 1;
            }
            if j + 1 < c.len() && c[j] == '.' && c[j + 1].is_ascii_digit() {
                j += 1;
                while j < c.len() && c[j].is_ascii_digit() {
                    j += 1;
                }
            }
            let ends_word = |k: usize| k >= c.len() || !(c[k].is_alphanumeric() || c[k] == '_');
            if j + 1 < c.len() && c[j] == ' ' && c[j + 1] == 's' && ends_word(j + 2) {
                out.push_str("T s");
                i = j + 2;
                continue;
            }
            out.extend(&c[i..j]);
            i = j;
            continue;
        }
        out.push(c[i]);
        i += 1;
    }
    out
}

fn regen(args: &[String]) -> Result<(), String> {
    let check = args.iter().any(|a| a == "--check");
    let names: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    if let Some(bad) = args.iter().find(|a| a.starts_with("--") && *a != "--check") {
        return Err(format!("unknown option {bad}\n{}", usage()));
    }
    for n in &names {
        if !GENERATORS.iter().any(|g| g.name == n.as_str()) {
            return Err(format!("unknown generator {n}\n{}", usage()));
        }
    }
    let gens: Vec<&Generator> = GENERATORS
        .iter()
        .filter(|g| names.is_empty() || names.iter().any(|n| n.as_str() == g.name))
        .collect();
    let root = root();
    if !check {
        return run_all(&root, &gens);
    }
    let before = snapshot(&root, &gens);
    let result = run_all(&root, &gens);
    let after = snapshot(&root, &gens);
    // Put the committed bytes (and times) back whatever happened, and remove files the run
    // added.
    for (path, (bytes, _)) in &before {
        if after.get(path).map(|a| &a.0) != Some(bytes) {
            fs::write(path, bytes)
                .map_err(|e| format!("cannot restore {}: {e}", path.display()))?;
        }
    }
    keep_times(&before);
    for path in after.keys().filter(|p| !before.contains_key(*p)) {
        let _ = fs::remove_file(path);
    }
    result?;
    let mut differ = Vec::new();
    for path in before.keys().chain(after.keys().filter(|p| !before.contains_key(*p))) {
        let (a, b) = (before.get(path).map(|x| &x.0), after.get(path).map(|x| &x.0));
        let same = match (a, b) {
            // A report states how long its run took: compared without those times, as
            // `.ci/docs-current.sh` compares the benchmarks' reports.
            (Some(a), Some(b)) if path.extension().is_some_and(|e| e == "md") => {
                without_times(a) == without_times(b)
            }
            _ => a == b,
        };
        if !same {
            let rel = path.strip_prefix(&root).unwrap_or(path).display().to_string();
            differ.push(match (a, b) {
                (Some(a), Some(b)) => {
                    let (added, removed) = line_changes(a, b);
                    format!("{rel} (+{added} −{removed} lines)")
                }
                (Some(_), None) => format!("{rel} (not written)"),
                _ => format!("{rel} (new)"),
            });
        }
    }
    let which: Vec<&str> = gens.iter().map(|g| g.name).collect();
    if differ.is_empty() {
        println!("regen --check: current ({}; {} files)", which.join(", "), before.len());
        Ok(())
    } else {
        Err(format!(
            "regen --check: {} of {} files differ from a regeneration: {} (run `cargo xtask regen {}`)",
            differ.len(),
            before.len().max(after.len()),
            differ.join(", "),
            which.join(" ")
        ))
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("regen") => regen(&args[1..]),
        Some("list") => {
            for g in GENERATORS {
                let env: Vec<String> = g.env.iter().map(|(k, v)| format!("{k}={v} ")).collect();
                println!(
                    "{}\n  writes: {}\n  command: {}{}\n  after: {}",
                    g.name,
                    g.outputs.join(", "),
                    env.concat(),
                    g.command.join(" "),
                    g.after
                );
            }
            Ok(())
        }
        Some("-h" | "--help" | "help") => {
            println!("{}", usage());
            Ok(())
        }
        _ => Err(usage()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_changes_count_added_and_removed_lines() {
        assert_eq!(line_changes(b"a\nb\nc\n", b"a\nb\nc\n"), (0, 0));
        assert_eq!(line_changes(b"a\nb\n", b"a\nx\ny\n"), (2, 1));
        assert_eq!(line_changes(b"a\na\n", b"a\n"), (0, 1));
    }

    #[test]
    fn durations_are_masked_and_nothing_else() {
        assert_eq!(without_times(b"took 12 s (3.5 s CPU)"), "took T s (T s CPU)");
        assert_eq!(without_times(b"N = 16 samples, 2 sets, a1 s"), "N = 16 samples, 2 sets, a1 s");
        assert_ne!(without_times(b"error 1.5 %"), without_times(b"error 1.6 %"));
    }

    #[test]
    fn generators_have_unique_names_and_a_command() {
        for (i, g) in GENERATORS.iter().enumerate() {
            assert!(!g.command.is_empty() && !g.outputs.is_empty(), "{}", g.name);
            assert!(GENERATORS[i + 1..].iter().all(|h| h.name != g.name), "{}", g.name);
        }
        assert_eq!(GENERATORS.last().map(|g| g.name), Some("baked"), "the bake runs last");
    }
}
