// Runs the sphere-quadrature WebAssembly module under Node (no npm packages) and prints
// `key index bits` lines: first the shared Cortex-M4 scenario (run inside the module), then
// every scalar export and the probe-style buffer round trip on fixed inputs. The host twin,
// eval/src/bin/wasm_scenario.rs, prints the same lines from native code; .ci/run diffs the two.
//
//   (cd examples/wasm && cargo build --release --target wasm32-unknown-unknown)
//   node examples/wasm/test.mjs > wasm.txt
//   cargo eval wasm_scenario | diff wasm.txt -
import { readFileSync } from "node:fs";

const path = new URL(
  "target/wasm32-unknown-unknown/release/sphere_quadrature_wasm.wasm",
  import.meta.url,
);
const { instance } = await WebAssembly.instantiate(readFileSync(path), {});
const w = instance.exports;
const memory = w.memory;

const out = [];
const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);
function bits(v) {
  if (Number.isNaN(v)) return "nan";
  f32[0] = v;
  return u32[0].toString(16).padStart(8, "0");
}
function value(key, index, v) {
  out.push(`${key} ${index} ${bits(v)}`);
}

// 1. The shared scenario, formatted inside the module into its static text buffer.
const len = w.scenario_run();
if (len < 0) throw new Error("scenario output overflowed the module's buffer");
const text = new TextDecoder().decode(new Uint8Array(memory.buffer, w.out_ptr(), len));
out.push(...text.split("\n").filter((l) => l.length > 0));

// 2. Scalar exports on the inputs of eval/src/bin/wasm_scenario.rs (same formulas; all inputs
// are dyadic rationals, exact in both f64 and f32).
const COUNT = 27;
function normal(i) {
  if (i === 24) return [0, 0, 0];
  if (i === 25) return [NaN, 0, 1];
  if (i === 26) return [Infinity, 0, 0];
  return [(((i * 5) % 9) - 4) / 4, (((i * 7) % 11) - 5) / 4, (((i * 3) % 7) - 3) / 2];
}
const lo = (i) => Math.imul(i, 0x9e3779b9) >>> 0;
const hi = (i) => Math.imul(i, 0x85ebca6b) >>> 0;
const exponent = (i) => (i % 8) * 8 - 4;

for (let i = 0; i < COUNT; i++) {
  const [x, y, z] = normal(i);
  value("w_irr64", i, w.qmc_irradiance_64(x, y, z, lo(i), hi(i)));
  value("w_phong64", i, w.phong_64(x, y, z, exponent(i), lo(i), hi(i)));
  value("w_sky", i, w.sky(x, y, z));
  out.push(`w_nearest4096 ${i} ${w.nearest_index_4096(x, y, z)}`);
}

const JS = [0, 1, 17, 63, 64, 255, 256, 4095, 4096];
for (let kind = 0; kind < 4; kind++) {
  JS.forEach((j, jj) => {
    for (let c = 0; c < 4; c++) value(`w_sf${kind}`, 4 * jj + c, w.sf_point_component(kind, j, c));
  });
}

const LAMBDAS = [0, 0.5, 1, 4, 16, 100, 1000, -1, NaN, Infinity];
const TS = [-1, -0.5, 0, 0.25, 1, 2, NaN];
LAMBDAS.forEach((l, li) => {
  TS.forEach((t, ti) => value("w_sghemi", li * TS.length + ti, w.sg_hemispherical_fraction(l, t)));
});

// 3. Probe style: the module writes the directions into its buffer, JavaScript evaluates the
// radiance (here the module's own sky, so the host can reproduce it bit for bit) and writes
// the samples into the module's sample buffer, the module estimates.
const SIZES = [16, 64, 4096, 0, 5000];
if (w.probe_max() !== 4096) throw new Error(`probe_max() = ${w.probe_max()}`);
for (let i = 0; i < 8; i++) {
  const [x, y, z] = normal(i);
  SIZES.forEach((n, ni) => {
    const k = i * SIZES.length + ni;
    const got = w.probe_directions(x, y, z, lo(i), hi(i), n);
    if (got < 0) {
      value("w_probe", k, NaN);
      return;
    }
    if (got !== n) throw new Error(`probe_directions returned ${got}, expected ${n}`);
    const dirs = new Float32Array(memory.buffer, w.dirs_ptr(), 3 * n);
    const samples = new Float32Array(memory.buffer, w.samples_ptr(), n);
    for (let j = 0; j < n; j++) samples[j] = w.sky(dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]);
    value("w_probe", k, w.probe_estimate(x, y, z, lo(i), hi(i), n));
    for (let c = 0; c < 3; c++) value("w_probedir", 3 * k + c, dirs[3 * (n - 1) + c]);
  });
}

// 4. The Bayesian Monte Carlo probe (64 RGB samples): the module writes its directions,
// JavaScript evaluates the scenario's RGB sky there (`sky_rgb` in f32 arithmetic via
// Math.fround) into the sample buffer, the module updates the probe and answers irradiance
// queries with variances; bad normals and NaN/infinite samples give error codes.
const BMC_SEEDS = [0, 1, 0xdeadbeef];
const BMC_NORMALS = [0, 1, 2, 3, 4, 5, 6, 7, 24, 25, 26];
const fr = Math.fround;
function skyRgb(x, y, z) {
  const l = w.sky(x, y, z);
  return [l, fr(fr(fr(0.9) * l) + fr(fr(0.05) * x)), fr(fr(0.8) * l)];
}
function bmcIrradiance(key, k, [x, y, z]) {
  const code = w.bmc_probe_irradiance(x, y, z);
  out.push(`${key}_code ${k} ${code}`);
  if (code !== 0) return;
  const e = new Float32Array(memory.buffer, w.bmc_out_ptr(), 6);
  for (let c = 0; c < 6; c++) value(key, 6 * k + c, e[c]);
}
// Glossy queries: (normal index, Phong exponent); the last two are bad (exponent −1, NaN).
const BMC_GLOSSY = [[0, 5], [1, 20], [4, 100], [7, 0], [25, -1], [26, NaN]];
function bmcGlossy(key, k, [x, y, z], e) {
  const code = w.bmc_probe_glossy(x, y, z, e);
  out.push(`${key}_code ${k} ${code}`);
  if (code !== 0) return;
  const g = new Float32Array(memory.buffer, w.bmc_out_ptr(), 6);
  for (let c = 0; c < 6; c++) value(key, 6 * k + c, g[c]);
}
BMC_SEEDS.forEach((seed, s) => {
  out.push(`w_bmc_reset ${s} ${w.bmc_probe_reset(seed)}`);
  out.push(`w_bmc_selected ${3 * s} ${w.bmc_probe_selected()}`);
  bmcIrradiance("w_bmc_empty", s, normal(0));
  const n = w.bmc_probe_directions();
  if (n !== 64) throw new Error(`bmc_probe_directions returned ${n}, expected 64`);
  const dirs = new Float32Array(memory.buffer, w.dirs_ptr(), 3 * n);
  for (let j = 0; j < 3 * n; j++) value("w_bmc_dir", 3 * n * s + j, dirs[j]);
  const samples = new Float32Array(memory.buffer, w.samples_ptr(), 3 * n);
  for (let j = 0; j < n; j++) samples.set(skyRgb(dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]), 3 * j);
  out.push(`w_bmc_update ${3 * s} ${w.bmc_probe_update()}`);
  out.push(`w_bmc_selected ${3 * s + 1} ${w.bmc_probe_selected()}`);
  BMC_NORMALS.forEach((i, ni) => bmcIrradiance("w_bmc_irr", BMC_NORMALS.length * s + ni, normal(i)));
  BMC_GLOSSY.forEach(([i, e], gi) => bmcGlossy("w_bmc_glossy", BMC_GLOSSY.length * s + gi, normal(i), e));
  // Bad samples are refused and the probe keeps the previous data.
  const good = samples[3 * 17 + 1];
  samples[3 * 17 + 1] = NaN;
  out.push(`w_bmc_update ${3 * s + 1} ${w.bmc_probe_update()}`);
  samples[3 * 17 + 1] = good;
  samples[3 * 40 + 2] = -Infinity;
  out.push(`w_bmc_update ${3 * s + 2} ${w.bmc_probe_update()}`);
  out.push(`w_bmc_selected ${3 * s + 2} ${w.bmc_probe_selected()}`);
  bmcIrradiance("w_bmc_kept", s, normal(3));
});

// 5. The batch form for every baked N (as the browser page uses it): directions, one update
// with the RGB sky, irradiance about normal(i) and Phong glossy (e = 20) about another
// direction, bad query directions giving NaN; then bad n, count, exponent and samples.
const SHADE_NS = [16, 32, 64, 128, 256];
const SHADE_Q = [0, 1, 2, 3, 5, 24, 25];
const mirrorOf = (i) => (i >= 24 ? 26 : (i + 7) % 24);
SHADE_NS.forEach((n, s) => {
  const seed = 7 + s;
  const got = w.bmc_shade_directions(n, seed);
  out.push(`w_shade_dirs ${s} ${got}`);
  if (got !== n) return;
  const dirs = new Float32Array(memory.buffer, w.dirs_ptr(), 3 * n);
  const samples = new Float32Array(memory.buffer, w.samples_ptr(), 3 * n);
  for (let j = 0; j < n; j++) samples.set(skyRgb(dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]), 3 * j);
  const q = new Float32Array(memory.buffer, w.queries_ptr(), 6 * SHADE_Q.length);
  SHADE_Q.forEach((i, k) => {
    q.set(normal(i), 6 * k);
    q.set(normal(mirrorOf(i)), 6 * k + 3);
  });
  out.push(`w_shade_code ${s} ${w.bmc_shade(n, seed, SHADE_Q.length, 20)}`);
  const r = new Float32Array(memory.buffer, w.shaded_ptr(), 6 * SHADE_Q.length);
  for (let k = 0; k < 6 * SHADE_Q.length; k++) value("w_shade", 6 * SHADE_Q.length * s + k, r[k]);
});
{
  // The sample buffer still holds the N = 256 sky: its first 16 samples are valid.
  out.push(`w_shade_bad 0 ${w.bmc_shade_directions(17, 1)}`);
  out.push(`w_shade_bad 1 ${w.bmc_shade(17, 1, 1, 20)}`);
  out.push(`w_shade_bad 2 ${w.bmc_shade(16, 1, 1025, 20)}`);
  out.push(`w_shade_bad 3 ${w.bmc_shade(16, 1, 1, -1)}`);
  const samples = new Float32Array(memory.buffer, w.samples_ptr(), 3 * 16);
  samples[4] = NaN;
  out.push(`w_shade_bad 4 ${w.bmc_shade(16, 1, 1, 20)}`);
}

// 6. Footprint probes (`Probe<N, [f32; 3], Gaussian<N/8>>`): JavaScript writes a 256×128 RGB
// test map into the module's map buffer, the module takes footprint samples of it at the
// probe's directions, exactly and from its mip pyramid, and the footprint probe answers the
// queries of section 5 from the exact samples; then nearest-pixel samples and bad input.
const MW = 256;
const MH = 128;
// Dyadic values (exact in f32): a bright upper half, a ripple, and a small bright "lamp".
function mapPixel(u, v) {
  if (u >= 40 && u < 44 && v >= 20 && v < 23) return [64, 60, 48];
  const base = v < MH / 2 ? 2 : 0.25;
  return [base + ((u * 3 + v * 5) % 16) / 16, base + ((u ^ v) & 7) / 8, base / 2 + (v % 4) / 4];
}
const mapBuf = new Float32Array(memory.buffer, w.map_ptr(), 3 * w.map_max());
if (w.map_max() !== 512 * 256) throw new Error(`map_max() = ${w.map_max()}`);
for (let v = 0; v < MH; v++) for (let u = 0; u < MW; u++) mapBuf.set(mapPixel(u, v), 3 * (v * MW + u));
SHADE_NS.forEach((n, s) => {
  const seed = 21 + s;
  const sharpness = w.footprint_sharpness(n);
  out.push(`w_fp_sharpness ${s} ${sharpness}`);
  const got = w.footprint_shade_directions(n, seed);
  out.push(`w_fp_dirs ${s} ${got}`);
  if (got !== n) return;
  const dirs = new Float32Array(memory.buffer, w.dirs_ptr(), 3 * n);
  for (const j of [0, n - 1]) for (let c = 0; c < 3; c++) value("w_fp_dir", 6 * s + 3 * (j && 1) + c, dirs[3 * j + c]);
  const samples = new Float32Array(memory.buffer, w.samples_ptr(), 3 * n);
  // The pyramid's samples first, so that the probe below gets the exact ones.
  for (const sampler of [1, 0]) {
    out.push(`w_fp_sample_code ${2 * s + sampler} ${w.map_footprint_samples(MW, MH, n, sharpness, sampler)}`);
    for (let k = 0; k < 3 * n; k++) value(`w_fp_sample${sampler}`, 3 * 256 * s + k, samples[k]);
  }
  const q = new Float32Array(memory.buffer, w.queries_ptr(), 6 * SHADE_Q.length);
  SHADE_Q.forEach((i, k) => {
    q.set(normal(i), 6 * k);
    q.set(normal(mirrorOf(i)), 6 * k + 3);
  });
  out.push(`w_fp_shade_code ${s} ${w.footprint_shade(n, seed, SHADE_Q.length, 20)}`);
  const r = new Float32Array(memory.buffer, w.shaded_ptr(), 6 * SHADE_Q.length);
  for (let k = 0; k < 6 * SHADE_Q.length; k++) value("w_fp_shade", 6 * SHADE_Q.length * s + k, r[k]);
});
{
  // Nearest-pixel samples (sharpness 0) at the N = 16 directions, seed 21.
  w.footprint_shade_directions(16, 21);
  out.push(`w_fp_point_code 0 ${w.map_footprint_samples(MW, MH, 16, 0, 0)}`);
  const samples = new Float32Array(memory.buffer, w.samples_ptr(), 3 * 16);
  for (let k = 0; k < 3 * 16; k++) value("w_fp_point", k, samples[k]);
  // Bad input: error codes, and the sample buffer is left as it was.
  const before = samples.slice();
  const dirs = new Float32Array(memory.buffer, w.dirs_ptr(), 3 * 16);
  const bad = [
    () => w.footprint_sharpness(17),
    () => w.footprint_shade_directions(17, 1),
    () => w.footprint_shade(17, 1, 1, 20),
    () => w.footprint_shade(16, 1, 1025, 20),
    () => w.footprint_shade(16, 1, 1, -1),
    () => w.map_footprint_samples(0, MH, 16, 2, 0),
    () => w.map_footprint_samples(1024, 256, 16, 2, 0),
    () => w.map_footprint_samples(MW, MH, 1025, 2, 0),
    () => w.map_footprint_samples(MW, MH, 16, 4097, 0),
    () => w.map_footprint_samples(MW, MH, 16, 2, 2),
    // A legal map whose pyramid does not fit the module's buffer: the exact form still works.
    () => w.map_footprint_samples(16384, 8, 16, 2, 1),
    () => {
      const keep = dirs[4];
      dirs[3] = dirs[4] = dirs[5] = 0;
      const code = [0, 1].map((sampler) => w.map_footprint_samples(MW, MH, 16, 2, sampler));
      w.footprint_shade_directions(16, 21);
      if (dirs[4] !== keep) throw new Error("directions not restored");
      return code.join(",");
    },
    () => {
      const keep = mapBuf[3 * 5 + 1];
      mapBuf[3 * 5 + 1] = NaN;
      const code = [0, 1].map((sampler) => w.map_footprint_samples(MW, MH, 16, 2, sampler));
      mapBuf[3 * 5 + 1] = keep;
      return code.join(",");
    },
  ];
  bad.forEach((f, k) => {
    out.push(`w_fp_bad ${k} ${f()}`);
    if (samples.some((x, i) => !Object.is(x, before[i]))) throw new Error(`bad input ${k} changed the samples`);
  });
  out.push(`w_fp_bad ${bad.length} ${w.map_footprint_samples(16384, 8, 16, 2, 0)}`);
  samples[4] = NaN;
  out.push(`w_fp_bad ${bad.length + 1} ${w.footprint_shade(16, 21, 1, 20)}`);
}

process.stdout.write(out.join("\n") + "\n");
