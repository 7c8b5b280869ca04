//! What the accuracy and glossy benchmarks report (issue #13 item 4): BMC against the better
//! of its two same-sample peers map by map, the 2σ coverage of the luminance error bar, the
//! issue's targets with met or missed, and the CSV rows.
//!
//! For one (tier, query, N) and a set of maps, with `b` BMC's relative RMSE on a map and `p₁`,
//! `p₂` the peers':
//! - mean of per-map ratios: the mean over maps of `b / min(p₁, p₂)`, each map against its
//!   own better peer;
//! - ratio of means: `mean b / min(mean p₁, mean p₂)`, against the peer that is better on
//!   average;
//! - worst map: the largest per-map ratio, with the map's name.
//!
//! Coverage is pooled over the maps' queries (every map has as many).

use std::fmt::{self, Write as _};
use std::path::Path;

/// No map may be worse than this times its best same-sample peer (issue #13).
pub const WORST_LIMIT: f64 = 1.03;
/// The interval the 2σ coverage must lie in (issue #13), as fractions.
pub const COVERAGE_RANGE: (f64, f64) = (0.88, 0.99);

/// One map's figures for one (tier, query, N).
#[derive(Clone, Debug)]
pub struct MapRow {
    /// The map's name (file stem).
    pub map: String,
    /// Not one of the maps the probe's hyperparameters were trained on.
    pub held_out: bool,
    /// BMC's relative RMSE.
    pub bmc: f64,
    /// The two same-sample peers' relative RMSE.
    pub peers: [f64; 2],
    /// Queries within 2σ of BMC's estimate, for each of the two error bars.
    pub covered: [usize; 2],
    /// Queries.
    pub queries: usize,
}

impl MapRow {
    /// BMC over the better peer on this map.
    pub fn ratio(&self) -> f64 {
        self.bmc / self.peers[0].min(self.peers[1])
    }
}

/// One (tier, query, N): a row per map.
#[derive(Clone, Debug)]
pub struct Case {
    pub tier: String,
    pub query: String,
    pub n: usize,
    pub rows: Vec<MapRow>,
}

/// The statistics of one case over a set of maps.
#[derive(Clone, Debug)]
pub struct Summary {
    pub maps: usize,
    /// Mean relative RMSE of BMC and of the two peers.
    pub bmc: f64,
    pub peers: [f64; 2],
    pub mean_of_ratios: f64,
    pub ratio_of_means: f64,
    /// The largest per-map ratio and its map.
    pub worst: (f64, String),
    /// Pooled 2σ coverage of each error bar.
    pub coverage: [f64; 2],
}

/// Which maps a statistic is over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Maps {
    HeldOut,
    All,
}

impl Case {
    fn rows(&self, maps: Maps) -> impl Iterator<Item = &MapRow> {
        self.rows.iter().filter(move |r| maps == Maps::All || r.held_out)
    }

    /// The statistics over `maps`, or `None` if there are none.
    pub fn summary(&self, maps: Maps) -> Option<Summary> {
        let rows: Vec<&MapRow> = self.rows(maps).collect();
        if rows.is_empty() {
            return None;
        }
        let count = rows.len() as f64;
        let mean = |f: &dyn Fn(&MapRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / count;
        let bmc = mean(&|r| r.bmc);
        let peers = [mean(&|r| r.peers[0]), mean(&|r| r.peers[1])];
        let mut worst = (f64::NEG_INFINITY, String::new());
        for r in &rows {
            let v = r.ratio();
            if v > worst.0 || v.is_nan() {
                worst = (v, r.map.clone());
            }
        }
        let queries: usize = rows.iter().map(|r| r.queries).sum();
        let coverage = [0, 1].map(|b| {
            rows.iter().map(|r| r.covered[b]).sum::<usize>() as f64 / queries.max(1) as f64
        });
        Some(Summary {
            maps: rows.len(),
            bmc,
            peers,
            mean_of_ratios: mean(&|r| r.ratio()),
            ratio_of_means: bmc / peers[0].min(peers[1]),
            worst,
            coverage,
        })
    }
}

/// A relative error as a percentage with three significant digits.
pub fn pct(x: f64) -> String {
    if !x.is_finite() {
        return "n/a".into();
    }
    let p = 100.0 * x;
    if p >= 100.0 {
        format!("{p:.0}%")
    } else if p >= 10.0 {
        format!("{p:.1}%")
    } else if p >= 1.0 {
        format!("{p:.2}%")
    } else if p >= 0.1 {
        format!("{p:.3}%")
    } else {
        format!("{p:.2e}%")
    }
}

/// A ratio with three decimals.
pub fn ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "n/a".into()
    }
}

/// A coverage fraction as a percentage with one decimal.
pub fn coverage(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1}%", 100.0 * x)
    } else {
        "n/a".into()
    }
}

/// One table per (tier, query), in the order the cases come: a row per N and map set
/// (held-out maps, all maps) with the mean errors, the three statistics and the coverage of
/// the two error bars. `peers` and `bars` name the peers and the error bars.
pub fn comparison_tables(md: &mut String, cases: &[Case], peers: [&str; 2], bars: [&str; 2]) {
    let mut groups: Vec<(&str, &str)> = Vec::new();
    for c in cases {
        if !groups.contains(&(c.tier.as_str(), c.query.as_str())) {
            groups.push((&c.tier, &c.query));
        }
    }
    for (tier, query) in groups {
        let _ = writeln!(md, "### {tier}, {query}\n");
        let _ = writeln!(
            md,
            "| N | maps | BMC | {} | {} | mean of per-map ratios | ratio of means | worst map \
             | 2σ, {} | 2σ, {} |",
            peers[0], peers[1], bars[0], bars[1]
        );
        md.push_str("| ---: | --- | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: |\n");
        for c in cases.iter().filter(|c| c.tier == tier && c.query == query) {
            let held = c.rows(Maps::HeldOut).count();
            let subsets: &[Maps] =
                if held == c.rows.len() { &[Maps::All] } else { &[Maps::HeldOut, Maps::All] };
            for &maps in subsets {
                let label = match (maps, held == c.rows.len()) {
                    (Maps::HeldOut, _) => format!("held-out ({held})"),
                    (Maps::All, true) => format!("all ({}, held out)", c.rows.len()),
                    (Maps::All, false) => format!("all ({})", c.rows.len()),
                };
                let Some(s) = c.summary(maps) else {
                    let _ = writeln!(md, "| {} | {label} |{}", c.n, " n/a |".repeat(8));
                    continue;
                };
                let bold = if maps == Maps::HeldOut || held == c.rows.len() { "**" } else { "" };
                let _ = writeln!(
                    md,
                    "| {} | {label} | {} | {} | {} | {bold}{}{bold} | {} | {} ({}) | {} | {} |",
                    c.n,
                    pct(s.bmc),
                    pct(s.peers[0]),
                    pct(s.peers[1]),
                    ratio(s.mean_of_ratios),
                    ratio(s.ratio_of_means),
                    ratio(s.worst.0),
                    s.worst.1,
                    coverage(s.coverage[0]),
                    coverage(s.coverage[1]),
                );
            }
        }
        md.push('\n');
    }
}

/// One line of a "Targets" section.
#[derive(Clone, Debug)]
pub struct Target {
    pub statement: String,
    pub measured: String,
    /// `None` when it cannot be judged (no held-out maps).
    pub met: Option<bool>,
}

/// The "Targets" table: target, measured over the held-out maps, verdict.
pub fn targets_table(md: &mut String, targets: &[Target]) {
    md.push_str("| target | measured (held-out maps) | |\n| --- | --- | --- |\n");
    for t in targets {
        let verdict = match t.met {
            Some(true) => "met",
            Some(false) => "**missed**",
            None => "n/a",
        };
        let _ = writeln!(md, "| {} | {} | {verdict} |", t.statement, t.measured);
    }
    md.push('\n');
}

fn find<'a>(cases: &'a [Case], tier: &str, query: &str) -> impl Iterator<Item = &'a Case> {
    let (tier, query) = (tier.to_string(), query.to_string());
    cases.iter().filter(move |c| c.tier == tier && c.query == query)
}

/// Mean of per-map ratios over the held-out maps ≤ `limit` at each N of `ns`.
pub fn mean_ratio_target(
    cases: &[Case],
    tier: &str,
    query: &str,
    peers: &str,
    ns: &[usize],
    limit: f64,
) -> Target {
    let mut measured = Vec::new();
    let mut met = Some(true);
    for &n in ns {
        let s = find(cases, tier, query).find(|c| c.n == n).and_then(|c| c.summary(Maps::HeldOut));
        match s {
            Some(s) => {
                let ok = s.mean_of_ratios <= limit;
                let cell = format!("{} (N = {n})", ratio(s.mean_of_ratios));
                measured.push(if ok { cell } else { format!("**{cell}**") });
                met = met.map(|m| m && ok);
            }
            None => {
                measured.push(format!("n/a (N = {n})"));
                met = None;
            }
        }
    }
    let ns: Vec<String> = ns.iter().map(usize::to_string).collect();
    Target {
        statement: format!(
            "`{tier}` {query}: mean of per-map ratios BMC / min({peers}) ≤ {limit:.2} at N = {}",
            ns.join(", ")
        ),
        measured: measured.join(", "),
        met,
    }
}

/// No held-out map at any N worse than `WORST_LIMIT` × its best peer.
pub fn worst_target(cases: &[Case], tier: &str, query: &str, peers: &str) -> Target {
    let mut worst: Option<(f64, String, usize)> = None;
    let (mut over, mut total) = (Vec::new(), 0usize);
    for c in find(cases, tier, query) {
        for r in c.rows(Maps::HeldOut) {
            let v = r.ratio();
            total += 1;
            if v.is_nan() || v > WORST_LIMIT {
                over.push((v, format!("{} N = {} ({})", r.map, c.n, ratio(v))));
            }
            if worst.as_ref().is_none_or(|w| v > w.0 || v.is_nan()) {
                worst = Some((v, r.map.clone(), c.n));
            }
        }
    }
    let statement =
        format!("`{tier}` {query}: no map, no N worse than {WORST_LIMIT} × the better of {peers}");
    let Some(w) = worst else {
        return Target { statement, measured: "no held-out maps".into(), met: None };
    };
    let mut measured = format!(
        "worst {} ({}, N = {}); {} of {total} (map, N) above {WORST_LIMIT}",
        ratio(w.0),
        w.1,
        w.2,
        over.len()
    );
    // The largest first, at most five.
    over.sort_by(|a, b| b.0.total_cmp(&a.0));
    let shown: Vec<&str> = over.iter().take(5).map(|(_, s)| s.as_str()).collect();
    if !shown.is_empty() {
        let more = if over.len() > shown.len() { ", …" } else { "" };
        let _ = write!(measured, ": {}{more}", shown.join(", "));
    }
    Target { statement, measured, met: Some(over.is_empty()) }
}

/// The 2σ coverage of error bar `bar` over the held-out maps within `COVERAGE_RANGE` at every
/// N.
pub fn coverage_target(cases: &[Case], tier: &str, query: &str, bar: usize, name: &str) -> Target {
    let (lo, hi) = COVERAGE_RANGE;
    let mut measured = Vec::new();
    let mut met = Some(true);
    for c in find(cases, tier, query) {
        match c.summary(Maps::HeldOut) {
            Some(s) => {
                let v = s.coverage[bar];
                let ok = (lo..=hi).contains(&v);
                let cell = format!("{} (N = {})", coverage(v), c.n);
                measured.push(if ok { cell } else { format!("**{cell}**") });
                met = met.map(|m| m && ok);
            }
            None => met = None,
        }
    }
    Target {
        statement: format!(
            "`{tier}` {query}: 2σ coverage of the luminance bar ({name}) in [{:.0}%, {:.0}%] at \
             every N",
            100.0 * lo,
            100.0 * hi
        ),
        measured: if measured.is_empty() { "no held-out maps".into() } else { measured.join(", ") },
        met,
    }
}

/// The CSV header of both benchmarks.
pub const CSV_HEADER: &str = "benchmark,tier,query,n,estimator,map,rel_rmse,coverage";

/// One CSV row: `<benchmark>,<tier>,<query>,<n>,<estimator>,<map>,<rel_rmse>,<coverage>`,
/// coverage (a fraction) empty for an estimator without an error bar.
pub struct CsvRow<'a> {
    pub benchmark: &'a str,
    pub tier: &'a str,
    pub query: &'a str,
    pub n: usize,
    pub estimator: &'a str,
    pub map: &'a str,
    pub rel_rmse: f64,
    pub coverage: Option<f64>,
}

impl fmt::Display for CsvRow<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{},{},{},{},{},{},{:.6e},",
            self.benchmark, self.tier, self.query, self.n, self.estimator, self.map, self.rel_rmse
        )?;
        match self.coverage {
            Some(c) => write!(f, "{c:.6}"),
            None => Ok(()),
        }
    }
}

/// Writes `rows` (lines, without the header) to `path` under [`CSV_HEADER`], creating its
/// folder.
pub fn write_csv(path: &Path, rows: &str) -> std::io::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(path, format!("{CSV_HEADER}\n{rows}"))
}
