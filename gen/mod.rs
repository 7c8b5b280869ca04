//! Table generators, shared by `build.rs` and the host tests (through `#[path]`).
//!
//! Plain std Rust with no dependencies: every firmware build of a user runs this code, so it
//! must compile fast and run fast even in the unoptimised build-script profile.

pub mod bmc;

/// The one line a build script prints for a bad table: `error: FILE:LINE: problem` for a
/// message `line LINE: problem` from a parser, else `error: FILE: message`; never more than
/// one line.
pub fn error_line(file: &str, message: &str) -> String {
    let one_line = message.replace(['\n', '\r'], " ");
    let located = one_line.strip_prefix("line ").and_then(|rest| {
        let (no, problem) = rest.split_once(": ")?;
        no.parse::<usize>().ok().map(|no| format!("error: {file}:{no}: {problem}"))
    });
    located.unwrap_or_else(|| format!("error: {file}: {one_line}"))
}
pub mod cache;
pub mod fp;
pub mod glossy;
pub mod probe;
pub mod sg;

/// A bake that failed: the file to name and the problem ([`error_line`] makes the one line).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// The file the problem is in (a table of `tables/` or a user's).
    pub file: String,
    /// The problem, `line N: …` when a parser knows the line.
    pub message: String,
}

/// Generated files: the name in `$OUT_DIR` and the text.
pub type Files = Vec<(&'static str, String)>;

/// Reads a file of the crate's `tables/` (the glossy sets' learned rows and optimal sets, the
/// feature sweeps), or names it in a [`Failure`].
pub type Read<'a> = &'a dyn Fn(&str) -> Result<String, Failure>;

fn failure(file: &str) -> impl Fn(String) -> Failure + '_ {
    move |message| Failure { file: file.to_string(), message }
}

/// The spherical-Gaussian tables of the config `text` (read from `file`).
pub fn sg_files(file: &str, text: &str) -> Result<Files, Failure> {
    let cfg = sg::parse(text).map_err(failure(file))?;
    let tables = sg::tables(&cfg);
    Ok(vec![("sg_tables.rs", sg::render(&cfg, &tables))])
}

/// The renderer weights of the config `text` (read from `file`), their Q1.31 form for the
/// `fixed` feature and the compile error of an unbaked size listing the baked ones.
pub fn bmc_files(file: &str, text: &str) -> Result<Files, Failure> {
    let specs = bmc::parse(text).map_err(failure(file))?;
    let sets = bmc::bake_all(&specs).map_err(failure(file))?;
    Ok(vec![
        ("bmc_tables.rs", bmc::render(&sets)),
        ("bmc_fixed_tables.rs", bmc::render_fixed(&sets)),
        ("bmc_size_diagnostics.rs", bmc::render_size_diagnostics(&sets)),
    ])
}

/// The glossy renderer's sets of the config `text` (read from `file`), with the renderer
/// benchmark's sweep ([`glossy::SWEEP_FILE`]) when `sweep`.
pub fn glossy_files(file: &str, text: &str, sweep: bool, read: Read) -> Result<Files, Failure> {
    let learned_file = glossy::LEARNED_FILE;
    let learned = glossy::parse_learned(&read(learned_file)?).map_err(failure(learned_file))?;
    let optimal_file = glossy::OPTIMAL_FILE;
    let optimal = glossy::parse_optimal(&read(optimal_file)?).map_err(failure(optimal_file))?;
    let mut specs = glossy::parse(text, &learned, &optimal).map_err(failure(file))?;
    if sweep {
        let sweep_file = glossy::SWEEP_FILE;
        let extra =
            glossy::parse(&read(sweep_file)?, &learned, &optimal).map_err(failure(sweep_file))?;
        for spec in extra {
            if !specs.iter().any(|s| s.n == spec.n && s.e == spec.e && s.optimal == spec.optimal) {
                specs.push(spec);
            }
        }
    }
    let sets = glossy::bake_all(&specs, &optimal).map_err(failure(file))?;
    Ok(vec![("glossy_tables.rs", glossy::render(&sets))])
}

/// The probe families of the config `text` (read from `file`), with the footprint
/// benchmark's sweep ([`probe::SWEEP_FILE`]) when `sweep`, and the `ProbeSize` trait whose
/// compile error lists the baked sizes.
pub fn probe_files(file: &str, text: &str, sweep: bool, read: Read) -> Result<Files, Failure> {
    let mut specs = probe::parse(text).map_err(failure(file))?;
    if sweep {
        let sweep_file = probe::SWEEP_FILE;
        let extra = probe::parse_extra(&read(sweep_file)?).map_err(failure(sweep_file))?;
        for spec in extra {
            if !specs.iter().any(|s| s.n == spec.n && s.footprint == spec.footprint) {
                specs.push(spec);
            }
        }
    }
    // (A footprint-sweep spec's error names its line in the sweep file.)
    let families = probe::bake_all(&specs).map_err(failure(file))?;
    Ok(vec![
        ("probe_tables.rs", probe::render(&specs, &families)),
        ("probe_size.rs", probe::render_size_trait(&specs)),
    ])
}

/// The footprint renderer's sets of the config `text` (read from `file`).
pub fn fp_files(file: &str, text: &str) -> Result<Files, Failure> {
    let (family, specs) = fp::parse(text).map_err(failure(file))?;
    let sets = fp::bake_all(&family, &specs).map_err(failure(file))?;
    Ok(vec![("footprint_tables.rs", fp::render(&family, &sets))])
}

/// Every file the crate's own tables bake (no user table, no feature sweep), in the order
/// `build.rs` writes them: what [`cache`] stores. `read` reads a file of the crate by its
/// path relative to the crate root.
pub fn default_files(read: Read) -> Result<Files, Failure> {
    let mut files = sg_files(sg::CONFIG_FILE, &read(sg::CONFIG_FILE)?)?;
    files.extend(bmc_files(bmc::CONFIG_FILE, &read(bmc::CONFIG_FILE)?)?);
    files.extend(glossy_files(glossy::CONFIG_FILE, &read(glossy::CONFIG_FILE)?, false, read)?);
    files.extend(probe_files(probe::CONFIG_FILE, &read(probe::CONFIG_FILE)?, false, read)?);
    files.extend(fp_files(fp::CONFIG_FILE, &read(fp::CONFIG_FILE)?)?);
    Ok(files)
}
