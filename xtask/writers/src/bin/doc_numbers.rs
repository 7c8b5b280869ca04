//! The Cortex-M4 costs quoted in the docs, checked against (or rewritten from) the device.
//!
//! ```text
//! (cd examples/cortex-m4 && cargo run --release) > target/ci/m4-libm.txt
//! .ci/m4-flash.sh > target/ci/m4-flash.txt
//! cargo writer doc_numbers                # check the docs (CI)
//! cargo writer doc_numbers -- --write     # rewrite them from the measurements
//! cargo xtask regen doc-numbers           # the rewrite, in the pipeline's order
//! ```
//!
//! The measurements are quoted in generated regions of `README.md` and `docs/costs.md`, between
//! `<!-- numbers: TEMPLATE -->` and `<!-- /numbers -->`: the template file with each
//! `{m4:NAME N=n}` (the device's `# count NAME N=n K instructions/call`), `{ram:NAME N=n}` (its
//! `# ram NAME N=n B`: the size of a type in RAM), `{code:NAME N=n}` and `{data:NAME N=n}`
//! (`.ci/m4-flash.sh`'s `# flash NAME N=n CODE DATA`) replaced by the measurement. The rustdoc
//! of `src/` quotes none (it links to the `costs` module, which includes `docs/costs.md`): a
//! line of `src/` that holds a quote such as "`` `m4:NAME N=n` ``" is an error.
//!
//! The same files may quote reports: each line between `<!-- quote: docs/REPORT.md -->` and
//! `<!-- /quote -->` must be a line of that generated report, verbatim.
//!
//! The size in a name is `N=n`, or `K=n` for a count of sensors (`m4:layout_init K=16`).
//! Numbers are written in groups of three digits separated by spaces (`88 800`). Without
//! `--write` the program fails, listing every place that disagrees, if any generated region
//! differs from its template and the measurements, or a template names a measurement that
//! does not exist.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;

use sphere_quadrature_eval::cli;

/// Check (or rewrite) the Cortex-M4 instruction counts, RAM and flash sizes quoted in README.md
/// and docs/costs.md against the device's output.
#[derive(Parser)]
#[command(bin_name = "cargo writer doc_numbers --")]
struct Args {
    /// The Cortex-M4 scenario's output with the `libm` backend
    /// (`cd examples/cortex-m4 && cargo run --release`).
    #[arg(long, default_value = "target/ci/m4-libm.txt")]
    m4: PathBuf,
    /// The flash sizes (`.ci/m4-flash.sh`).
    #[arg(long, default_value = "target/ci/m4-flash.txt")]
    flash: PathBuf,
    /// Rewrite the quoted numbers from the measurements instead of checking them.
    #[arg(long)]
    write: bool,
}

/// A measurement's name and size: `NAME N=n` (or `K=n`) as ("NAME", "N=n").
type Key = (String, String);

#[derive(Default)]
struct Measured {
    /// Instructions per call.
    m4: BTreeMap<Key, u64>,
    /// Bytes of RAM.
    ram: BTreeMap<Key, u64>,
    /// Bytes of code, bytes of tables.
    flash: BTreeMap<Key, (u64, u64)>,
}

impl Measured {
    fn load(m4: &Path, flash: &Path) -> Result<Self, String> {
        let read = |p: &Path| {
            std::fs::read_to_string(p).map_err(|e| format!("cannot read {}: {e}", p.display()))
        };
        let mut out = Self::default();
        for line in read(m4)?.lines() {
            // "# count NAME N=n K instructions/call"
            let w: Vec<&str> = line.split_whitespace().collect();
            if let ["#", "count", name, n, k, "instructions/call"] = w[..] {
                out.m4.insert(key(name, n)?, number(k)?);
            }
            // "# ram NAME N=n B"
            if let ["#", "ram", name, n, b] = w[..] {
                out.ram.insert(key(name, n)?, number(b)?);
            }
        }
        for line in read(flash)?.lines() {
            // "# flash NAME N=n CODE DATA"
            let w: Vec<&str> = line.split_whitespace().collect();
            if let ["#", "flash", name, n, code, data] = w[..] {
                out.flash.insert(key(name, n)?, (number(code)?, number(data)?));
            }
        }
        if out.m4.is_empty() || out.flash.is_empty() {
            return Err(format!(
                "no measurements in {} ({} counts) or {} ({} sizes)",
                m4.display(),
                out.m4.len(),
                flash.display(),
                out.flash.len()
            ));
        }
        Ok(out)
    }
}

fn number(s: &str) -> Result<u64, String> {
    s.parse().map_err(|_| format!("not a count: {s:?}"))
}

fn key(name: &str, n: &str) -> Result<Key, String> {
    let size = n.strip_prefix("N=").or_else(|| n.strip_prefix("K="));
    let size = size.ok_or_else(|| format!("expected N=n or K=n, found {n:?}"))?;
    number(size)?;
    Ok((name.to_string(), n.to_string()))
}

/// `n` in groups of three digits separated by spaces: `88 800`, `2 716`, `57`.
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// One quoted number that disagrees, or names nothing measured.
struct Problem {
    place: String,
    what: String,
}

/// The template with every `{m4:…}`, `{ram:…}`, `{code:…}` and `{data:…}` replaced.
fn render(template: &str, measured: &Measured, place: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let close = rest[open..].find('}').ok_or_else(|| format!("{place}: unclosed {{"))? + open;
        let inner = &rest[open + 1..close];
        let (kind, name) = inner.split_once(':').ok_or_else(|| format!("{place}: {{{inner}}}"))?;
        let (name, n) = name.split_once(' ').ok_or_else(|| format!("{place}: {{{inner}}}"))?;
        let k = key(name, n)?;
        let value = match kind {
            "m4" => measured.m4.get(&k).copied(),
            "ram" => measured.ram.get(&k).copied(),
            "code" => measured.flash.get(&k).map(|f| f.0),
            "data" => measured.flash.get(&k).map(|f| f.1),
            _ => return Err(format!("{place}: unknown placeholder {{{inner}}}")),
        };
        let value = value.ok_or_else(|| format!("{place}: {{{inner}}} was not measured"))?;
        out.push_str(&grouped(value));
        rest = &rest[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

const OPEN: &str = "<!-- numbers: ";
const CLOSE: &str = "<!-- /numbers -->";

/// README.md with its generated regions rendered from their templates.
fn generated_regions(
    root: &Path,
    text: &str,
    measured: &Measured,
    regions: &mut usize,
) -> Result<String, String> {
    let mut out = String::new();
    let mut lines = text.split_inclusive('\n');
    while let Some(line) = lines.next() {
        out.push_str(line);
        let Some(template) =
            line.trim_end().strip_prefix(OPEN).and_then(|t| t.strip_suffix(" -->"))
        else {
            continue;
        };
        let path = root.join(template);
        let body = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        out.push_str(&render(&body, measured, template)?);
        // Skip the old region up to its closing marker, which is kept.
        loop {
            let Some(old) = lines.next() else {
                return Err(format!("README.md: {template}: no {CLOSE}"));
            };
            if old.trim_end() == CLOSE {
                out.push_str(old);
                break;
            }
        }
        *regions += 1;
    }
    Ok(out)
}

/// The files with generated regions and quotes of reports.
const GENERATED: [&str; 2] = ["README.md", "docs/costs.md"];
const QUOTE: &str = "<!-- quote: ";
const QUOTE_END: &str = "<!-- /quote -->";

/// Every line between `<!-- quote: REPORT -->` and `<!-- /quote -->` must be a line of
/// `REPORT` (a generated report under `docs/`), verbatim.
fn quoted_lines(
    root: &Path,
    name: &str,
    text: &str,
    quotes: &mut usize,
    problems: &mut Vec<Problem>,
) -> Result<(), String> {
    let mut source: Option<(String, Vec<String>)> = None;
    for (i, line) in text.lines().enumerate() {
        let place = format!("{name}:{}", i + 1);
        if let Some(rest) = line.strip_prefix(QUOTE) {
            let Some(report) = rest.strip_suffix(" -->") else {
                return Err(format!("{place}: no ` -->` after the quoted report's name"));
            };
            let body = std::fs::read_to_string(root.join(report))
                .map_err(|e| format!("{place}: {report}: {e}"))?;
            source = Some((report.to_string(), body.lines().map(str::to_string).collect()));
        } else if line == QUOTE_END {
            source = None;
        } else if let Some((report, lines)) = &source {
            *quotes += 1;
            if !lines.iter().any(|l| l == line) {
                problems.push(Problem {
                    place,
                    what: format!("not a line of {report} (rerun its benchmark, then quote it)"),
                });
            }
        }
    }
    if source.is_some() {
        return Err(format!("{name}: a quote has no {QUOTE_END}"));
    }
    Ok(())
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            rust_files(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    Ok(())
}

fn run(args: &Args) -> Result<bool, String> {
    let measured = Measured::load(&args.m4, &args.flash)?;
    let root = cli::repo_root();
    let mut problems = Vec::new();
    let mut changed = Vec::new();

    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files).map_err(|e| format!("src/: {e}"))?;
    files.sort();
    for path in &files {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let rel = path.strip_prefix(root).unwrap_or(path).display().to_string();
        for (i, line) in text.lines().enumerate() {
            if ["`m4:", "`ram:", "`flash:"].iter().any(|q| line.contains(q)) {
                problems.push(Problem {
                    place: format!("{rel}:{}", i + 1),
                    what: "quotes a measurement: the costs belong in docs/templates/costs.md"
                        .into(),
                });
            }
        }
    }

    let mut regions = 0;
    let mut quotes = 0;
    for name in GENERATED {
        let path = root.join(name);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{name}: {e}"))?;
        let new = generated_regions(root, &text, &measured, &mut regions)?;
        if new != text {
            problems.push(Problem {
                place: name.into(),
                what: "a generated region differs from its template and the measurements".into(),
            });
            changed.push((path, new));
        }
        quoted_lines(root, name, &text, &mut quotes, &mut problems)?;
    }

    if args.write {
        for (path, text) in &changed {
            std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
            println!("rewrote {}", path.display());
        }
        return Ok(true);
    }
    for p in &problems {
        eprintln!("{}: {}", p.place, p.what);
    }
    println!(
        "{regions} generated region(s) and {quotes} quoted report line(s) of {}, no quote in \
         src/: {}",
        GENERATED.join(" and "),
        if problems.is_empty() { "all equal the measurements" } else { "see the errors above" }
    );
    Ok(problems.is_empty())
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(&args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => {
            eprintln!("rerun with --write to take the measurements (after checking them)");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("doc_numbers: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups() {
        assert_eq!(grouped(57), "57");
        assert_eq!(grouped(2716), "2 716");
        assert_eq!(grouped(33_627_000), "33 627 000");
    }

    #[test]
    fn templates() {
        let mut m = Measured::default();
        m.m4.insert(key("probe_update", "N=64").unwrap(), 88_801);
        m.flash.insert(key("probe_update", "N=64").unwrap(), (18_396, 24_096));
        m.m4.insert(key("layout_init", "K=6").unwrap(), 317_640);
        m.ram.insert(key("layout_f32", "K=6").unwrap(), 2_868);
        let t = render("a {m4:probe_update N=64} b {code:probe_update N=64}", &m, "t").unwrap();
        assert_eq!(t, "a 88 801 b 18 396");
        let t = render("{data:probe_update N=64}, {ram:layout_f32 K=6}", &m, "t").unwrap();
        assert_eq!(t, "24 096, 2 868");
        assert_eq!(render("{m4:layout_init K=6}", &m, "t").unwrap(), "317 640");
        // K=n is not N=n, and a name the device did not print is an error.
        assert!(render("{m4:layout_init N=6}", &m, "t").is_err());
        assert!(render("{m4:other N=1}", &m, "t").is_err());
        assert!(render("{size:probe_update N=64}", &m, "t").is_err());
        assert!(key("layout_init", "M=6").is_err());
    }
}
