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
//! Two kinds of place quote a measurement:
//! - rustdoc lines in `src/`: "`` `m4:NAME N=n`: K instructions ``" (the device's
//!   `# count NAME N=n K instructions/call`), "`` `ram:NAME N=n`: B bytes ``" (the device's
//!   `# ram NAME N=n B`: the size of a type in RAM) and "`` `flash:NAME N=n`: C bytes of code
//!   and D bytes of tables ``" (`.ci/m4-flash.sh`'s `# flash NAME N=n C D`);
//! - generated regions of `README.md` and `docs/costs.md`, between `<!-- numbers: TEMPLATE -->` and
//!   `<!-- /numbers -->`: the template file with each `{m4:NAME N=n}`, `{code:NAME N=n}` and
//!   `{data:NAME N=n}` replaced by the measurement.
//!
//! - quoted lines, between `<!-- quote: docs/REPORT.md -->` and `<!-- /quote -->` in the same
//!   files: each must be a line of that generated report, verbatim.
//!
//! The size in a name is `N=n`, or `K=n` for a count of sensors (`m4:layout_init K=16`).
//! Numbers are written in groups of three digits separated by spaces (`88 800`). Without
//! `--write` the program fails, listing every place that disagrees, if any quoted number
//! differs from the measurement or names one the measurements do not have.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;

use sphere_quadrature_eval::cli;

/// Check (or rewrite) the Cortex-M4 instruction counts and flash sizes quoted in the rustdoc of
/// `src/`, README.md and docs/costs.md against the device's output.
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

/// The grouped number at the start of `s` (`88 800 instructions` → 88 800, its 6 bytes).
fn leading_grouped(s: &str) -> Option<(u64, usize)> {
    let b = s.as_bytes();
    let mut end = b.iter().take_while(|c| c.is_ascii_digit()).count();
    if end == 0 {
        return None;
    }
    // Further groups: a space and exactly three digits, not followed by another digit.
    while b.len() >= end + 4
        && b[end] == b' '
        && b[end + 1..end + 4].iter().all(u8::is_ascii_digit)
        && b.get(end + 4).is_none_or(|c| !c.is_ascii_digit())
    {
        end += 4;
    }
    let value = s[..end].replace(' ', "").parse().ok()?;
    Some((value, end))
}

/// Parses the key `NAME N=n` that follows a prefix such as "`m4:": returns it and the rest of
/// the line after the closing "`: ".
fn quoted_key(s: &str) -> Option<(Key, &str)> {
    let close = s.find('`')?;
    let (name, n) = s[..close].split_once(' ')?;
    let key = key(name, n).ok()?;
    Some((key, s[close..].strip_prefix("`: ")?))
}

/// One quoted number that disagrees, or names nothing measured.
struct Problem {
    place: String,
    what: String,
}

/// Checks or rewrites the rustdoc quotes of one line; returns the line as it should be.
fn doc_line(line: &str, measured: &Measured, place: &str, problems: &mut Vec<Problem>) -> String {
    let mut report = |what: String| problems.push(Problem { place: place.into(), what });
    let mut out = String::new();
    let mut rest = line;
    // The first quote on the rest of the line, while there is one.
    let first = |rest: &str| {
        ["`m4:", "`ram:", "`flash:"]
            .into_iter()
            .filter_map(|p| rest.find(p).map(|at| (at, p)))
            .min()
    };
    while let Some((at, prefix)) = first(rest) {
        out.push_str(&rest[..at + prefix.len()]);
        rest = &rest[at + prefix.len()..];
        let Some((key, after)) = quoted_key(rest) else {
            report(format!("cannot parse {prefix}"));
            continue;
        };
        let name = format!("{} {}", key.0, key.1);
        out.push_str(&rest[..rest.len() - after.len()]);
        rest = after;
        if prefix != "`flash:" {
            let (kind, unit, table) = if prefix == "`m4:" {
                ("m4", " instructions", &measured.m4)
            } else {
                ("ram", " bytes", &measured.ram)
            };
            let Some((k, len)) =
                leading_grouped(rest).filter(|(_, len)| rest[*len..].starts_with(unit))
            else {
                report(format!("{kind}:{name}: expected \"K{unit}\""));
                continue;
            };
            match table.get(&key) {
                Some(&device) => {
                    if device != k {
                        report(format!("{kind}:{name} says {k}{unit}, the device {device}"));
                    }
                    out.push_str(&grouped(device));
                }
                None => {
                    report(format!("cites {kind}:{name}, which the device does not print"));
                    out.push_str(&rest[..len]);
                }
            }
            rest = &rest[len..];
        } else {
            const MID: &str = " bytes of code and ";
            let parsed = leading_grouped(rest).and_then(|(code, len)| {
                let tail = rest[len..].strip_prefix(MID)?;
                let (data, len2) = leading_grouped(tail)?;
                tail[len2..].starts_with(" bytes of tables").then_some((code, data, len, len2))
            });
            let Some((code, data, len, len2)) = parsed else {
                report(format!("flash:{name}: expected \"C bytes of code and D bytes of tables\""));
                continue;
            };
            let consumed = len + MID.len() + len2;
            match measured.flash.get(&key) {
                Some(&(c, d)) => {
                    if (c, d) != (code, data) {
                        report(format!(
                            "flash:{name} says {code} + {data} bytes, the build {c} + {d}"
                        ));
                    }
                    let _ = write!(out, "{}{MID}{}", grouped(c), grouped(d));
                }
                None => {
                    report(format!("cites flash:{name}, which .ci/m4-flash.sh does not print"));
                    out.push_str(&rest[..consumed]);
                }
            }
            rest = &rest[consumed..];
        }
    }
    out.push_str(rest);
    out
}

/// The template with every `{m4:…}`, `{code:…}` and `{data:…}` replaced.
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
    let (mut m4_cited, mut ram_cited, mut flash_cited) = (0, 0, 0);

    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files).map_err(|e| format!("src/: {e}"))?;
    files.sort();
    for path in &files {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let rel = path.strip_prefix(root).unwrap_or(path).display().to_string();
        let mut new = String::new();
        for (i, line) in text.split_inclusive('\n').enumerate() {
            m4_cited += line.matches("`m4:").count();
            ram_cited += line.matches("`ram:").count();
            flash_cited += line.matches("`flash:").count();
            new.push_str(&doc_line(line, &measured, &format!("{rel}:{}", i + 1), &mut problems));
        }
        if new != text {
            changed.push((path.clone(), new));
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
        "{m4_cited} instruction counts, {ram_cited} RAM sizes and {flash_cited} flash sizes in the \
         rustdoc of src/, {regions} generated region(s) and {quotes} quoted report line(s) of {}: \
         {}",
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
        assert_eq!(leading_grouped("88 800 instructions"), Some((88_800, 6)));
        assert_eq!(leading_grouped("2 716 / 828"), Some((2716, 5)));
        assert_eq!(leading_grouped("57 instructions"), Some((57, 2)));
        assert_eq!(leading_grouped("x"), None);
    }

    #[test]
    fn lines() {
        let mut m = Measured::default();
        m.m4.insert(key("probe_update", "N=64").unwrap(), 88_801);
        m.flash.insert(key("probe_update", "N=64").unwrap(), (18_396, 24_096));
        m.m4.insert(key("layout_init", "K=6").unwrap(), 317_640);
        m.ram.insert(key("layout_f32", "K=6").unwrap(), 2_868);
        let mut problems = Vec::new();
        let line = "/// - `m4:probe_update N=64`: 88 800 instructions (four-member selection)\n";
        let fixed = doc_line(line, &m, "x", &mut problems);
        assert_eq!(fixed, line.replace("88 800", "88 801"));
        assert_eq!(problems.len(), 1);
        problems.clear();
        let line =
            "/// - `flash:probe_update N=64`: 18 396 bytes of code and 24 096 bytes of tables\n";
        assert_eq!(doc_line(line, &m, "x", &mut problems), line);
        assert!(problems.is_empty());
        let line = "/// - `m4:missing N=64`: 1 instructions\n";
        assert_eq!(doc_line(line, &m, "x", &mut problems), line);
        assert_eq!(problems.len(), 1);
        problems.clear();
        // Sizes in sensors, RAM sizes, and K=n is not N=n.
        let line =
            "//! - `m4:layout_init K=6`: 317 640 instructions; `ram:layout_f32 K=6`: 2 868 bytes\n";
        assert_eq!(doc_line(line, &m, "x", &mut problems), line);
        assert!(problems.is_empty());
        let line = "//! `ram:layout_f32 K=6`: 2 000 bytes, `m4:layout_init N=6`: 1 instructions\n";
        let fixed = doc_line(line, &m, "x", &mut problems);
        assert_eq!(fixed, line.replace("2 000", "2 868"));
        assert_eq!(problems.len(), 2);
        assert!(key("layout_init", "M=6").is_err());
        let t = render("a {m4:probe_update N=64} b {code:probe_update N=64}", &m, "t").unwrap();
        assert_eq!(t, "a 88 801 b 18 396");
        assert!(render("{m4:other N=1}", &m, "t").is_err());
    }
}
