// Throughput of the package's probes in Node: updates and queries per second at N = 16, 64 and
// 256, against a plain JavaScript SH9 projection of the same samples, and the same modules built
// with simd128 (and at opt-level 3, with and without it) against the package's plain ones.
// Prints a Markdown report. Timings on a shared machine are noise for a test: CI does not run it.
//
//   examples/wasm/package/bench/build.sh      # the package's modules and the other builds
//   node examples/wasm/package/bench/throughput.mjs [--reps R] [--ms T] [--sizes 16,64,256]
//       [--variants simd128,o3,o3-simd128 | --no-variants] [--quick] [--out FILE] [--csv FILE]
//
// Each case runs a batch of calls that takes about T ms (default 200; the batch size is fixed
// by a warm-up), R times (default 9); the cases are interleaved within each repetition (plain
// wasm, simd128 wasm and JS side by side), so that a change of the machine's load hits all of
// them alike. A figure is the median of the R rates; a ratio is the ratio of two medians (the
// CSV rows `wasm-throughput,<what>,<n>,<build>,<per_second>` recompute it).
import { readFileSync, writeFileSync, existsSync } from "node:fs";
import { fileURLToPath } from "node:url";
import os from "node:os";
import { LayoutProbe, Probe, TemporalProbe } from "../index.js";

const usage = `usage: node throughput.mjs [--reps R] [--ms T] [--sizes 16,64,256] [--variants L | --no-variants] [--quick] [--out FILE] [--csv FILE]
  --reps R     repetitions per case, the median is reported (default 9)
  --ms T       milliseconds per timed batch (default 200)
  --sizes L    probe sizes N, comma-separated, from 16, 32, 64, 128, 256 (default 16,64,256)
  --variants L the other builds of the modules, from target/wasm-bench/<variant>/ at the repository
               root (bench/build.sh), comma-separated (default simd128,o3,o3-simd128)
  --no-variants  time the package's modules only
  --quick      a smoke check: 1 repetition of 5 ms batches (figures meaningless)
  --out FILE   also write the Markdown report to FILE
  --csv FILE   write rows wasm-throughput,<what>,<n>,<build>,<per_second> to FILE`;

// ------------------------------------------------------------------------------- options
const args = process.argv.slice(2);
const VARIANTS = ["simd128", "o3", "o3-simd128"];
const opt = { reps: 9, ms: 200, sizes: [16, 64, 256], variants: VARIANTS, out: null, csv: null, quick: false };
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  const value = () => {
    if (i + 1 >= args.length) fail(`${a} needs a value`);
    return args[++i];
  };
  if (a === "-h" || a === "--help") {
    console.log(usage);
    process.exit(0);
  } else if (a === "--reps") opt.reps = positiveInteger(value(), a);
  else if (a === "--ms") opt.ms = positiveInteger(value(), a);
  else if (a === "--sizes") opt.sizes = value().split(",").map((s) => positiveInteger(s, a));
  else if (a === "--variants") opt.variants = value().split(",");
  else if (a === "--no-variants") opt.variants = [];
  else if (a === "--quick") Object.assign(opt, { reps: 1, ms: 5, quick: true });
  else if (a === "--out") opt.out = value();
  else if (a === "--csv") opt.csv = value();
  else fail(`unknown option ${a}`);
}
for (const n of opt.sizes) if (![16, 32, 64, 128, 256].includes(n)) fail(`no probe of size ${n}`);
for (const v of opt.variants) if (!VARIANTS.includes(v)) fail(`no variant ${v} (variants ${VARIANTS.join(", ")})`);

function fail(message) {
  console.error(`throughput.mjs: ${message}\n${usage}`);
  process.exit(2);
}
function positiveInteger(s, what) {
  const v = Number(s);
  if (!Number.isInteger(v) || v <= 0) fail(`${what} needs a positive integer, not ${s}`);
  return v;
}

// ------------------------------------------------------------------------------- modules
const root = fileURLToPath(new URL("../../../../", import.meta.url));
const builds = ["plain", ...opt.variants];
const modules = {};
const bytes = { plain: {} };
const need = [...opt.sizes.map((n) => `probe-${n}.wasm`), ...(opt.sizes.includes(16) ? ["layout.wasm"] : [])];
for (const f of need) {
  const path = fileURLToPath(new URL(`../wasm/${f}`, import.meta.url));
  if (!existsSync(path)) fail(`wasm/${f} is missing: run examples/wasm/package/build.sh (or bench/build.sh)`);
  bytes.plain[f] = readFileSync(path).length;
}
for (const v of opt.variants) {
  const dir = `${root}target/wasm-bench/${v}`;
  const missing = need.filter((f) => !existsSync(`${dir}/${f}`));
  if (missing.length > 0) fail(`${dir} lacks ${missing.join(", ")}: run examples/wasm/package/bench/build.sh, or pass --no-variants`);
  modules[v] = {};
  bytes[v] = {};
  for (const f of need) {
    const b = readFileSync(`${dir}/${f}`);
    bytes[v][f] = b.length;
    modules[v][f] = await WebAssembly.compile(b);
  }
}
// The plain modules are the package's defaults (wasm/ beside index.js), as a user loads them.
const wasmOf = (build, file) => (build === "plain" ? undefined : modules[build][file]);

// ------------------------------------------------------------------------------- the field
// A smooth RGB radiance field (degree ≤ 2 in the direction), positive everywhere.
function radiance(x, y, z, out, k) {
  out[k] = 1 + 0.5 * z + 0.3 * x * x;
  out[k + 1] = 2 + 0.4 * y - 0.2 * x * z;
  out[k + 2] = 3 - 0.6 * x + 0.1 * z * z;
}
function samplesAt(dirs) {
  const ys = new Float32Array(dirs.length);
  for (let k = 0; k < dirs.length; k += 3) radiance(dirs[k], dirs[k + 1], dirs[k + 2], ys, k);
  return ys;
}
// 64 query normals, spread over the sphere (spherical Fibonacci), cycled through by the queries.
const normals = [];
for (let i = 0; i < 64; i++) {
  const z = 1 - (2 * i + 1) / 64, r = Math.sqrt(1 - z * z), phi = 2.399963229728653 * i;
  normals.push([r * Math.cos(phi), r * Math.sin(phi), z]);
}

// ------------------------------------------------------------------------------- plain JS SH9
// The baseline: N RGB samples projected onto the 9 real SH basis functions of degree ≤ 2 with
// equal weights 4π/N, and irradiance from the coefficients with the cosine lobe's gains π,
// 2π/3, π/4 (as three.js's LightProbeGenerator and SphericalHarmonics3 do, in plain JS).
const C0 = 0.28209479177387814, C1 = 0.4886025119029199, C2 = 1.0925484305920792;
const C20 = 0.31539156525252005, C22 = 0.5462742152960396;
/** Projects the samples `ys` (r, g, b × N) in `dirs` (x, y, z × N) into `sh` (Float64Array(27)). */
function projectSh9(dirs, ys, sh) {
  sh.fill(0);
  const n = dirs.length / 3, w = (4 * Math.PI) / n;
  for (let j = 0; j < n; j++) {
    const x = dirs[3 * j], y = dirs[3 * j + 1], z = dirs[3 * j + 2];
    const b0 = C0, b1 = C1 * y, b2 = C1 * z, b3 = C1 * x;
    const b4 = C2 * x * y, b5 = C2 * y * z, b6 = C20 * (3 * z * z - 1), b7 = C2 * x * z, b8 = C22 * (x * x - y * y);
    for (let c = 0; c < 3; c++) {
      const v = w * ys[3 * j + c];
      sh[c] += b0 * v; sh[3 + c] += b1 * v; sh[6 + c] += b2 * v; sh[9 + c] += b3 * v; sh[12 + c] += b4 * v;
      sh[15 + c] += b5 * v; sh[18 + c] += b6 * v; sh[21 + c] += b7 * v; sh[24 + c] += b8 * v;
    }
  }
  return sh;
}
const A0 = Math.PI, A1 = (2 * Math.PI) / 3, A2 = Math.PI / 4;
/** Irradiance about the unit normal (x, y, z) from the SH9 coefficients, RGB into `out`. */
function irradianceSh9(sh, x, y, z, out) {
  const b0 = A0 * C0, b1 = A1 * C1 * y, b2 = A1 * C1 * z, b3 = A1 * C1 * x;
  const b4 = A2 * C2 * x * y, b5 = A2 * C2 * y * z, b6 = A2 * C20 * (3 * z * z - 1), b7 = A2 * C2 * x * z, b8 = A2 * C22 * (x * x - y * y);
  for (let c = 0; c < 3; c++) {
    out[c] = b0 * sh[c] + b1 * sh[3 + c] + b2 * sh[6 + c] + b3 * sh[9 + c] + b4 * sh[12 + c] +
      b5 * sh[15 + c] + b6 * sh[18 + c] + b7 * sh[21 + c] + b8 * sh[24 + c];
  }
  return out;
}

// ------------------------------------------------------------------------------- the cases
// A case: { what, n, build, run(count) } where run makes `count` calls and returns a number
// that depends on their results (kept in `sink`, so no call can be optimised away).
let sink = 0;
const cases = [];
const agreement = [];
for (const n of opt.sizes) {
  for (const build of builds) {
    const probe = await Probe.create({ n, seed: 1, wasm: wasmOf(build, `probe-${n}.wasm`) });
    const ys = samplesAt(probe.directions());
    probe.update(ys);
    cases.push({ what: "probe-update", n, build, run(count) {
      for (let i = 0; i < count; i++) probe.update(ys);
      return 0;
    } });
    cases.push({ what: "probe-irradiance", n, build, run(count) {
      let s = 0;
      for (let i = 0; i < count; i++) s += probe.irradiance(normals[i & 63]).value[0];
      return s;
    } });
    cases.push({ what: "probe-radiance-sh", n, build, run(count) {
      let s = 0;
      for (let i = 0; i < count; i++) s += probe.radianceSh()[0];
      return s;
    } });
    // A temporal probe of static light: a constant per channel, so the samples do not depend
    // on the directions; each update asks for its directions and sentinels, as a user must.
    const temporal = await TemporalProbe.create({ n, seed: 1, wasm: wasmOf(build, `probe-${n}.wasm`) });
    const ts = Float32Array.from({ length: 3 * temporal.sampleCount }, (_, k) => 1 + (k % 3));
    const tr = Float32Array.from({ length: 3 * temporal.sentinelCount }, (_, k) => 1 + (k % 3));
    temporal.pool(ts, tr);
    cases.push({ what: "temporal-pool", n, build, run(count) {
      let s = 0;
      for (let i = 0; i < count; i++) {
        s += temporal.directions()[0] + temporal.sentinels()[0];
        temporal.pool(ts, tr);
      }
      return s;
    } });
    cases.push({ what: "temporal-irradiance", n, build, run(count) {
      let s = 0;
      for (let i = 0; i < count; i++) s += temporal.irradiance(normals[i & 63]).value[0];
      return s;
    } });
    if (build === "plain") {
      // The baseline on the same directions and samples as the Probe's.
      const dirs = probe.directions();
      const sh = new Float64Array(27), e = new Float64Array(3);
      cases.push({ what: "js-sh9-project", n, build: "js", run(count) {
        let s = 0;
        for (let i = 0; i < count; i++) s += projectSh9(dirs, ys, sh)[0];
        return s;
      } });
      cases.push({ what: "js-sh9-irradiance", n, build: "js", run(count) {
        let s = 0;
        for (let i = 0; i < count; i++) {
          const [x, y, z] = normals[i & 63];
          s += irradianceSh9(sh, x, y, z, e)[0];
        }
        return s;
      } });
      // Both compute the same quantity: their irradiance at the 64 normals, worst relative
      // difference (the Probe's BMC weights against the baseline's equal weights).
      projectSh9(dirs, ys, sh);
      let worst = 0;
      for (const [x, y, z] of normals) {
        const a = probe.irradiance([x, y, z]).value, b = irradianceSh9(sh, x, y, z, e);
        for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(a[c] - b[c]) / Math.abs(a[c]));
      }
      agreement.push({ n, worst });
    }
  }
}
if (opt.sizes.includes(16)) {
  // The layout probe of K = 16 sensors (its largest count) on a spherical Fibonacci layout.
  const dirs = new Float32Array(48);
  for (let i = 0; i < 16; i++) {
    const z = 1 - (2 * i + 1) / 16, r = Math.sqrt(1 - z * z), phi = 2.399963229728653 * i;
    dirs.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * i);
  }
  const ys = samplesAt(dirs);
  for (const build of builds) {
    const probe = await LayoutProbe.create({ directions: dirs, noise: { absolute: 0.01, relative: 0.02 }, wasm: wasmOf(build, "layout.wasm") });
    probe.update(ys);
    cases.push({ what: "layout-update", n: 16, build, run(count) {
      for (let i = 0; i < count; i++) probe.update(ys);
      return 0;
    } });
    cases.push({ what: "layout-irradiance", n: 16, build, run(count) {
      let s = 0;
      for (let i = 0; i < count; i++) s += probe.irradiance(normals[i & 63]).value[0];
      return s;
    } });
  }
}

// ------------------------------------------------------------------------------- timing
const now = () => performance.now();
// Warm-up and batch size: doubles the count until a batch takes a quarter of T, then scales;
// then runs the case for 2T more (V8 starts wasm and JS on baseline compilers and tiers hot
// functions up to optimised code in the background).
for (const c of cases) {
  let count = 1, t = 0;
  for (;;) {
    const t0 = now();
    sink += c.run(count);
    t = now() - t0;
    if (t >= opt.ms / 4 || count >= 1 << 28) break;
    count *= 2;
  }
  c.count = Math.max(1, Math.round((count * opt.ms) / Math.max(t, 1e-3)));
  c.rates = [];
  if (!opt.quick) for (let k = 0; k < 2; k++) sink += c.run(c.count);
}
const loadBefore = os.loadavg();
const started = now();
for (let r = 0; r < opt.reps; r++) {
  for (const c of cases) {
    const t0 = now();
    sink += c.run(c.count);
    c.rates.push(c.count / ((now() - t0) / 1000));
  }
}
const seconds = (now() - started) / 1000;
const loadAfter = os.loadavg();
if (!Number.isFinite(sink)) throw new Error("the sink is not finite");

const median = (v) => {
  const s = [...v].sort((a, b) => a - b), m = s.length >> 1;
  return s.length % 2 ? s[m] : (s[m - 1] + s[m]) / 2;
};
for (const c of cases) {
  c.median = median(c.rates);
  c.spread = (Math.max(...c.rates) - Math.min(...c.rates)) / c.median;
}
const find = (what, n, build) => cases.find((c) => c.what === what && c.n === n && c.build === build);
const rate = (what, n, build) => find(what, n, build)?.median;

// ------------------------------------------------------------------------------- report
/** Three significant digits with thin grouping: 1 230 000, 56 700, 812, 86.3. */
function perSecond(v) {
  if (v === undefined) return "—";
  const digits = Math.max(0, 2 - Math.floor(Math.log10(v)));
  const rounded = Number(v.toPrecision(3));
  return digits > 0 ? rounded.toFixed(digits) : Math.round(rounded).toString().replace(/\B(?=(\d{3})+(?!\d))/g, " ");
}
const times = (r) => `${r >= 0.995 ? r.toFixed(2) : r.toPrecision(2)}×`;
const ratio = (a, b) => (a === undefined || b === undefined ? "—" : times(a / b));
const pct = (v) => `${Math.round(100 * v)} %`;
const group = (v) => v.toString().replace(/\B(?=(\d{3})+(?!\d))/g, " ");
const lines = [];
const out = (s = "") => lines.push(s);
const arch = os.arch() === "x64" ? "x86-64" : os.arch();
const has = (b) => builds.includes(b);

out("# WebAssembly throughput in Node");
out();
if (opt.quick) {
  out("**A smoke check (`--quick`): one short repetition, the figures mean nothing.**");
  out();
}
out(`Calls per second of the JavaScript package's probes in Node (${os.cpus().length}-core ${arch}, Node ${process.version}):`);
out(`probe updates and queries at N = ${opt.sizes.join(", ")}, against a plain JavaScript SH9 projection of the`);
out("same samples" + (has("simd128") ? "; and the same modules built with `-C target-feature=+simd128`." : "."));
out();
out("## Method");
out();
out(`\`node examples/wasm/package/bench/throughput.mjs${args.length ? " " + args.join(" ") : ""}\`, after`);
out("`examples/wasm/package/bench/build.sh`. Each case is warmed up, then runs a batch of calls");
out(`that takes about ${opt.ms} ms, ${opt.reps} ${opt.reps === 1 ? "time" : "times"}, the cases interleaved within each repetition. A figure is`);
out("the median of the repetitions' rates (calls per second); a ratio is the ratio of two medians");
out("of the same run (`--csv` writes the medians).");
out(`Load average (1, 5, 15 min): ${loadBefore.map((v) => v.toFixed(2)).join(", ")} before the timed repetitions,`);
out(`${loadAfter.map((v) => v.toFixed(2)).join(", ")} after (${seconds.toFixed(0)} s).`);
out();
out("- **Updates:** `Probe.update(samples)` with the same 3N samples every call (a smooth RGB");
out("  field of degree ≤ 2 at the probe's directions, rotation seed 1); `TemporalProbe.pool`");
out("  (point samples) with its `directions()` and `sentinels()` calls, on static light (a constant");
out("  per channel);" + (opt.sizes.includes(16) ? " `LayoutProbe.update` of K = 16 sensors (its largest count; spherical Fibonacci" : ""));
if (opt.sizes.includes(16)) out("  directions, absolute and relative noise) in the K = 16 rows.");
out("- **Queries:** `irradiance(normal)` (value and variance) cycling through 64 normals spread over");
out("  the sphere; `Probe.radianceSh()` (the 27 SH coefficients).");
out("- **Plain JS SH9:** the same samples in the same directions projected onto the 9 real SH");
out("  basis functions of degree ≤ 2 with equal weights 4π/N (f64 accumulators), and irradiance");
out("  from the 9 coefficients with the cosine lobe's gains π, 2π/3, π/4 (value only, no variance).");
out("  Its irradiance at the 64 normals differs from the Probe's (Bayesian Monte Carlo weights) by at");
out("  most " + agreement.map(({ n, worst }) => `${(100 * worst).toFixed(2)} % at N = ${n}`).join(", ") + ": the same quantity.");
if (builds.length > 1) {
  out("- **Builds:** *plain*, the package's modules (`build.sh`: `opt-level = \"z\"`, fat LTO, one");
  out("  codegen unit, then `wasm-opt -Oz`); *simd128*, the same with");
  out("  `RUSTFLAGS=\"-C target-feature=+simd128\"`; *o3*, `opt-level = 3` and `wasm-opt -O3` (LLVM's");
  out("  loop and SLP vectorisers do not run at `\"z\"`); *o3-simd128*, both (`bench/build.sh`). All");
  out("  are timed through the same `index.js`.");
}
out("- *spread*: the largest (max − min)/median of the repetitions' rates over the row's cases.");
out();
out("## Updates per second");
out();
out("| N | `Probe.update` | `TemporalProbe.pool` | plain JS SH9 projection | `Probe.update` / JS | `pool` / JS | spread |");
out("| --- | --- | --- | --- | --- | --- | --- |");
const spreadOf = (...cs) => Math.max(...cs.filter((c) => c !== undefined).map((c) => c.spread));
for (const n of opt.sizes) {
  const u = rate("probe-update", n, "plain"), p = rate("temporal-pool", n, "plain"), j = rate("js-sh9-project", n, "js");
  const spread = spreadOf(find("probe-update", n, "plain"), find("temporal-pool", n, "plain"), find("js-sh9-project", n, "js"));
  out(`| ${n} | ${perSecond(u)} | ${perSecond(p)} | ${perSecond(j)} | ${ratio(u, j)} | ${ratio(p, j)} | ${pct(spread)} |`);
}
if (opt.sizes.includes(16)) {
  const u = rate("layout-update", 16, "plain"), j = rate("js-sh9-project", 16, "js");
  out(`| K = 16 | \`LayoutProbe.update\`: ${perSecond(u)} | | ${perSecond(j)} (N = 16) | ${ratio(u, j)} | | ${pct(spreadOf(find("layout-update", 16, "plain"), find("js-sh9-project", 16, "js")))} |`);
}
out();
out("## Queries per second");
out();
out("| N | `Probe.irradiance` | `TemporalProbe.irradiance` | `Probe.radianceSh` | plain JS SH9 irradiance | `Probe.irradiance` / JS | `TemporalProbe.irradiance` / JS | spread |");
out("| --- | --- | --- | --- | --- | --- | --- | --- |");
for (const n of opt.sizes) {
  const i = rate("probe-irradiance", n, "plain"), t = rate("temporal-irradiance", n, "plain"), s = rate("probe-radiance-sh", n, "plain"), j = rate("js-sh9-irradiance", n, "js");
  const spread = spreadOf(...["probe-irradiance", "temporal-irradiance", "probe-radiance-sh"].map((w) => find(w, n, "plain")), find("js-sh9-irradiance", n, "js"));
  out(`| ${n} | ${perSecond(i)} | ${perSecond(t)} | ${perSecond(s)} | ${perSecond(j)} | ${ratio(i, j)} | ${ratio(t, j)} | ${pct(spread)} |`);
}
if (opt.sizes.includes(16)) {
  const i = rate("layout-irradiance", 16, "plain"), j = rate("js-sh9-irradiance", 16, "js");
  out(`| K = 16 | \`LayoutProbe.irradiance\`: ${perSecond(i)} | | | ${perSecond(j)} (N = 16) | ${ratio(i, j)} | | ${pct(spreadOf(find("layout-irradiance", 16, "plain"), find("js-sh9-irradiance", 16, "js")))} |`);
}
const whats = ["probe-update", "temporal-pool", "layout-update", "probe-irradiance", "temporal-irradiance", "layout-irradiance", "probe-radiance-sh"];
const comparisons = [["simd128", "plain"], ["o3", "plain"], ["o3-simd128", "o3"], ["o3-simd128", "plain"]].filter(([a, b]) => has(a) && has(b));
if (comparisons.length > 0) {
  out();
  out("## simd128 and opt-level 3 against the package's build");
  out();
  out("Calls per second of each build, and ratios of two builds (above 1: the first is faster).");
  out();
  out(`| call | N | ${builds.join(" | ")} | ${comparisons.map(([a, b]) => `${a} / ${b}`).join(" | ")} | spread |`);
  out(`|${" --- |".repeat(3 + builds.length + comparisons.length)}`);
  const all = comparisons.map(() => []);
  for (const what of whats) {
    for (const n of opt.sizes) {
      if (find(what, n, "plain") === undefined) continue;
      const cells = builds.map((b) => perSecond(rate(what, n, b)));
      const rs = comparisons.map(([a, b], k) => {
        const r = rate(what, n, a) / rate(what, n, b);
        all[k].push(r);
        return times(r);
      });
      const spread = spreadOf(...builds.map((b) => find(what, n, b)));
      out(`| \`${what}\` | ${what.startsWith("layout") ? `K = ${n}` : n} | ${cells.join(" | ")} | ${rs.join(" | ")} | ${pct(spread)} |`);
    }
  }
  out();
  for (const [k, [a, b]] of comparisons.entries()) {
    const r = all[k], sorted = [...r].sort((x, y) => x - y);
    const faster = r.filter((x) => x > 1.1).length, slower = r.filter((x) => x < 1 / 1.1).length;
    out(`- ${a} / ${b} over these ${r.length} calls: median ${times(median(r))}, from ${times(sorted[0])} to ${times(sorted[sorted.length - 1])};`);
    out(`  more than 10 % faster in ${faster}, more than 10 % slower in ${slower}.`);
  }
  out();
  out("Module bytes:");
  out();
  out(`| build | ${need.map((f) => `\`${f}\``).join(" | ")} |`);
  out(`|${" --- |".repeat(1 + need.length)}`);
  for (const b of builds) out(`| ${b} | ${need.map((f) => group(bytes[b][f])).join(" | ")} |`);
}
const report = lines.join("\n") + "\n";
process.stdout.write(report);
if (opt.out) writeFileSync(opt.out, report);
if (opt.csv) {
  const rows = cases.map((c) => `wasm-throughput,${c.what},${c.n},${c.build},${Number(c.median.toPrecision(4))}`);
  writeFileSync(opt.csv, rows.join("\n") + "\n");
}
