//! The prebaked default tables in `baked/`: what [`super::default_files`] writes for the
//! crate's own `tables/`, stored compactly and keyed by a hash of everything that determines
//! it ([`key`]: the generator in `gen/`, `build.rs` and the table files).
//!
//! `build.rs` expands them instead of baking when the key matches and the family has no user
//! table or feature sweep; any other build bakes from `tables/` as before. `tests/bmc/baked.rs`
//! checks that the key is current and that the expansion equals a fresh bake byte for byte
//! (and rewrites `baked/` with `SPHERE_QUADRATURE_WRITE_BAKED=1`).
//!
//! # Format
//! `baked/index.txt` holds `key HEX` and one `file NAME` line per generated file, in order.
//! `baked/NAME.skel` is that file's text with runs of numeric lines replaced by one line
//! `@T PER COUNT`: `COUNT` lines of template `T` with `PER` 32-bit words each, the words taken
//! in order from `baked/words.bin` (little-endian u32, continuing across the files). A line
//! of the text that starts with `@` is stored as `@@…`. A line becomes a template only when
//! rendering its words reproduces it exactly, so the expansion is the text, byte for byte.
//! Templates (`B(w)` is `f32::from_bits(0xHHHH_HHHH)`, `D(w)` the `{:?}` of that f32):
//! `1`: `    0xHHHHHHHH, 0xHHHHHHHH,` (one or more words); `2`: `    B(w), // D(w)`;
//! `3`: `    [B(a), B(b), B(c)], // D(a)`.

use std::fmt::Write as _;
use std::path::Path;

/// The directory of the cache, relative to the crate root.
pub const DIR: &str = "baked";

/// Part of the key: change it when the format or the expansion changes.
const VERSION: &str = "baked-v1";

/// The files that determine the default bake, relative to the crate root and sorted: `build.rs`,
/// `gen/*.rs` and `tables/*.txt`.
pub fn inputs(root: &Path) -> Result<Vec<String>, String> {
    let mut out = vec!["build.rs".to_string()];
    for (dir, ext) in [("gen", "rs"), ("tables", "txt")] {
        let entries =
            std::fs::read_dir(root.join(dir)).map_err(|e| format!("cannot read {dir}/: {e}"))?;
        let mut names: Vec<String> = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| format!("cannot read {dir}/: {e}"))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let is_file = entry.file_type().is_ok_and(|t| t.is_file());
            if is_file && name.rsplit_once('.').is_some_and(|(_, x)| x == ext) {
                names.push(format!("{dir}/{name}"));
            }
        }
        names.sort();
        out.extend(names);
    }
    Ok(out)
}

/// The cache key: 64-bit FNV-1a over [`VERSION`] and each input's path and contents (carriage
/// returns dropped, so a CRLF checkout keeps the key), as 16 hex digits.
pub fn key(root: &Path) -> Result<String, String> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            if b != b'\r' {
                h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
        h = (h ^ 0xff).wrapping_mul(0x0000_0100_0000_01b3);
    };
    eat(VERSION.as_bytes());
    for file in inputs(root)? {
        let bytes =
            std::fs::read(root.join(&file)).map_err(|e| format!("cannot read {file}: {e}"))?;
        eat(file.as_bytes());
        eat(&bytes);
    }
    Ok(format!("{h:016x}"))
}

/// The key stored in `baked/index.txt`, if any.
pub fn stored_key(root: &Path) -> Option<String> {
    let index = std::fs::read_to_string(root.join(DIR).join("index.txt")).ok()?;
    index.lines().find_map(|l| l.strip_prefix("key ")).map(|k| k.trim().to_string())
}

/// The cached files when `baked/` holds the bake of `key`; `Ok(None)` when it holds another
/// key or none.
pub fn load(root: &Path, key: &str) -> Result<Option<Vec<(String, String)>>, String> {
    let dir = root.join(DIR);
    let Ok(index) = std::fs::read_to_string(dir.join("index.txt")) else {
        return Ok(None);
    };
    if stored_key(root).as_deref() != Some(key) {
        return Ok(None);
    }
    let words = std::fs::read(dir.join("words.bin"))
        .map_err(|e| format!("cannot read {DIR}/words.bin: {e}"))?;
    let mut at = 0;
    let mut files = Vec::new();
    for name in index.lines().filter_map(|l| l.strip_prefix("file ")) {
        let skel = std::fs::read_to_string(dir.join(format!("{name}.skel")))
            .map_err(|e| format!("cannot read {DIR}/{name}.skel: {e}"))?;
        let text = expand(&skel, &words, &mut at).map_err(|e| format!("{DIR}/{name}.skel: {e}"))?;
        files.push((name.to_string(), text));
    }
    if at != words.len() {
        return Err(format!("{DIR}/words.bin has {} bytes, the skeletons use {at}", words.len()));
    }
    Ok(Some(files))
}

/// Writes `files` as the cache of `key` (replacing what `baked/` held).
pub fn store(root: &Path, key: &str, files: &[(&str, String)]) -> Result<(), String> {
    let dir = root.join(DIR);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {DIR}/: {e}"))?;
    let mut index = format!("key {key}\n");
    let mut words = Vec::new();
    for (name, text) in files {
        let _ = writeln!(index, "file {name}");
        let skel = compact(text, &mut words);
        let path = dir.join(format!("{name}.skel"));
        std::fs::write(&path, skel).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    std::fs::write(dir.join("words.bin"), words).map_err(|e| format!("cannot write words: {e}"))?;
    std::fs::write(dir.join("index.txt"), index).map_err(|e| format!("cannot write index: {e}"))
}

/// The skeleton of `text`, its template words appended to `words`.
pub fn compact(text: &str, words: &mut Vec<u8>) -> String {
    let mut out: Vec<String> = Vec::new();
    // The open run: template, words per line, lines.
    let mut run: Option<(u8, usize, usize)> = None;
    let mut line_words = Vec::new();
    for line in text.split('\n') {
        line_words.clear();
        let template = parse(line, &mut line_words).filter(|&t| {
            let mut again = String::new();
            render(t, &line_words, &mut again);
            again == line
        });
        match (template, &mut run) {
            (Some(t), Some((rt, per, count))) if *rt == t && *per == line_words.len() => {
                *count += 1;
            }
            (Some(t), _) => {
                if let Some((rt, per, count)) = run.take() {
                    out.push(format!("@{rt} {per} {count}"));
                }
                run = Some((t, line_words.len(), 1));
            }
            (None, _) => {
                if let Some((rt, per, count)) = run.take() {
                    out.push(format!("@{rt} {per} {count}"));
                }
                out.push(if line.starts_with('@') { format!("@{line}") } else { line.to_string() });
            }
        }
        if template.is_some() {
            for w in &line_words {
                words.extend_from_slice(&w.to_le_bytes());
            }
        }
    }
    if let Some((rt, per, count)) = run {
        out.push(format!("@{rt} {per} {count}"));
    }
    out.join("\n")
}

/// The text of a skeleton, its words read from `words` at `*at` (advanced past them).
pub fn expand(skel: &str, words: &[u8], at: &mut usize) -> Result<String, String> {
    let mut out = String::with_capacity(skel.len() * 4);
    let mut first = true;
    let mut line_words: Vec<u32> = Vec::new();
    for line in skel.split('\n') {
        let Some(marker) = line.strip_prefix('@') else {
            if !first {
                out.push('\n');
            }
            first = false;
            out.push_str(line);
            continue;
        };
        if marker.starts_with('@') {
            if !first {
                out.push('\n');
            }
            first = false;
            out.push_str(marker);
            continue;
        }
        let bad = || format!("bad marker line `{line}`");
        let mut f = marker.split(' ');
        let mut num = || f.next().and_then(|x| x.parse::<usize>().ok()).ok_or_else(bad);
        let (t, per, count) = (num()?, num()?, num()?);
        let t = u8::try_from(t).ok().filter(|t| (1..=3).contains(t)).ok_or_else(bad)?;
        for _ in 0..count {
            line_words.clear();
            for _ in 0..per {
                let b = words.get(*at..*at + 4).ok_or("words.bin ends early")?;
                line_words.push(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
                *at += 4;
            }
            if !first {
                out.push('\n');
            }
            first = false;
            render(t, &line_words, &mut out);
        }
    }
    Ok(out)
}

/// The template and words of a numeric line, if it has the shape of one (the caller checks
/// that rendering them gives the line back).
fn parse(line: &str, words: &mut Vec<u32>) -> Option<u8> {
    if let Some(rest) = line.strip_prefix("    0x") {
        for item in rest.strip_suffix(',')?.split(", ") {
            words.push(u32::from_str_radix(item.strip_prefix("0x").unwrap_or(item), 16).ok()?);
        }
        return Some(1);
    }
    let (template, count) = if line.starts_with("    f32::from_bits(0x") {
        (2, 1)
    } else if line.starts_with("    [f32::from_bits(0x") {
        (3, 3)
    } else {
        return None;
    };
    let mut rest = line;
    for _ in 0..count {
        let start = rest.find("from_bits(0x")? + "from_bits(0x".len();
        let hex = rest.get(start..start + 9)?;
        let (hi, lo) = hex.split_once('_')?;
        words.push((u32::from_str_radix(hi, 16).ok()? << 16) | u32::from_str_radix(lo, 16).ok()?);
        rest = &rest[start + 9..];
    }
    Some(template)
}

/// Appends the line of template `t` with `words` to `out`.
fn render(t: u8, words: &[u32], out: &mut String) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let hex = |out: &mut String, w: u32, split: bool| {
        for k in (0..8).rev() {
            if split && k == 3 {
                out.push('_');
            }
            out.push(char::from(HEX[(w >> (4 * k)) as usize & 15]));
        }
    };
    match t {
        1 => {
            out.push_str("    ");
            for (i, &w) in words.iter().enumerate() {
                out.push_str(if i == 0 { "0x" } else { ", 0x" });
                hex(out, w, false);
            }
            out.push(',');
        }
        _ => {
            out.push_str(if t == 2 { "    " } else { "    [" });
            for (i, &w) in words.iter().enumerate() {
                out.push_str(if i == 0 { "f32::from_bits(0x" } else { ", f32::from_bits(0x" });
                hex(out, w, true);
                out.push(')');
            }
            out.push_str(if t == 2 { ", // " } else { "], // " });
            let _ = write!(out, "{:?}", f32::from_bits(words.first().copied().unwrap_or(0)));
        }
    }
}
