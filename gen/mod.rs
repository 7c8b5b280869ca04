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
pub mod glossy;
pub mod probe;
pub mod sg;
