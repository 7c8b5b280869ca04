// The Node test of the sphere-quadrature package, run from a consumer project that installed
// the packed tarball (test/run.sh): imports the package by its name, as a user would, and
// checks
// 1. the installed modules: all five sizes, no imports, only the package's exports, sizes
//    (N = 64 at most 100 KB, the target);
// 2. every value against the host reference (eval/src/bin/js_package_reference.rs), bit for bit:
//    directions, irradiance and glossy with variances, SH coefficients and variances, for
//    every size and two rotations, and the errors of bad queries by name; and, for every size,
//    a stream of temporal updates (static light, a switch, a slight brightening) of a point
//    and of a footprint TemporalProbe: directions, what each update did, the state (effective
//    updates, change probability, evidence), irradiance with variance, SH and SH variances;
// 3. the physics on fields with known answers (constant radiance: irradiance π·L, glossy L,
//    SH c₀₀ = √(4π)·L; a linear field: irradiance π·(a + b·n_z·2/3)), independent of Rust;
//    the temporal probe's irradiance of a constant and a linear field, point and footprint;
// 4. the JS side: exceptions (type, code, message) for every kind of bad input, kept data
//    after a refused update, independent probes, dispose, the `wasm` option.
//
//   node test.mjs REFERENCE
import { readFileSync, statSync } from "node:fs";
import { createRequire } from "node:module";
import { Probe, ProbeError, SIZES, TemporalProbe } from "sphere-quadrature";

let failures = 0;
let checks = 0;
function ok(cond, what) {
  checks++;
  if (!cond) {
    failures++;
    console.log(`FAIL: ${what}`);
  }
}
function throws(fn, code, what) {
  try {
    fn();
  } catch (e) {
    ok(e instanceof ProbeError && e instanceof Error && e.code === code && e.name === "ProbeError" && e.message.length > 0,
      `${what}: expected ProbeError ${code}, got ${e?.name} ${e?.code}: ${e?.message}`);
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
  "probe_radiance_sh", "probe_radiance_sh_variance", "probe_size", "probe_update", "temporal_directions",
  "temporal_free", "temporal_irradiance", "temporal_new", "temporal_radiance_sh", "temporal_radiance_sh_variance",
  "temporal_sentinel_count", "temporal_sentinels", "temporal_sharpness", "temporal_state", "temporal_update",
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
    // Updates and degree as integers, then effective updates, change probability, evidence.
    const state = (key, u) => {
      lines.push(`t_${key} ${at(u)} 0 ${t.updates}`, `t_${key} ${at(u)} 1 ${t.degree}`);
      const { rotated, sentinels } = t.lastEvidence;
      [t.effectiveUpdates, t.lastChangeProbability, rotated, sentinels]
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
          change = t.update(ys, ss);
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
    lines.push(`t_err ${at(u)} 0 ${refused(() => t.update(bad, ss))}`);
    const badSentinels = ss.slice();
    badSentinels[3 * (t.sentinelCount - 1) + 2] = Infinity;
    lines.push(`t_err ${at(u)} 1 ${refused(() => t.update(ys, badSentinels))}`);
    const after = t.directions();
    lines.push(`t_err ${at(u)} 2 ${before.every((v, i) => v === after[i])}`);
    state("state_after_err", u);
    lines.push(`t_err ${at(u)} 3 ${refused(() => t.irradiance([0, 0, 0]))}`);
    lines.push(`t_err ${at(u)} 4 ${refused(() => t.irradiance([0, NaN, 1]))}`);
    t.dispose();
  }
}
// The streams must hold what they are meant to compare: every update, a reset at the
// switch and none on the static light before it.
const updatesPerStream = PHASES.reduce((a, b) => a + b, 0);
ok(changes.length === SIZES.length * STREAMS.length * updatesPerStream, `${changes.length} temporal updates`);
ok(reference.filter((l) => l.startsWith("t_change ")).length === changes.length,
  `the reference has ${reference.filter((l) => l.startsWith("t_change ")).length} temporal updates, the package ${changes.length}`);
for (const n of SIZES) {
  for (const { name } of STREAMS) {
    const c = changes.filter((x) => x.n === n && x.name === name);
    ok(c[0]?.change === "first" && c.slice(1, PHASES[0]).every((x) => x.change === "blended"),
      `temporal ${n} ${name}: static light ${c.slice(0, PHASES[0]).map((x) => x.change).join(" ")}`);
    ok(c[PHASES[0]]?.change === "reset", `temporal ${n} ${name}: the switch gave ${c[PHASES[0]]?.change}`);
  }
}

let differing = 0;
for (let i = 0; i < Math.max(lines.length, reference.length); i++) {
  if (lines[i] !== reference[i]) {
    if (differing < 5) console.log(`line ${i + 1}: package "${lines[i]}", host "${reference[i]}"`);
    differing++;
  }
}
const temporalLines = reference.filter((l) => l.startsWith("t_")).length;
ok(reference.length > 8000 && temporalLines > 100000 && differing === 0,
  `${differing} of ${reference.length} reference lines differ (package printed ${lines.length}; ${temporalLines} temporal)`);
if (differing === 0) {
  console.log(`${lines.length} lines (every size, seeds ${SEEDS.join(" and ")}; ${temporalLines} of them from ` +
    `${changes.length} temporal updates, point and footprint) identical to the host reference`);
}

// 3. Fields with known answers.
const rel = (a, b) => Math.abs(a - b) / Math.abs(b);
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
  p.dispose();
}

// The temporal probes on known fields: a constant L has irradiance π·L; a linear field
// a + b·z reads a + g₁·b·z through the Gaussian footprint of sharpness S (g₁ = coth S − 1/S)
// and has irradiance π·(a + b·n_z·2/3) for a unit n, which both probes recover.
for (const n of SIZES) {
  for (const footprint of ["point", "gaussian"]) {
    const t = await TemporalProbe.create({ n, seed: 2, footprint });
    const L = [0.5, 2, 7];
    const constant = (count) => Float32Array.from({ length: 3 * count }, (_, k) => L[k % 3]);
    for (let k = 0; k < 3; k++) t.update(constant(t.sampleCount), constant(t.sentinelCount));
    const normal = [0.3, -0.4, 0.5];
    const irr = t.irradiance(normal);
    const sh = t.radianceSh();
    for (let c = 0; c < 3; c++) {
      ok(rel(irr.value[c], Math.PI * L[c]) < 1e-5, `temporal N = ${n} ${footprint}, constant ${L[c]}: irradiance ${irr.value[c]}`);
      ok(rel(sh[c], Math.sqrt(4 * Math.PI) * L[c]) < 1e-5, `temporal N = ${n} ${footprint}, constant: c00 ${sh[c]}`);
      ok(irr.variance[c] >= 0 && irr.variance[c] < 1e-6 * L[c] ** 2, `temporal N = ${n} ${footprint}, constant: variance ${irr.variance[c]}`);
    }
    ok(t.updates === 3 && t.effectiveUpdates === 3, `temporal N = ${n} ${footprint}: ${t.updates} updates, ${t.effectiveUpdates} effective`);
    const s = t.sharpness;
    const g1 = s === 0 ? 1 : 1 / Math.tanh(s) - 1 / s;
    const a = [1, 2, 0.5], b = [0.5, -1, 0.25];
    const linear = (dirs) => Float32Array.from({ length: dirs.length }, (_, k) => a[k % 3] + g1 * b[k % 3] * dirs[3 * Math.floor(k / 3) + 2]);
    const fresh = await TemporalProbe.create({ n, seed: 3, footprint });
    const sentinelReadings = linear(fresh.sentinels());
    for (let k = 0; k < 4; k++) ok(fresh.update(linear(fresh.directions()), sentinelReadings) !== "reset", `temporal N = ${n} ${footprint}: no reset on static light`);
    const u = Math.hypot(...normal);
    const lin = fresh.irradiance(normal);
    // Aliasing is left after 4 updates (0.2 % at N = 16 point, below 0.4 % from N = 32).
    for (let c = 0; c < 3; c++) {
      const want = Math.PI * (a[c] + (b[c] * normal[2] * 2) / (3 * u));
      ok(rel(lin.value[c], want) < 1e-2, `temporal N = ${n} ${footprint}, linear: irradiance ${lin.value[c]}, expected ${want}`);
    }
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
  const dirs = t.directions();
  const sentinels = t.sentinels();
  ok(dirs.length === 3 * 62 && sentinels.length === 6, `temporal directions ${dirs.length}, sentinels ${sentinels.length}`);
  const ys = Float32Array.from({ length: 3 * 62 }, (_, k) => 1 + (k % 5) / 8);
  const ss = Float32Array.from({ length: 6 }, () => 1.25);
  throws(() => t.update(ys.subarray(1), ss), "LengthMismatch", "temporal update with 3(N − S) − 1 samples");
  throws(() => t.update(new Float32Array(3 * 64), ss), "LengthMismatch", "temporal update with 3N samples");
  throws(() => t.update(ys, ss.subarray(3)), "LengthMismatch", "temporal update with one sentinel reading short");
  throws(() => t.update(ys), "LengthMismatch", "temporal update without sentinel readings");
  ok(t.update(ys, Array.from(ss)) === "first", "the first temporal update");
  const next = t.directions();
  ok(next.some((v, i) => v !== dirs[i]), "a temporal update rotates the directions");
  ok(t.sentinels().every((v, i) => v === sentinels[i]), "the sentinels stay");
  const before = t.irradiance([0, 1, 0]);
  const bad = ys.slice();
  bad[4] = Infinity;
  throws(() => t.update(bad, ss), "InvalidRadiance", "temporal: infinite sample");
  throws(() => t.update(ys, Float32Array.from([1, 1, NaN, 1, 1, 1])), "InvalidRadiance", "temporal: NaN sentinel reading");
  const after = t.irradiance([0, 1, 0]);
  ok(t.updates === 1 && before.value.every((v, c) => v === after.value[c]) && t.directions().every((v, i) => v === next[i]),
    "a refused temporal update keeps the state and the directions");
  throws(() => t.irradiance([0, 1]), "LengthMismatch", "temporal: a normal of 2 components");
  throws(() => t.irradiance([0, 0, 0]), "InvalidDirection", "temporal: zero normal");
  // Probes and temporal probes of one module are independent; the `wasm` option's module
  // answers as the default one.
  const p = await Probe.create({ n: 64 });
  const own = await TemporalProbe.create({ n: 64, seed: 4, wasm: new WebAssembly.Module(bytesOf[64]) });
  own.update(ys, ss);
  ok(own.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "the `wasm` option's temporal probe answers as the default one");
  p.dispose();
  ok(t.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "freeing a Probe leaves the temporal probes alone");
  t.dispose();
  t.dispose();
  throws(() => t.directions(), "InvalidHandle", "temporal directions after dispose");
  throws(() => t.update(ys, ss), "InvalidHandle", "temporal update after dispose");
  throws(() => t.effectiveUpdates, "InvalidHandle", "temporal state after dispose");
  const r = await TemporalProbe.create({ n: 64, seed: 4 });
  r.update(ys, ss);
  ok(r.irradiance([0, 1, 0]).value.every((v, c) => v === before.value[c]), "a new temporal probe in a freed slot starts afresh");
  for (const x of [r, own]) x.dispose();
  try {
    new TemporalProbe();
    ok(false, "new TemporalProbe() must throw");
  } catch (e) {
    ok(e instanceof TypeError, `new TemporalProbe(): ${e}`);
  }
}

console.log(`${checks} checks, ${failures} failed`);
process.exit(failures === 0 ? 0 : 1);
