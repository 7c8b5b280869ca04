// The Node test of the sphere-quadrature package, run from a consumer project that installed
// the packed tarball (test/run.sh): imports the package by its name, as a user would, and
// checks
// 1. the installed modules: all five sizes, no imports, only the package's exports, sizes
//    (N = 64 at most 100 KB, the issue's target);
// 2. every value against the host reference (eval/src/bin/js_package_reference.rs), bit for bit:
//    directions, irradiance and glossy with variances, SH coefficients and variances, for
//    every size and two rotations, and the errors of bad queries by name; and, for every size,
//    a stream of temporal updates (static light, a switch, a slight brightening) of a point
//    and of a footprint TemporalProbe: directions, what each `pool` did, the state (pooled
//    updates, change probability, evidence), irradiance with variance, SH and SH variances;
//    and layout probes (a cube of six sensors, a dome of five under the sky-above prior, the
//    cube under the other priors): an update and streams of pooled readings (static light,
//    then a switch), what each did, the state, irradiance with its averaged and exact
//    variances, Phong averages, SH coefficients, and the errors of refused layouts and
//    readings;
// 3. the physics on fields with known answers (constant radiance: irradiance π·L, glossy L,
//    SH c₀₀ = √(4π)·L; a linear field: irradiance π·(a + b·n_z·2/3)), independent of Rust;
//    the temporal probe's irradiance of a constant and a linear field, point and footprint;
//    the layout probe's answers for a constant field;
// 4. the JS side: exceptions (type, code, message) for every kind of bad input, kept data
//    after a refused update, independent probes, dispose, the `wasm` option, the method names
//    of the crate's vocabulary (`update` replaces, `pool` pools, `pooledUpdates`).
//
//   node test.mjs REFERENCE
import { readFileSync, statSync } from "node:fs";
import { createRequire } from "node:module";
import { LAYOUT_SIZES, LayoutProbe, Probe, ProbeError, SIZES, TemporalProbe } from "sphere-quadrature";

let failures = 0;
let checks = 0;
function ok(cond, what) {
  checks++;
  if (!cond) {
    failures++;
    console.log(`FAIL: ${what}`);
  }
}
/** `fn` throws ProbeError `code`; its message starts with `prefix` (the method) if given. */
function throws(fn, code, what, prefix) {
  try {
    fn();
  } catch (e) {
    ok(e instanceof ProbeError && e instanceof Error && e.code === code && e.name === "ProbeError" && e.message.length > 0 &&
      (prefix === undefined || e.message.startsWith(`${prefix}: `)),
      `${what}: expected ProbeError ${code}${prefix === undefined ? "" : ` from ${prefix}`}, got ${e?.name} ${e?.code}: ${e?.message}`);
    return;
  }
  ok(false, `${what}: expected ProbeError ${code}, nothing thrown`);
}
async function rejects(promise, code, what) {
  try {
    await promise;
  } catch (e) {
    ok(e instanceof ProbeError && e.code === code, `${what}: expected ProbeError ${code}, got ${e?.name} ${e?.code}: ${e?.message}`);
    return;
  }
  ok(false, `${what}: expected ProbeError ${code}, nothing thrown`);
}

// 1. The installed package and its modules.
// Resolved as Node resolves the package (its "exports" map), from this consumer project.
const resolve = createRequire(import.meta.url).resolve;
const entry = resolve("sphere-quadrature");
ok(entry.includes(`node_modules/sphere-quadrature/`), `the package resolves into node_modules: ${entry}`);
ok(JSON.stringify(SIZES) === "[16,32,64,128,256]", `SIZES ${SIZES}`);
const EXPORTS = [
  "io_len", "io_ptr", "memory", "probe_directions", "probe_free", "probe_glossy", "probe_irradiance", "probe_new",
  "probe_radiance_sh", "probe_radiance_sh_variance", "probe_size", "probe_three_js_sh",
  "probe_update", "temporal_directions", "temporal_free", "temporal_irradiance", "temporal_new", "temporal_pool",
  "temporal_radiance_sh", "temporal_radiance_sh_variance", "temporal_sentinel_count", "temporal_sentinels",
  "temporal_sharpness", "temporal_state", "temporal_three_js_sh",
];
const bytesOf = {};
for (const n of SIZES) {
  const file = resolve(`sphere-quadrature/wasm/probe-${n}.wasm`);
  const bytes = readFileSync(file);
  bytesOf[n] = bytes;
  const module = new WebAssembly.Module(bytes);
  const imports = WebAssembly.Module.imports(module);
  ok(imports.length === 0, `probe-${n}.wasm has ${imports.length} imports: ${JSON.stringify(imports)}`);
  // Functions and the memory: exactly the package's (the linker's __heap_base/__data_end
  // globals aside).
  const exported = WebAssembly.Module.exports(module).filter((e) => e.kind !== "global").map((e) => e.name).sort();
  ok(JSON.stringify(exported) === JSON.stringify(EXPORTS), `probe-${n}.wasm exports ${exported.join(", ")}`);
  console.log(`probe-${n}.wasm: ${statSync(file).size} bytes, ${imports.length} imports, ${exported.length} exports`);
}
ok(bytesOf[64].length <= 100 * 1024, `probe-64.wasm is ${bytesOf[64].length} bytes, above the 100 KB target`);
ok(JSON.stringify(LAYOUT_SIZES) === "[4,5,6,7,8,12,16]", `LAYOUT_SIZES ${LAYOUT_SIZES}`);
const LAYOUT_EXPORTS = [
  "io_len", "io_ptr", "layout_capacities", "layout_directions", "layout_free", "layout_irradiance",
  "layout_irradiance_variance", "layout_new", "layout_phong", "layout_pool", "layout_radiance_sh", "layout_state",
  "layout_update", "memory",
];
const layoutFile = resolve("sphere-quadrature/wasm/layout.wasm");
const layoutBytes = readFileSync(layoutFile);
{
  const module = new WebAssembly.Module(layoutBytes);
  const imports = WebAssembly.Module.imports(module);
  ok(imports.length === 0, `layout.wasm has ${imports.length} imports: ${JSON.stringify(imports)}`);
  const exported = WebAssembly.Module.exports(module).filter((e) => e.kind !== "global").map((e) => e.name).sort();
  ok(JSON.stringify(exported) === JSON.stringify(LAYOUT_EXPORTS), `layout.wasm exports ${exported.join(", ")}`);
  console.log(`layout.wasm: ${layoutBytes.length} bytes, ${imports.length} imports, ${exported.length} exports`);
}

// 2. Against the host reference, bit for bit.
const refPath = process.argv[2];
if (!refPath) throw new Error("usage: node test.mjs REFERENCE (cargo eval js_package_reference)");
const reference = readFileSync(refPath, "utf8").split("\n").filter((l) => l.length > 0);
const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);
const bits = (v) => {
  f32[0] = v;
  return u32[0].toString(16).padStart(8, "0");
};
const fromBits = (h) => {
  u32[0] = parseInt(h, 16);
  return f32[0];
};
const QUERIES = [
  [0, 0, 1], [0, 0, -1], [1, 0, 0], [0.5, -0.25, 0.75], [-1.5, 2, 0.5], [0.125, 0.5, -1], [3, 3, 3], [-0.25, -0.75, 0],
];
const EXPONENTS = [0, 1, 5, 20, 100, 7.5, 50, 2];
const SEEDS = [0, 7];
const samplesOf = new Map();
for (const l of reference) {
  const [key, n, seed, , v] = l.split(" ");
  if (key !== "sample") continue;
  const k = `${n} ${seed}`;
  if (!samplesOf.has(k)) samplesOf.set(k, []);
  samplesOf.get(k).push(fromBits(v));
}
const lines = [];
for (const n of SIZES) {
  for (const seed of SEEDS) {
    const values = (key, vs) => Array.from(vs).forEach((v, i) => lines.push(`${key} ${n} ${seed} ${i} ${bits(v)}`));
    const error = (key, i, fn) => {
      let what = "ok";
      try {
        fn();
      } catch (e) {
        if (!(e instanceof ProbeError)) throw e;
        what = e.code;
      }
      lines.push(`${key} ${n} ${seed} ${i} ${what}`);
    };
    const p = await Probe.create({ n, seed });
    ok(p.n === n && p.seed === seed, `n ${p.n}, seed ${p.seed}`);
    values("dir", p.directions());
    const ys = Float32Array.from(samplesOf.get(`${n} ${seed}`) ?? []);
    values("sample", ys);
    const fresh = p.irradiance([0, 0, 1]);
    values("fresh", [...fresh.value, ...fresh.variance]);
    values("fresh_sh", p.radianceSh());
    error("update", 0, () => p.update(ys));
    QUERIES.forEach((q, i) => {
      const irr = p.irradiance(q);
      values(`irr${i}`, [...irr.value, ...irr.variance]);
      error("irr_ok", i, () => p.irradiance(q));
      const g = p.glossy(q, EXPONENTS[i]);
      values(`glossy${i}`, [...g.value, ...g.variance]);
      error("glossy_ok", i, () => p.glossy(q, EXPONENTS[i]));
    });
    values("sh", p.radianceSh());
    values("shvar", p.radianceShVariance());
    const bad = ys.slice();
    bad[3 * (n / 2) + 1] = NaN;
    error("err_update", 0, () => p.update(bad));
    bad[3 * (n / 2) + 1] = Infinity;
    error("err_update", 1, () => p.update(bad));
    values("sh_after_err", p.radianceSh());
    error("err_irr", 0, () => p.irradiance([0, 0, 0]));
    error("err_irr", 1, () => p.irradiance([NaN, 0, 1]));
    error("err_irr", 2, () => p.irradiance([Infinity, 0, 0]));
    error("err_glossy", 0, () => p.glossy([0, 0, 1], -1));
    error("err_glossy", 1, () => p.glossy([0, 0, 1], NaN));
    error("err_glossy", 2, () => p.glossy([0, 0, 1], Infinity));
    error("err_glossy", 3, () => p.glossy([0, 0, 0], 20));
    p.dispose();
  }
}
// The temporal streams (eval/src/bin/js_package_reference.rs, `temporal_stream`): per size a
// point probe (seed 5, the default hazard) and a footprint probe (seed 11, hazard 1/256), fed
// the host's samples and sentinel readings of each update.
const STREAMS = [
  { name: "point", seed: 5, footprint: "point", hazard: undefined },
  { name: "gaussian", seed: 11, footprint: "gaussian", hazard: 1 / 256 },
];
/** Updates per light: static, a switch, the switched light 3 % brighter. */
const PHASES = [12, 8, 6];
const TEMPORAL_NORMALS = [[0, 0, 1], [1, 0, 0], [-0.5, 0.75, -0.25], [0.125, -1, 0.5]];
const inputs = new Map();
for (const l of reference) {
  const [key, n, at, , v] = l.split(" ");
  if (key !== "t_sample" && key !== "t_reading") continue;
  const k = `${key} ${n} ${at}`;
  if (!inputs.has(k)) inputs.set(k, []);
  inputs.get(k).push(fromBits(v));
}
const changes = [];
for (const n of SIZES) {
  for (const { name, seed, footprint, hazard } of STREAMS) {
    const t = await TemporalProbe.create({ n, seed, footprint, ...(hazard === undefined ? {} : { hazard }) });
    ok(t.n === n && t.seed === seed && t.footprint === footprint && t.sampleCount + t.sentinelCount === n,
      `temporal ${n} ${name}: n ${t.n}, seed ${t.seed}, footprint ${t.footprint}, ${t.sampleCount} + ${t.sentinelCount}`);
    ok(t.sharpness === (footprint === "gaussian" ? n / 8 : 0), `temporal ${n} ${name}: sharpness ${t.sharpness}`);
    const at = (u) => `${n} ${name}.${u}`;
    const values = (key, u, vs) => Array.from(vs).forEach((v, i) => lines.push(`t_${key} ${at(u)} ${i} ${bits(v)}`));
    const irradiance = (u) => TEMPORAL_NORMALS.forEach((q, i) => {
      const e = t.irradiance(q);
      values(`irr${i}`, u, [...e.value, ...e.variance]);
    });
    // Updates and degree as integers, then pooled updates, change probability, evidence.
    const state = (key, u) => {
      lines.push(`t_${key} ${at(u)} 0 ${t.updates}`, `t_${key} ${at(u)} 1 ${t.degree}`);
      const { rotated, sentinels } = t.lastEvidence;
      [t.pooledUpdates, t.lastChangeProbability, rotated, sentinels]
        .forEach((v, i) => lines.push(`t_${key} ${at(u)} ${i + 2} ${bits(v)}`));
    };
    const refused = (f) => {
      try {
        f();
      } catch (e) {
        if (!(e instanceof ProbeError)) throw e;
        return `Some(${e.code})`;
      }
      return "None";
    };
    values("sentinel_dir", 0, t.sentinels());
    irradiance(0);
    values("fresh_sh", 0, t.radianceSh());
    let u = 0;
    for (const count of PHASES) {
      for (let k = 0; k < count; k++) {
        u++;
        values("dir", u, t.directions());
        const ys = Float32Array.from(inputs.get(`t_sample ${at(u)}`) ?? []);
        const ss = Float32Array.from(inputs.get(`t_reading ${at(u)}`) ?? []);
        values("sample", u, ys);
        values("reading", u, ss);
        let change;
        try {
          change = t.pool(ys, ss);
        } catch (e) {
          if (!(e instanceof ProbeError)) throw e;
          change = e.code;
        }
        lines.push(`t_change ${at(u)} 0 ${change}`);
        changes.push({ n, name, u, change });
        state("state", u);
        irradiance(u);
        if (k + 1 === count) {
          values("sh", u, t.radianceSh());
          values("shvar", u, t.radianceShVariance());
        }
      }
    }
    // A refused update keeps the state and the directions.
    const before = t.directions();
    const ys = Float32Array.from(inputs.get(`t_sample ${at(u)}`) ?? []);
    const ss = Float32Array.from(inputs.get(`t_reading ${at(u)}`) ?? []);
    const bad = ys.slice();
    bad[3 * Math.floor(t.sampleCount / 2) + 1] = NaN;
    lines.push(`t_err ${at(u)} 0 ${refused(() => t.pool(bad, ss))}`);
    const badSentinels = ss.slice();
    badSentinels[3 * (t.sentinelCount - 1) + 2] = Infinity;
    lines.push(`t_err ${at(u)} 1 ${refused(() => t.pool(ys, badSentinels))}`);
    const after = t.directions();
    lines.push(`t_err ${at(u)} 2 ${before.every((v, i) => v === after[i])}`);
    state("state_after_err", u);
    lines.push(`t_err ${at(u)} 3 ${refused(() => t.irradiance([0, 0, 0]))}`);
    lines.push(`t_err ${at(u)} 4 ${refused(() => t.irradiance([0, NaN, 1]))}`);
    t.dispose();
  }
}
// The streams must hold what they are meant to compare: every update, a reset within two
// updates of the switch (a change the sentinels see counts once their next reading confirms
// it) and none on the static light before it.
const updatesPerStream = PHASES.reduce((a, b) => a + b, 0);
ok(changes.length === SIZES.length * STREAMS.length * updatesPerStream, `${changes.length} temporal updates`);
ok(reference.filter((l) => l.startsWith("t_change ")).length === changes.length,
  `the reference has ${reference.filter((l) => l.startsWith("t_change ")).length} temporal updates, the package ${changes.length}`);
for (const n of SIZES) {
  for (const { name } of STREAMS) {
    const c = changes.filter((x) => x.n === n && x.name === name);
    ok(c[0]?.change === "first" && c.slice(1, PHASES[0]).every((x) => x.change === "blended"),
      `temporal ${n} ${name}: static light ${c.slice(0, PHASES[0]).map((x) => x.change).join(" ")}`);
    const atSwitch = c.slice(PHASES[0], PHASES[0] + 2).map((x) => x?.change);
    ok(atSwitch.includes("reset"), `temporal ${n} ${name}: the switch gave ${atSwitch.join(" ")}`);
  }
}

// The layout probes (eval/src/bin/js_package_reference.rs, `layouts`): the host's sensors
// and readings, fed to LayoutProbes of the package.
/** Fewer layout lines in the reference mean that it lost some of what it is meant to hold. */
const LAYOUT_MIN_LINES = 3000;
const LAYOUT_NORMALS = [[0, 0, 1], [1, 0, 0], [-0.5, 0.75, -0.25], [0.125, -1, 0.5], [0, 0, -1]];
const LAYOUT_PHONG = [[[0, 0, 1], 20], [[1, 0.5, 0.25], 5], [[-0.25, -1, 0.5], 1], [[0, 0, -1], 0]];
/** Accumulations of a stream: of the first light, then of the second. */
const LAYOUT_STREAM = [6, 4];
const CUBE_NOISE = { absolute: 1 / 64, relative: 1 / 32 };
const LAYOUT_CASES = [
  { name: "cube6", prior: "environment", noise: CUBE_NOISE, hazard: undefined, stream: true },
  { name: "dome5", prior: "sky-above", noise: { absolute: 3 / 128, relative: 0 }, hazard: 1 / 32, stream: true },
  { name: "cube6-smooth-environment", prior: "smooth-environment", noise: CUBE_NOISE, hazard: 1 / 64, stream: false },
  { name: "cube6-smooth-sky-above", prior: "smooth-sky-above", noise: CUBE_NOISE, hazard: 1 / 64, stream: false },
  { name: "cube6-se4", prior: { squaredExponential: 4 }, noise: CUBE_NOISE, hazard: 1 / 64, stream: false },
];
const layoutInputs = new Map();
for (const l of reference) {
  const [key, at, , v] = l.split(" ");
  if (key !== "l_sensor" && key !== "l_reading") continue;
  const k = `${key} ${at}`;
  if (!layoutInputs.has(k)) layoutInputs.set(k, []);
  layoutInputs.get(k).push(fromBits(v));
}
const layoutInput = (key, name, step) => Float32Array.from(layoutInputs.get(`l_${key} ${name}.${step}`) ?? []);
/** `None` or `Some(code)` of `f`, as the host prints `Option<Error>`. */
const refusal = (f) => {
  try {
    f();
  } catch (e) {
    if (!(e instanceof ProbeError)) throw e;
    return `Some(${e.code})`;
  }
  return "None";
};
const refusalAsync = async (promise) => {
  try {
    (await promise).dispose();
  } catch (e) {
    if (!(e instanceof ProbeError)) throw e;
    return `Some(${e.code})`;
  }
  return "None";
};
const layoutChanges = [];
for (const { name, prior, noise, hazard, stream } of LAYOUT_CASES) {
  const out = (key, step, vs) => Array.from(vs).forEach((v, i) => lines.push(`l_${key} ${name}.${step} ${i} ${bits(v)}`));
  const [directions, powers, noiseScales] = [0, 1, 2].map((i) => layoutInput("sensor", name, i));
  [directions, powers, noiseScales].forEach((v, i) => out("sensor", i, v));
  let p;
  try {
    p = await LayoutProbe.create({ directions, powers, noiseScales, noise, prior, ...(hazard === undefined ? {} : { hazard }) });
    lines.push(`l_new ${name}.0 0 ok`);
  } catch (e) {
    if (!(e instanceof ProbeError)) throw e;
    lines.push(`l_new ${name}.0 0 ${e.code}`);
    continue;
  }
  ok(p.k === directions.length / 3 && p.hazard === (hazard ?? 1 / 64), `layout ${name}: k ${p.k}, hazard ${p.hazard}`);
  out("dir", 0, p.directions());
  const state = (step) => {
    lines.push(`l_state ${name}.${step} 0 ${p.k}`, `l_state ${name}.${step} 1 ${p.updated}`);
    out("state", step, [p.pooledUpdates, p.lastChangeProbability, ...p.signalVariance]);
  };
  const queries = (step) => LAYOUT_NORMALS.forEach((q, i) => {
    const e = p.irradiance(q);
    out(`irr${i}`, step, [...e.value, ...e.variance]);
    out(`irrvar${i}`, step, p.irradianceVariance(q));
  });
  const lobes = (step) => {
    LAYOUT_PHONG.forEach(([axis, e], i) => {
      const est = p.phong(axis, e);
      out(`phong${i}`, step, [...est.value, ...est.variance]);
    });
    out("sh", step, p.radianceSh());
  };
  state(0);
  queries(0);
  out("sh", 0, p.radianceSh());
  const first = layoutInput("reading", name, 1);
  out("reading", 1, first);
  lines.push(`l_update ${name}.1 0 ${refusal(() => p.update(first))}`);
  state(1);
  queries(1);
  lobes(1);
  let step = 1;
  if (stream) {
    for (const count of LAYOUT_STREAM) {
      for (let k = 0; k < count; k++) {
        step++;
        const readings = layoutInput("reading", name, step);
        out("reading", step, readings);
        let change;
        try {
          change = p.pool(readings);
        } catch (e) {
          if (!(e instanceof ProbeError)) throw e;
          change = e.code;
        }
        lines.push(`l_change ${name}.${step} 0 ${change}`);
        layoutChanges.push({ name, step, change });
        state(step);
        queries(step);
        if (k + 1 === count) lobes(step);
      }
    }
  }
  // Refused readings keep the state (one reading NaN, then infinite).
  const bad = Float32Array.from(first);
  bad[3 * Math.floor(p.k / 2) + 1] = NaN;
  lines.push(`l_err ${name}.${step} 0 ${refusal(() => p.update(bad))}`);
  bad[3 * Math.floor(p.k / 2) + 1] = Infinity;
  lines.push(`l_err ${name}.${step} 1 ${refusal(() => p.pool(bad))}`);
  state(step + 1);
  queries(step + 1);
  lines.push(`l_err ${name}.${step} 2 ${refusal(() => p.irradiance([0, 0, 0]))}`);
  lines.push(`l_err ${name}.${step} 3 ${refusal(() => p.irradianceVariance([NaN, 0, 1]))}`);
  lines.push(`l_err ${name}.${step} 4 ${refusal(() => p.phong([0, 0, 1], -1))}`);
  lines.push(`l_err ${name}.${step} 5 ${refusal(() => p.phong([0, 0, 0], 2))}`);
  p.dispose();
}
// Refused layouts, as the host refuses them.
{
  const directions = layoutInput("sensor", "cube6", 0);
  const powers = layoutInput("sensor", "cube6", 1);
  const noiseScales = layoutInput("sensor", "cube6", 2);
  const create = (options) => LayoutProbe.create({ directions, powers, noiseScales, noise: CUBE_NOISE, prior: "environment", ...options });
  const zero = Float32Array.from(directions);
  zero.fill(0, 6, 9);
  lines.push(`l_bad zero 0 ${await refusalAsync(create({ directions: zero }))}`);
  const many = new Float32Array(3 * 65).map((_, i) => (i % 3 === 2 ? 1 : 0));
  lines.push(`l_bad k65 0 ${await refusalAsync(create({ directions: many, powers: undefined, noiseScales: undefined }))}`);
  lines.push(`l_bad responses 0 ${await refusalAsync(create({ powers: [1, 2, 3, 4, 5, 6] }))}`);
  lines.push(`l_bad noise 0 ${await refusalAsync(create({ noise: { absolute: -1, relative: 0 } }))}`);
  lines.push(`l_bad lambda 0 ${await refusalAsync(create({ prior: { squaredExponential: 0 } }))}`);
  lines.push(`l_bad hazard 0 ${await refusalAsync(create({ hazard: 1 }))}`);
  const scale = Float32Array.from(noiseScales);
  scale[0] = 0;
  lines.push(`l_bad scale 0 ${await refusalAsync(create({ noiseScales: scale }))}`);
}
// The streams must hold what they are meant to compare: blended static light, a reset at
// the switch.
ok(layoutChanges.length === 2 * LAYOUT_STREAM.reduce((a, b) => a + b, 0), `${layoutChanges.length} layout pool calls`);
ok(reference.filter((l) => l.startsWith("l_change ")).length === layoutChanges.length,
  `the reference has ${reference.filter((l) => l.startsWith("l_change ")).length} layout pool calls, the package ${layoutChanges.length}`);
for (const name of ["cube6", "dome5"]) {
  const c = layoutChanges.filter((x) => x.name === name).map((x) => x.change);
  const [a, b] = LAYOUT_STREAM;
  ok(c.slice(0, a).every((x) => x === "blended") && c[a] === "reset" && c.slice(a + 1).every((x) => x === "blended"),
    `layout ${name}: the stream gave ${c.join(" ")}`);
}

let differing = 0;
for (let i = 0; i < Math.max(lines.length, reference.length); i++) {
  if (lines[i] !== reference[i]) {
    if (differing < 5) console.log(`line ${i + 1}: package "${lines[i]}", host "${reference[i]}"`);
    differing++;
  }
}
const temporalLines = reference.filter((l) => l.startsWith("t_")).length;
const layoutLines = reference.filter((l) => l.startsWith("l_")).length;
ok(reference.length > 8000 && temporalLines > 100000 && layoutLines > LAYOUT_MIN_LINES && differing === 0,
  `${differing} of ${reference.length} reference lines differ (package printed ${lines.length}; ${temporalLines} temporal, ` +
  `${layoutLines} layout)`);
if (differing === 0) {
  console.log(`${lines.length} lines (every size, seeds ${SEEDS.join(" and ")}; ${temporalLines} of them from ` +
    `${changes.length} temporal updates, point and footprint; ${layoutLines} from ${LAYOUT_CASES.length} layout probes ` +
    `and ${layoutChanges.length} pool calls) identical to the host reference`);
}

// 3. Fields with known answers.
const rel = (a, b) => Math.abs(a - b) / Math.abs(b);
/**
 * E(n) = Σ Â_l·c_lm·Y_lm(n) (Â = π, 2π/3, π/4; the basis of the crate's sh.rs, full-precision
 * constants), channel `c` of 27 floats, unit `n`.
 */
function shIrradiance(sh, n, c) {
  const [x, y, z] = n;
  const k = (i) => sh[3 * i + c];
  const y0 = 0.5 * Math.sqrt(1 / Math.PI), y1 = 0.5 * Math.sqrt(3 / Math.PI), y2 = 0.5 * Math.sqrt(15 / Math.PI);
  const y20 = 0.25 * Math.sqrt(5 / Math.PI), y22 = 0.25 * Math.sqrt(15 / Math.PI);
  return Math.PI * k(0) * y0 + (2 * Math.PI / 3) * y1 * (k(1) * y + k(2) * z + k(3) * x) +
    (Math.PI / 4) * (y2 * (k(4) * x * y + k(5) * y * z + k(7) * x * z) + y20 * k(6) * (3 * z * z - 1) + y22 * k(8) * (x * x - y * y));
}
/** three.js's `shGetIrradianceAt` (lights_pars_begin.glsl.js), channel `c` of 27 floats, unit `n`. */
function threeIrradiance(sh, n, c) {
  const [x, y, z] = n;
  const k = (i) => sh[3 * i + c];
  return k(0) * 0.886227 + k(1) * 2 * 0.511664 * y + k(2) * 2 * 0.511664 * z + k(3) * 2 * 0.511664 * x +
    k(4) * 2 * 0.429043 * x * y + k(5) * 2 * 0.429043 * y * z + k(6) * (0.743125 * z * z - 0.247708) +
    k(7) * 2 * 0.429043 * x * z + k(8) * 0.429043 * (x * x - y * y);
}
for (const n of SIZES) {
  const p = await Probe.create({ n, seed: 3 });
  const d = p.directions();
  const L = [0.5, 2, 7];
  p.update(Float32Array.from({ length: 3 * n }, (_, k) => L[k % 3]));
  const normal = [0.3, -0.4, 0.5];
  const irr = p.irradiance(normal);
  const gl = p.glossy([-1, 0.25, 0], 30);
  const sh = p.radianceSh();
  for (let c = 0; c < 3; c++) {
    ok(rel(irr.value[c], Math.PI * L[c]) < 1e-5, `N = ${n}, constant ${L[c]}: irradiance ${irr.value[c]}, expected π·L`);
    ok(rel(gl.value[c], L[c]) < 1e-5, `N = ${n}, constant: glossy ${gl.value[c]}, expected ${L[c]}`);
    ok(rel(sh[c], Math.sqrt(4 * Math.PI) * L[c]) < 1e-5, `N = ${n}, constant: c00 ${sh[c]}, expected √(4π)·L`);
    for (let k = 1; k < 9; k++) ok(Math.abs(sh[3 * k + c]) < 1e-5 * L[c], `N = ${n}, constant: c${k} = ${sh[3 * k + c]}`);
    ok(irr.variance[c] >= 0 && irr.variance[c] < 1e-6 * L[c] ** 2, `N = ${n}, constant: variance ${irr.variance[c]}`);
  }
  // L(x) = a + b·z (per channel): E(n) = π·(a + b·n_z·2/3) for a unit n; the model's
  // smoothing of the linear term leaves a small bias (0.1 % at N = 64).
  const a = [1, 2, 0.5], b = [0.5, -1, 0.25];
  p.update(Float32Array.from({ length: 3 * n }, (_, k) => a[k % 3] + b[k % 3] * d[3 * Math.floor(k / 3) + 2]));
  const u = Math.hypot(...normal);
  const lin = p.irradiance(normal);
  const tol = n <= 32 ? 1e-2 : 3e-3;
  for (let c = 0; c < 3; c++) {
    const want = Math.PI * (a[c] + (b[c] * normal[2] * 2) / (3 * u));
    ok(rel(lin.value[c], want) < tol, `N = ${n}, linear: irradiance ${lin.value[c]}, expected ${want}`);
    ok(lin.variance[c] > 0, `N = ${n}, linear: variance ${lin.variance[c]} not positive`);
  }
  const shv = p.radianceShVariance();
  ok(shv.length === 27 && shv.every((v) => v >= 0 && Number.isFinite(v)), `N = ${n}: SH variances ${shv}`);
  // The three.js export: three.js's shader formula (shGetIrradianceAt,
  // lights_pars_begin.glsl.js, its 6-digit constants) at the y-up image (x, z, −y) of a z-up
  // normal gives, for "z-up", the irradiance of radianceSh() at that normal (Ramamoorthi and
  // Hanrahan's E(n) = Σ Â_l·c_lm·Y_lm(n), the crate's ShL2::irradiance) and so the linear
  // field's; for "y-up" (the coefficients unchanged) at the normal itself. The light varies
  // along z, so handing over unrotated coefficients moves it: that check can fail.
  const shLin = p.radianceSh();
  const zUp = p.threeJsSh("z-up");
  const yUp = p.threeJsSh("y-up");
  ok(yUp.length === 27 && yUp.every((v, k) => v === shLin[k]), `N = ${n}: threeJsSh("y-up") is radianceSh() unchanged`);
  const unit = normal.map((v) => v / u);
  const m = [unit[0], unit[2], -unit[1]];
  for (let c = 0; c < 3; c++) {
    const want = Math.PI * (a[c] + (b[c] * normal[2] * 2) / (3 * u));
    const shE = shIrradiance(shLin, unit, c);
    ok(rel(shE, want) < tol, `N = ${n}, linear: SH irradiance ${shE}, expected ${want}`);
    const three = threeIrradiance(zUp, m, c);
    ok(rel(three, shE) < 1e-5, `N = ${n}: three.js at the y-up normal ${three}, SH irradiance ${shE}`);
    ok(rel(threeIrradiance(yUp, m, c), shE) > 1e-2, `N = ${n}: the unrotated export matches at the y-up normal too`);
    ok(rel(threeIrradiance(yUp, unit, c), shE) < 1e-5, `N = ${n}: "y-up" at the normal itself`);
  }
  throws(() => p.threeJsSh("Y-UP"), "InvalidParameter", "threeJsSh of an unknown frame", "threeJsSh");
  throws(() => p.threeJsSh(), "InvalidParameter", "threeJsSh without a frame", "threeJsSh");
  p.dispose();
  throws(() => p.threeJsSh("z-up"), "InvalidHandle", "threeJsSh after dispose", "threeJsSh");
}

// The temporal probes on known fields: a constant L has irradiance π·L; a linear field
// a + b·z reads a + g₁·b·z through the Gaussian footprint of sharpness S (g₁ = coth S − 1/S)
// and has irradiance π·(a + b·n_z·2/3) for a unit n, which both probes recover.
for (const n of SIZES) {
  for (const footprint of ["point", "gaussian"]) {
    const t = await TemporalProbe.create({ n, seed: 2, footprint });
    const L = [0.5, 2, 7];
    const constant = (count) => Float32Array.from({ length: 3 * count }, (_, k) => L[k % 3]);
    for (let k = 0; k < 3; k++) t.pool(constant(t.sampleCount), constant(t.sentinelCount));
    const normal = [0.3, -0.4, 0.5];
    const irr = t.irradiance(normal);
    const sh = t.radianceSh();
    for (let c = 0; c < 3; c++) {
      ok(rel(irr.value[c], Math.PI * L[c]) < 1e-5, `temporal N = ${n} ${footprint}, constant ${L[c]}: irradiance ${irr.value[c]}`);
      ok(rel(sh[c], Math.sqrt(4 * Math.PI) * L[c]) < 1e-5, `temporal N = ${n} ${footprint}, constant: c00 ${sh[c]}`);
      ok(irr.variance[c] >= 0 && irr.variance[c] < 1e-6 * L[c] ** 2, `temporal N = ${n} ${footprint}, constant: variance ${irr.variance[c]}`);
    }
    ok(t.updates === 3 && t.pooledUpdates === 3, `temporal N = ${n} ${footprint}: ${t.updates} updates, ${t.pooledUpdates} pooled`);
    const s = t.sharpness;
    const g1 = s === 0 ? 1 : 1 / Math.tanh(s) - 1 / s;
    const a = [1, 2, 0.5], b = [0.5, -1, 0.25];
    const linear = (dirs) => Float32Array.from({ length: dirs.length }, (_, k) => a[k % 3] + g1 * b[k % 3] * dirs[3 * Math.floor(k / 3) + 2]);
    const fresh = await TemporalProbe.create({ n, seed: 3, footprint });
    for (let k = 0; k < 4; k++) ok(fresh.pool(linear(fresh.directions()), linear(fresh.sentinels())) !== "reset", `temporal N = ${n} ${footprint}: no reset on static light`);
    const u = Math.hypot(...normal);
    const lin = fresh.irradiance(normal);
    // Aliasing is left after 4 updates (0.2 % at N = 16 point, below 0.4 % from N = 32).
    for (let c = 0; c < 3; c++) {
      const want = Math.PI * (a[c] + (b[c] * normal[2] * 2) / (3 * u));
      ok(rel(lin.value[c], want) < 1e-2, `temporal N = ${n} ${footprint}, linear: irradiance ${lin.value[c]}, expected ${want}`);
      // three.js's formula on the z-up export at the y-up image of the normal gives the
      // irradiance of the degree ≤ 2 coefficients at the normal (the state's degrees above 2
      // are not exported).
      const three = threeIrradiance(fresh.threeJsSh("z-up"), [normal[0] / u, normal[2] / u, -normal[1] / u], c);
      const shE = shIrradiance(fresh.radianceSh(), normal.map((v) => v / u), c);
      ok(rel(three, shE) < 1e-5, `temporal N = ${n} ${footprint}: three.js ${three}, SH irradiance ${shE}`);
    }
    const freshSh = fresh.radianceSh();
    ok(fresh.threeJsSh("y-up").every((v, k) => v === freshSh[k]), `temporal N = ${n} ${footprint}: "y-up" export unchanged`);
    throws(() => fresh.threeJsSh("x-up"), "InvalidParameter", "temporal threeJsSh of an unknown frame", "threeJsSh");
    t.dispose();
    fresh.dispose();
  }
}

// 4. Errors, state and options on the JS side.
await rejects(Probe.create({ n: 48 }), "InvalidSize", "unbaked N = 48");
await rejects(Probe.create({ n: 512 }), "InvalidSize", "unbaked N = 512");
await rejects(Probe.create({ seed: -1 }), "InvalidParameter", "negative seed");
await rejects(Probe.create({ seed: 1.5 }), "InvalidParameter", "fractional seed");
await rejects(Probe.create({ seed: 2 ** 32 }), "InvalidParameter", "seed ≥ 2³²");
await rejects(Probe.create({ n: 32, wasm: bytesOf[64] }), "InvalidSize", "the N = 64 module for N = 32");
await rejects(Probe.create({ n: 64, wasm: new Uint8Array([0, 97, 115, 109, 1, 0, 0, 0]) }), "InvalidParameter",
  "an empty module (no exports)");
{
  const p = await Probe.create();
  ok(p.n === 64 && p.seed === 0, "defaults N = 64, seed 0");
  const q = await Probe.create({ n: 64, seed: 9 });
  const own = await Probe.create({ n: 64, seed: 9, wasm: new WebAssembly.Module(bytesOf[64]) });
  const n = 64;
  const ys = Float32Array.from({ length: 3 * n }, (_, k) => 1 + (k % 7) / 4);
  throws(() => p.update(ys.subarray(1)), "LengthMismatch", "update with 3N − 1 floats");
  throws(() => p.update(new Float32Array(n)), "LengthMismatch", "update with N (scalar) floats");
  throws(() => p.update(null), "LengthMismatch", "update(null)");
  p.update(ys);
  q.update(ys);
  own.update(Array.from(ys));
  const before = p.irradiance([0, 1, 0]);
  const bad = ys.slice();
  bad[5] = NaN;
  throws(() => p.update(bad), "InvalidRadiance", "NaN sample");
  const after = p.irradiance([0, 1, 0]);
  ok(before.value.every((v, c) => v === after.value[c]) && before.variance.every((v, c) => v === after.variance[c]),
    "a refused update keeps the probe's data");
  throws(() => p.irradiance([0, 1]), "LengthMismatch", "a normal of 2 components");
  throws(() => p.irradiance([0, 0, 0]), "InvalidDirection", "zero normal");
  throws(() => p.glossy([0, 0, 1], -2), "InvalidExponent", "negative exponent");
  throws(() => p.glossy([0, NaN, 1], 20), "InvalidDirection", "NaN reflection direction");
  // Probes are independent: other rotations give other directions and answers; the module
  // passed in `wasm` gives the default module's answers.
  const dq = q.directions(), dp = p.directions();
  ok(dq.some((v, i) => v !== dp[i]), "seed 9 rotates the directions");
  const eq = q.irradiance([0, 1, 0]), eo = own.irradiance([0, 1, 0]);
  ok(eq.value.some((v, c) => v !== after.value[c]), "a rotated probe answers differently");
  ok(eq.value.every((v, c) => v === eo.value[c]), "the `wasm` option's module answers as the default one");
  p.dispose();
  p.dispose();
  throws(() => p.directions(), "InvalidHandle", "directions after dispose");
  throws(() => p.irradiance([0, 0, 1]), "InvalidHandle", "irradiance after dispose");
  const r = await Probe.create({ n: 64, seed: 0 });
  r.update(ys);
  ok(r.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "a new probe in a freed slot starts afresh");
  ok(q.irradiance([0, 1, 0]).value.every((v, c) => v === eq.value[c]), "freeing a probe leaves the others alone");
  for (const x of [q, r, own]) x.dispose();
  // Many probes at once (the module's memory grows; views are taken afresh).
  const many = await Promise.all(Array.from({ length: 200 }, (_, i) => Probe.create({ n: 256, seed: i + 1 })));
  for (const m of many) m.update(Float32Array.from({ length: 3 * 256 }, () => 1));
  ok(many.every((m) => Math.abs(m.irradiance([0, 0, 1]).value[0] - Math.PI) < 1e-5), "200 probes of N = 256");
  many.forEach((m) => m.dispose());
  try {
    new Probe();
    ok(false, "new Probe() must throw");
  } catch (e) {
    ok(e instanceof TypeError, `new Probe(): ${e}`);
  }
}

// The temporal probe's errors, state and options.
await rejects(TemporalProbe.create({ n: 48 }), "InvalidSize", "temporal: unbaked N = 48");
await rejects(TemporalProbe.create({ seed: -1 }), "InvalidParameter", "temporal: negative seed");
await rejects(TemporalProbe.create({ seed: 0.5 }), "InvalidParameter", "temporal: fractional seed");
await rejects(TemporalProbe.create({ footprint: "cone" }), "InvalidParameter", "temporal: unknown footprint");
for (const hazard of [0, 1, -0.5, NaN, "0.1"]) {
  await rejects(TemporalProbe.create({ hazard }), "InvalidParameter", `temporal: hazard ${hazard}`);
}
await rejects(TemporalProbe.create({ n: 16, wasm: bytesOf[64] }), "InvalidSize", "temporal: the N = 64 module for N = 16");
{
  const t = await TemporalProbe.create({ n: 64, seed: 4 });
  ok(t.n === 64 && t.seed === 4 && t.footprint === "point" && t.hazard === 1 / 64 && t.sharpness === 0,
    "temporal defaults: point samples, hazard 1/64");
  ok(t.sentinelCount === 2 && t.sampleCount === 62 && t.degree === 6, `temporal N = 64: ${t.sampleCount} + ${t.sentinelCount}, L = ${t.degree}`);
  const fresh = t.irradiance([0, 0, 1]);
  ok([...fresh.value, ...fresh.variance].every((v) => v === 0) && t.updates === 0 && t.lastChangeProbability === 0,
    "a fresh temporal probe answers zero");
  // The crate's vocabulary: a temporal probe pools (0.1's `update` and `effectiveUpdates` are gone).
  ok(typeof t.pool === "function" && !("update" in t) && !("effectiveUpdates" in t) && t.pooledUpdates === 0,
    "TemporalProbe has pool and pooledUpdates, not update or effectiveUpdates");
  const dirs = t.directions();
  const sentinels = t.sentinels();
  ok(dirs.length === 3 * 62 && sentinels.length === 6, `temporal directions ${dirs.length}, sentinels ${sentinels.length}`);
  const ys = Float32Array.from({ length: 3 * 62 }, (_, k) => 1 + (k % 5) / 8);
  const ss = Float32Array.from({ length: 6 }, () => 1.25);
  throws(() => t.pool(ys.subarray(1), ss), "LengthMismatch", "temporal pool with 3(N − S) − 1 samples", "pool");
  throws(() => t.pool(new Float32Array(3 * 64), ss), "LengthMismatch", "temporal pool with 3N samples", "pool");
  throws(() => t.pool(ys, ss.subarray(3)), "LengthMismatch", "temporal pool with one sentinel reading short", "pool");
  throws(() => t.pool(ys), "LengthMismatch", "temporal pool without sentinel readings", "pool");
  ok(t.pool(ys, Array.from(ss)) === "first", "the first temporal pool");
  const next = t.directions();
  ok(next.some((v, i) => v !== dirs[i]), "a temporal update rotates the directions");
  // The sentinels re-read directions of the update before.
  const reread = t.sentinels();
  ok([0, 1].every((j) => [...Array(62).keys()].some((i) => [0, 1, 2].every((c) => reread[3 * j + c] === dirs[3 * i + c]))),
    "the sentinels re-read directions of the update before");
  const before = t.irradiance([0, 1, 0]);
  const bad = ys.slice();
  bad[4] = Infinity;
  throws(() => t.pool(bad, ss), "InvalidRadiance", "temporal: infinite sample", "pool");
  throws(() => t.pool(ys, Float32Array.from([1, 1, NaN, 1, 1, 1])), "InvalidRadiance", "temporal: NaN sentinel reading", "pool");
  const after = t.irradiance([0, 1, 0]);
  ok(t.updates === 1 && before.value.every((v, c) => v === after.value[c]) && t.directions().every((v, i) => v === next[i]),
    "a refused temporal pool keeps the state and the directions");
  throws(() => t.irradiance([0, 1]), "LengthMismatch", "temporal: a normal of 2 components");
  throws(() => t.irradiance([0, 0, 0]), "InvalidDirection", "temporal: zero normal");
  // Probes and temporal probes of one module are independent; the `wasm` option's module
  // answers as the default one.
  const p = await Probe.create({ n: 64 });
  const own = await TemporalProbe.create({ n: 64, seed: 4, wasm: new WebAssembly.Module(bytesOf[64]) });
  own.pool(ys, ss);
  ok(own.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "the `wasm` option's temporal probe answers as the default one");
  p.dispose();
  ok(t.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "freeing a Probe leaves the temporal probes alone");
  t.dispose();
  t.dispose();
  throws(() => t.directions(), "InvalidHandle", "temporal directions after dispose");
  throws(() => t.pool(ys, ss), "InvalidHandle", "temporal pool after dispose", "pool");
  throws(() => t.pooledUpdates, "InvalidHandle", "temporal state after dispose", "pooledUpdates");
  const r = await TemporalProbe.create({ n: 64, seed: 4 });
  r.pool(ys, ss);
  ok(r.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "a new temporal probe in a freed slot starts afresh");
  for (const x of [r, own]) x.dispose();
  try {
    new TemporalProbe();
    ok(false, "new TemporalProbe() must throw");
  } catch (e) {
    ok(e instanceof TypeError, `new TemporalProbe(): ${e}`);
  }
}

// Layout probes: known answers, every sensor count, and the JS side.
{
  // A constant field L under a prior with a constant mean: irradiance π·L at every normal,
  // every normalised Phong average L, c₀₀ = √(4π)·L, no variance (the crate's doc examples).
  const faces = [1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1];
  const L = [0.5, 2, 7];
  const p = await LayoutProbe.create({ directions: faces, prior: { squaredExponential: 2 } });
  ok(p.k === 6 && !p.updated && p.pooledUpdates === 0, `a fresh layout probe: k ${p.k}, updated ${p.updated}`);
  // The crate's vocabulary: `update` replaces, `pool` pools (0.1's `accumulate` is gone).
  ok(typeof p.update === "function" && typeof p.pool === "function" && !("accumulate" in p),
    "LayoutProbe has update and pool, not accumulate");
  const zero = p.irradiance([0, 0, 1]);
  ok([...zero.value, ...zero.variance].every((v) => v === 0), "a layout probe answers zero before the first update");
  ok(p.pool(Float32Array.from({ length: 18 }, (_, k) => L[k % 3])) === "first", "the first pool");
  ok(p.updated && p.pooledUpdates === 1, `after the first pool: pooled ${p.pooledUpdates}`);
  const irr = p.irradiance([0.3, -0.4, 0.5]);
  const phong = p.phong([0.2, 0.3, 0.9], 20);
  const sh = p.radianceSh();
  const exact = p.irradianceVariance([0.3, -0.4, 0.5]);
  for (let c = 0; c < 3; c++) {
    ok(rel(irr.value[c], Math.PI * L[c]) < 1e-4, `layout, constant ${L[c]}: irradiance ${irr.value[c]}`);
    ok(rel(phong.value[c], L[c]) < 1e-4, `layout, constant ${L[c]}: phong ${phong.value[c]}`);
    ok(rel(sh[c], Math.sqrt(4 * Math.PI) * L[c]) < 1e-4, `layout, constant: c00 ${sh[c]}`);
    ok(exact[c] >= 0 && exact[c] < 1e-4 * L[c] ** 2 && phong.variance[c] < 1e-4 * L[c] ** 2,
      `layout, constant: variances ${exact[c]}, ${phong.variance[c]}`);
  }
  ok(sh.slice(3).every((v, i) => Math.abs(v) < 1e-4 * L[i % 3]), `layout, constant: higher SH ${sh.slice(3)}`);
  // An update and a first pool of the same readings fit the same.
  const q = await LayoutProbe.create({ directions: faces, prior: { squaredExponential: 2 } });
  q.update(Float32Array.from({ length: 18 }, (_, k) => L[k % 3]));
  ok(q.irradiance([0.3, -0.4, 0.5]).value.every((v, c) => v === irr.value[c]), "update and a first pool agree");
  ok(q.lastChangeProbability === 0 && p.lastChangeProbability === 1, `change probabilities ${q.lastChangeProbability}, ${p.lastChangeProbability}`);

  // Every sensor count of the module builds and answers (spherical Fibonacci layouts).
  for (const k of LAYOUT_SIZES) {
    const dirs = new Float32Array(3 * k);
    for (let i = 0; i < k; i++) {
      const z = 1 - (2 * i + 1) / k, r = Math.sqrt(1 - z * z), phi = 2.399963229728653 * i;
      dirs.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * i);
    }
    const t = await LayoutProbe.create({ directions: dirs, noise: { absolute: 0.01, relative: 0.02 }, prior: "smooth-environment" });
    t.update(Float32Array.from({ length: 3 * k }, (_, j) => 1 + 0.5 * dirs[3 * Math.floor(j / 3) + 2]));
    const e = t.irradiance([0, 0, 1]);
    ok(t.k === k && e.value.every((v) => v > 0 && Number.isFinite(v)) && e.variance.every((v) => v >= 0),
      `layout K = ${k}: irradiance ${e.value}, variance ${e.variance}`);
    t.dispose();
  }

  // Sensor counts the module does not carry, above and between its capacities.
  await rejects(LayoutProbe.create({ directions: new Float32Array(3 * 17).fill(1) }), "InvalidSize", "layout of 17 sensors (above the capacities)");
  await rejects(LayoutProbe.create({ directions: new Float32Array(3 * 9).fill(1) }), "InvalidSize", "layout of 9 sensors");
  await rejects(LayoutProbe.create({ directions: new Float32Array(3 * 3).fill(1) }), "InvalidSize", "layout of 3 sensors");
  {
    // The module's own check, below index.js's.
    const { exports } = await WebAssembly.instantiate(new WebAssembly.Module(layoutBytes), {});
    const counts = new Uint32Array(exports.memory.buffer, exports.io_ptr(), exports.layout_capacities());
    ok(Array.from(counts).join() === LAYOUT_SIZES.join(), `layout_capacities ${Array.from(counts)}`);
    new Float32Array(exports.memory.buffer, exports.io_ptr(), exports.io_len()).fill(1);
    ok(exports.layout_new(17, 0, 0, 0, 0, 1 / 64) === -4 && exports.layout_new(9, 0, 0, 0, 0, 1 / 64) === -4,
      "the module refuses sensor counts it does not carry (-4)");
    ok(exports.layout_new(6, 7, 0, 0, 0, 1 / 64) === -5, "the module refuses an unknown prior (-5)");
    ok(exports.layout_free(0) === 100 && exports.layout_update(3) === 100, "the module refuses unknown handles (100)");
  }
  await rejects(LayoutProbe.create({ directions: faces.slice(1) }), "LengthMismatch", "layout directions not a multiple of 3");
  await rejects(LayoutProbe.create({}), "LengthMismatch", "layout without directions");
  await rejects(LayoutProbe.create({ directions: faces, powers: [1, 1, 1] }), "LengthMismatch", "layout with 3 powers for 6 sensors");
  await rejects(LayoutProbe.create({ directions: faces, noiseScales: [1] }), "LengthMismatch", "layout with 1 noise scale for 6 sensors");
  await rejects(LayoutProbe.create({ directions: faces, prior: "sky" }), "InvalidParameter", "layout with an unknown prior");
  await rejects(LayoutProbe.create({ directions: faces, prior: { squaredExponential: 65 } }), "InvalidParameter", "layout prior λ = 65");
  await rejects(LayoutProbe.create({ directions: faces, noise: { absolute: "1" } }), "InvalidParameter", "layout noise not a number");
  await rejects(LayoutProbe.create({ directions: faces, noise: { relative: NaN } }), "InvalidParameter", "layout noise NaN");
  await rejects(LayoutProbe.create({ directions: faces, noise: 0.01 }), "InvalidParameter", "layout noise a number");
  await rejects(LayoutProbe.create({ directions: faces, hazard: 0 }), "InvalidParameter", "layout hazard 0");
  await rejects(LayoutProbe.create({ directions: faces, powers: [1, 1, 1, 1, 1, -1] }), "InvalidParameter", "layout negative power");
  const nan = faces.slice();
  nan[4] = NaN;
  await rejects(LayoutProbe.create({ directions: nan }), "InvalidDirection", "layout NaN direction");
  // Readings: lengths, NaN, kept state.
  const before = p.irradiance([0, 1, 0]);
  throws(() => p.update(new Float32Array(17)), "LengthMismatch", "layout update with 3K − 1 readings", "update");
  throws(() => p.pool([1, 2, 3]), "LengthMismatch", "layout pool with 3 readings", "pool");
  throws(() => p.update(null), "LengthMismatch", "layout update without readings", "update");
  const bad = Float32Array.from({ length: 18 }, (_, k) => L[k % 3]);
  bad[7] = NaN;
  throws(() => p.update(bad), "InvalidRadiance", "layout: NaN reading (update)", "update");
  throws(() => p.pool(bad), "InvalidRadiance", "layout: NaN reading (pool)", "pool");
  const after = p.irradiance([0, 1, 0]);
  ok(p.pooledUpdates === 1 && before.value.every((v, c) => v === after.value[c]), "a refused layout update keeps the state");
  throws(() => p.irradiance([0, 1]), "LengthMismatch", "layout: a normal of 2 components");
  throws(() => p.irradianceVariance([0, 0, 0]), "InvalidDirection", "layout: zero normal (exact variance)");
  throws(() => p.phong([0, 0, 1], Infinity), "InvalidExponent", "layout: infinite exponent");
  // Every estimator takes the exponents 0 to 1e8, and refuses the rest.
  const sharp = p.phong([0, 0, 1], 5000);
  ok(sharp.value.every(Number.isFinite) && sharp.variance.every((v) => v >= 0), "layout: exponent 5000 (as the probe takes it)");
  throws(() => p.phong([0, 0, 1], 2e8), "InvalidExponent", "layout: exponent above 1e8");
  // The `wasm` option, independence, dispose.
  const own = await LayoutProbe.create({ directions: faces, prior: { squaredExponential: 2 }, wasm: layoutBytes });
  own.update(Float32Array.from({ length: 18 }, (_, k) => L[k % 3]));
  ok(own.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "the `wasm` option's layout probe answers as the default one");
  await rejects(LayoutProbe.create({ directions: faces, wasm: bytesOf[16] }), "InvalidParameter", "a probe module as the layout module");
  q.dispose();
  ok(p.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "freeing a layout probe leaves the others alone");
  p.dispose();
  p.dispose();
  throws(() => p.directions(), "InvalidHandle", "layout directions after dispose");
  throws(() => p.update(bad), "InvalidHandle", "layout update after dispose");
  throws(() => p.pool(bad), "InvalidHandle", "layout pool after dispose", "pool");
  throws(() => p.pooledUpdates, "InvalidHandle", "layout state after dispose", "pooledUpdates");
  own.dispose();
  try {
    new LayoutProbe();
    ok(false, "new LayoutProbe() must throw");
  } catch (e) {
    ok(e instanceof TypeError, `new LayoutProbe(): ${e}`);
  }
}

console.log(`${checks} checks, ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
