// The browser page of examples/wasm (index.html): shades a sphere from a bundled environment
// map with one Bayesian Monte Carlo probe of N samples (diffuse irradiance + normalised Phong
// glossy, N selectable), from point samples and from footprint samples (the module filters
// the map with a spherical Gaussian of sharpness N/8 about each direction), next to the
// weighted averages of the same samples, QMC with N samples per pixel, and a brute-force
// reference over every map pixel, and runs the page's own numeric check (see CHECK).
// Served from the repository root (examples/wasm/browser_test.mjs does that), so the map is at
// ../envmaps/<name>.hdr and the module at target/… relative to this page.

import { Probe, ProbeError } from "./package/index.js";

const WASM = "target/wasm32-unknown-unknown/release/sphere_quadrature_wasm.wasm";
const MAPS = ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];
/** Grid of normals per sphere (the reference sums all 131 072 pixels for each). */
const G = 32;
/**
 * The page check, over every bundled map at this lighting, N and Phong exponent (means of the
 * relative RMSE of luminance over the maps):
 * - point samples: the BMC probe below the weighted averages (diffuse and glossy), and on
 *   `map` below `diffuseMax` and `glossyMax` (sanity: the benchmark measures ≈ 20 % diffuse
 *   there);
 * - footprint samples, exact and from the mip pyramid: the footprint probe's diffuse error at
 *   most `footprintRatio` times the lower of the point probe's and the cosine-weighted average
 *   of point samples (issue #11's target ratio at N = 64 against that average; the benchmark
 *   measures 0.02–0.05, and the point model on footprint samples about 0.5); its glossy error
 *   below the point probe's and below the lobe-weighted average of the footprint samples;
 * - every pyramid sample within `pyramidMax` of the exact one (largest channel error over the
 *   largest channel: src/envmap.rs documents at most 5.7·10⁻³ on clamped maps for S ≤ 64).
 */
const CHECK = {
  map: "apartment", lighting: "clamp", n: 64, e: 20, diffuseMax: 0.2, glossyMax: 0.6,
  footprintRatio: 0.1, pyramidMax: 0.01,
};
/** `map_footprint_samples` samplers: exact (every pixel) and the mip pyramid (approximate). */
const SAMPLERS = { exact: 0, pyramid: 1 };
/** Rotation seeds of the BMC probe (`bmc_shade`); figures are means over them. */
const SEEDS = [1, 2, 3, 4, 5, 6, 7, 8];

const $ = (id) => document.getElementById(id);
const lum = (r, g, b) => 0.2126 * r + 0.7152 * g + 0.0722 * b;

// ---------------------------------------------------------------------------------------------
// Radiance RGBE (.hdr) decoding: flat or new-style RLE scanlines, `-Y h +X w` only.

function decodeHdr(bytes) {
  let p = 0;
  const line = () => {
    let s = "";
    while (p < bytes.length && bytes[p] !== 0x0a) s += String.fromCharCode(bytes[p++]);
    p++;
    return s;
  };
  if (!line().startsWith("#?")) throw new Error("not a Radiance .hdr file");
  for (let l = line(); l !== ""; l = line()) {
    if (l.startsWith("FORMAT=") && l !== "FORMAT=32-bit_rle_rgbe") throw new Error(`unsupported ${l}`);
  }
  const m = /^-Y (\d+) \+X (\d+)$/.exec(line());
  if (!m) throw new Error("unsupported .hdr orientation");
  const h = Number(m[1]);
  const w = Number(m[2]);
  const rgb = new Float32Array(w * h * 3);
  const scan = new Uint8Array(4 * w);
  for (let y = 0; y < h; y++) {
    if (w >= 8 && w < 32768 && bytes[p] === 2 && bytes[p + 1] === 2 && (bytes[p + 2] & 0x80) === 0) {
      if (((bytes[p + 2] << 8) | bytes[p + 3]) !== w) throw new Error("bad RLE scanline width");
      p += 4;
      for (let c = 0; c < 4; c++) {
        for (let x = 0; x < w; ) {
          let count = bytes[p++];
          if (count > 128) {
            count -= 128;
            if (x + count > w) throw new Error("bad RLE run");
            const v = bytes[p++];
            for (let k = 0; k < count; k++) scan[4 * x++ + c] = v;
          } else {
            if (count === 0 || x + count > w) throw new Error("bad RLE dump");
            for (let k = 0; k < count; k++) scan[4 * x++ + c] = bytes[p++];
          }
        }
      }
    } else {
      scan.set(bytes.subarray(p, p + 4 * w));
      p += 4 * w;
    }
    if (p > bytes.length) throw new Error("truncated .hdr");
    for (let x = 0; x < w; x++) {
      const e = scan[4 * x + 3];
      const f = e === 0 ? 0 : 2 ** (e - 136);
      const o = 3 * (y * w + x);
      rgb[o] = scan[4 * x] * f;
      rgb[o + 1] = scan[4 * x + 1] * f;
      rgb[o + 2] = scan[4 * x + 2] * f;
    }
  }
  return { w, h, rgb };
}

/** The map plus, per pixel, its centre direction and its radiance × solid angle. */
function prepareMap({ w, h, rgb }) {
  const n = w * h;
  const dx = new Float32Array(n), dy = new Float32Array(n), dz = new Float32Array(n);
  const wr = new Float32Array(n), wg = new Float32Array(n), wb = new Float32Array(n);
  const dTheta = Math.PI / h, dPhi = (2 * Math.PI) / w;
  for (let v = 0; v < h; v++) {
    const theta = (Math.PI * (v + 0.5)) / h;
    const st = Math.sin(theta), ct = Math.cos(theta);
    const omega = st * dTheta * dPhi;
    for (let u = 0; u < w; u++) {
      const phi = (2 * Math.PI * (u + 0.5)) / w;
      const i = v * w + u;
      dx[i] = st * Math.cos(phi);
      dy[i] = st * Math.sin(phi);
      dz[i] = ct;
      wr[i] = rgb[3 * i] * omega;
      wg[i] = rgb[3 * i + 1] * omega;
      wb[i] = rgb[3 * i + 2] * omega;
    }
  }
  return { w, h, rgb, dx, dy, dz, wr, wg, wb };
}

/** Nearest-pixel radiance index (times 3) in direction (x, y, z) (unit). */
function pixelOf(map, x, y, z) {
  const theta = Math.acos(Math.min(1, Math.max(-1, z)));
  let phi = Math.atan2(y, x);
  if (phi < 0) phi += 2 * Math.PI;
  const v = Math.min(map.h - 1, Math.floor((theta / Math.PI) * map.h));
  const u = Math.min(map.w - 1, Math.floor((phi / (2 * Math.PI)) * map.w));
  return 3 * (v * map.w + u);
}

// ---------------------------------------------------------------------------------------------
// The sphere: orthographic camera on the −y axis looking along +y, screen up = +z.

/** Per grid cell: normal and mirror direction (about the view vector (0, −1, 0)), or null. */
function sphereCells() {
  const cells = [];
  for (let j = 0; j < G; j++) {
    for (let i = 0; i < G; i++) {
      const sx = ((i + 0.5) / G) * 2 - 1;
      const sy = 1 - ((j + 0.5) / G) * 2;
      const q = 1 - sx * sx - sy * sy;
      if (q <= 0) {
        cells.push(null);
        continue;
      }
      const n = [sx, -Math.sqrt(q), sy];
      const ndv = -n[1]; // n · (0, −1, 0)
      const r = [2 * ndv * n[0], 2 * ndv * n[1] + 1, 2 * ndv * n[2]];
      const rl = Math.hypot(r[0], r[1], r[2]);
      cells.push({ k: j * G + i, n, r: [r[0] / rl, r[1] / rl, r[2] / rl] });
    }
  }
  return cells;
}

/** Reference (all pixels): diffuse irradiance / π, or normalised Phong radiance (e ≥ 0). */
function reference(map, cells, e) {
  const out = new Float32Array(3 * G * G).fill(NaN);
  const { dx, dy, dz, wr, wg, wb } = map;
  const len = dx.length;
  for (const c of cells) {
    if (!c) continue;
    const [ax, ay, az] = e === null ? c.n : c.r;
    let r = 0, g = 0, b = 0;
    for (let i = 0; i < len; i++) {
      const t = ax * dx[i] + ay * dy[i] + az * dz[i];
      if (t <= 0) continue;
      const f = e === null ? t : t ** e;
      r += f * wr[i];
      g += f * wg[i];
      b += f * wb[i];
    }
    const s = e === null ? 1 / Math.PI : (e + 1) / (2 * Math.PI);
    out[3 * c.k] = r * s;
    out[3 * c.k + 1] = g * s;
    out[3 * c.k + 2] = b * s;
  }
  return out;
}

/** QMC per pixel: N lobe-distributed directions from wasm for every cell, radiance from JS. */
function qmcPerPixel(wasm, map, cells, n, e) {
  const out = new Float32Array(3 * G * G).fill(NaN);
  const w = wasm;
  for (const c of cells) {
    if (!c) continue;
    // A fixed, distinct rotation phase per cell (as a renderer would randomise per pixel).
    const lo = Math.imul(c.k + 1, 0x9e3779b9) >>> 0;
    const hi = Math.imul(c.k + 1 + (e === null ? 0 : 0x5bd1), 0x85ebca6b) >>> 0;
    const [x, y, z] = e === null ? c.n : c.r;
    const got = e === null ? w.probe_directions(x, y, z, lo, hi, n) : w.probe_directions_phong(x, y, z, e, lo, hi, n);
    if (got !== n) throw new Error(`probe directions returned ${got}, expected ${n}`);
    const dirs = new Float32Array(w.memory.buffer, w.dirs_ptr(), 3 * n);
    const samples = new Float32Array(w.memory.buffer, w.samples_ptr(), n);
    const idx = new Int32Array(n);
    for (let j = 0; j < n; j++) idx[j] = pixelOf(map, dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]);
    for (let ch = 0; ch < 3; ch++) {
      for (let j = 0; j < n; j++) samples[j] = map.rgb[idx[j] + ch];
      const v = e === null ? w.probe_estimate(x, y, z, lo, hi, n) / Math.PI : w.probe_estimate_phong(x, y, z, e, lo, hi, n);
      out[3 * c.k + ch] = v;
    }
  }
  return out;
}

/**
 * One Bayesian Monte Carlo probe for the whole sphere, through the JavaScript package
 * (examples/wasm/package, `Probe` of its module for N): its N directions (rotation `seed`), JS
 * writes the N RGB radiance samples there (the nearest pixel), `update`, then `irradiance`
 * about each cell's normal and `glossy` (normalised Phong) about its mirror direction. The same
 * N samples also feed the peers a probe would otherwise use: the cosine-weighted average
 * (diffuse) and the Phong-lobe-weighted average (glossy).
 */
async function bmcProbe(map, cells, n, e, seed) {
  const probe = await Probe.create({ n, seed });
  try {
    const dirs = probe.directions();
    const ys = new Float32Array(3 * n);
    for (let j = 0; j < n; j++) {
      const i = pixelOf(map, dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]);
      for (let ch = 0; ch < 3; ch++) ys[3 * j + ch] = map.rgb[i + ch];
    }
    probe.update(ys);
    const live = cells.filter((c) => c);
    const shaded = new Float32Array(6 * live.length);
    live.forEach((c, q) => {
      shaded.set(probe.irradiance(c.n).value, 6 * q);
      shaded.set(probe.glossy(c.r, e).value, 6 * q + 3);
    });
    return { ...shadeAndAverage(cells, n, e, dirs, ys, shaded), ys, shaded };
  } finally {
    probe.dispose();
  }
}

/**
 * The same probe through the module's own `bmc_shade` export (the crate's probe, one call for
 * every cell): the page checks that the package answers bit for bit as it does.
 */
function bmcShade(wasm, cells, n, e, seed, ys) {
  return shadeWith(wasm, "bmc_shade", cells, n, e, seed, ys);
}

/** Writes the map into the module's map buffer (once per map and lighting). */
let loadedMap = null;
function loadMap(wasm, map) {
  if (loadedMap === map) return;
  if (map.w * map.h > wasm.map_max()) throw new Error(`map larger than map_max() = ${wasm.map_max()}`);
  new Float32Array(wasm.memory.buffer, wasm.map_ptr(), map.rgb.length).set(map.rgb);
  loadedMap = map;
}

/** The footprint samples of the loaded map at the current directions, and the time taken. */
function footprintSamples(wasm, map, n, sampler) {
  const w = wasm;
  const t0 = performance.now();
  const code = w.map_footprint_samples(map.w, map.h, n, w.footprint_sharpness(n), sampler);
  const ms = performance.now() - t0;
  if (code !== 0) throw new Error(`map_footprint_samples returned error code ${code}`);
  return { ys: new Float32Array(w.memory.buffer, w.samples_ptr(), 3 * n).slice(), ms };
}

/**
 * The footprint probe `Probe<N, [f32; 3], Gaussian<N/8>>` for the whole sphere: wasm gives its
 * directions (rotation `seed`, the same as the point probe's), takes the footprint samples of
 * the map (each the map filtered by the normalised spherical Gaussian of sharpness N/8 about
 * its direction) with each sampler of `samplers`, and one `footprint_shade` call per sampler
 * answers every cell; plus the weighted averages of the same footprint samples. Also the
 * largest deviation of the pyramid's samples from the exact ones when both were taken.
 */
function footprintProbe(wasm, map, cells, n, e, seed, samplers) {
  const w = wasm;
  loadMap(w, map);
  const got = w.footprint_shade_directions(n, seed);
  if (got !== n) throw new Error(`footprint_shade_directions returned ${got}, expected ${n}`);
  const dirs = new Float32Array(w.memory.buffer, w.dirs_ptr(), 3 * n).slice();
  const taken = samplers.map((sampler) => footprintSamples(w, map, n, sampler));
  let deviation = NaN;
  if (taken.length === 2) {
    deviation = 0;
    const [a, b] = taken.map((t) => t.ys);
    for (let j = 0; j < n; j++) {
      const top = Math.max(...a.subarray(3 * j, 3 * j + 3).map(Math.abs));
      for (let ch = 0; ch < 3; ch++) deviation = Math.max(deviation, Math.abs(b[3 * j + ch] - a[3 * j + ch]) / top);
    }
  }
  const out = taken.map(({ ys, ms }) => ({
    ...shadeAndAverage(cells, n, e, dirs, ys, shadeWith(w, "footprint_shade", cells, n, e, seed, ys)),
    ms,
  }));
  return { out, deviation };
}

/**
 * Writes `ys` into the module's sample buffer and the cells' normal and mirror direction into
 * its query buffer, calls `shade` (`bmc_shade` or `footprint_shade`) and returns its answers:
 * irradiance RGB and glossy RGB per live cell.
 */
function shadeWith(wasm, shade, cells, n, e, seed, ys) {
  const w = wasm;
  new Float32Array(w.memory.buffer, w.samples_ptr(), 3 * n).set(ys);
  const live = cells.filter((c) => c);
  const queries = new Float32Array(w.memory.buffer, w.queries_ptr(), 6 * live.length);
  live.forEach((c, q) => {
    queries.set(c.n, 6 * q);
    queries.set(c.r, 6 * q + 3);
  });
  const code = w[shade](n, seed, live.length, e);
  if (code !== 0) throw new Error(`${shade} returned error code ${code}`);
  return new Float32Array(w.memory.buffer, w.shaded_ptr(), 6 * live.length).slice();
}

/**
 * The probe's pictures (`dp` diffuse, `gp` glossy) from `shaded` (irradiance RGB and glossy
 * RGB per live cell) and those of the weighted averages of `ys` (RGB at `dirs`; `da`, `ga`).
 */
function shadeAndAverage(cells, n, e, dirs, ys, shaded) {
  const live = cells.filter((c) => c);
  const dp = new Float32Array(3 * G * G).fill(NaN);
  const gp = new Float32Array(3 * G * G).fill(NaN);
  const da = new Float32Array(3 * G * G).fill(NaN);
  const ga = new Float32Array(3 * G * G).fill(NaN);
  live.forEach((c, q) => {
    let dw = 0, gw = 0;
    const ds = [0, 0, 0], gs = [0, 0, 0];
    for (let j = 0; j < n; j++) {
      const x = dirs[3 * j], y = dirs[3 * j + 1], z = dirs[3 * j + 2];
      const cn = Math.max(0, c.n[0] * x + c.n[1] * y + c.n[2] * z);
      const cr = Math.max(0, c.r[0] * x + c.r[1] * y + c.r[2] * z) ** e;
      dw += cn;
      gw += cr;
      for (let ch = 0; ch < 3; ch++) {
        ds[ch] += cn * ys[3 * j + ch];
        gs[ch] += cr * ys[3 * j + ch];
      }
    }
    for (let ch = 0; ch < 3; ch++) {
      dp[3 * c.k + ch] = shaded[6 * q + ch] / Math.PI;
      gp[3 * c.k + ch] = shaded[6 * q + 3 + ch];
      da[3 * c.k + ch] = dw > 0 ? ds[ch] / dw : 0;
      ga[3 * c.k + ch] = gw > 0 ? gs[ch] / gw : 0;
    }
  });
  return { dp, gp, da, ga };
}

/** RMSE of luminance over the sphere's cells / mean |reference luminance|. */
function relRmse(est, ref) {
  let se = 0, sa = 0, m = 0;
  for (let k = 0; k < G * G; k++) {
    if (Number.isNaN(ref[3 * k])) continue;
    const a = lum(est[3 * k], est[3 * k + 1], est[3 * k + 2]);
    const b = lum(ref[3 * k], ref[3 * k + 1], ref[3 * k + 2]);
    se += (a - b) ** 2;
    sa += Math.abs(b);
    m++;
  }
  return Math.sqrt(se / m) / (sa / m);
}

/** Draws a G×G RGB grid (Reinhard tone map at `scale`, sRGB-ish gamma), upsampled. */
function draw(canvas, img, scale) {
  const small = document.createElement("canvas");
  small.width = small.height = G;
  const ctx = small.getContext("2d");
  const id = ctx.createImageData(G, G);
  for (let k = 0; k < G * G; k++) {
    if (Number.isNaN(img[3 * k])) continue;
    for (let ch = 0; ch < 3; ch++) {
      const v = img[3 * k + ch] * scale;
      id.data[4 * k + ch] = Math.round(255 * Math.pow(v / (1 + v), 1 / 2.2));
    }
    id.data[4 * k + 3] = 255;
  }
  ctx.putImageData(id, 0, 0);
  canvas.width = canvas.height = 256;
  const big = canvas.getContext("2d");
  big.imageSmoothingEnabled = true;
  big.imageSmoothingQuality = "high";
  big.clearRect(0, 0, 256, 256);
  big.drawImage(small, 0, 0, 256, 256);
}

function meanLum(img) {
  let s = 0, m = 0;
  for (let k = 0; k < G * G; k++) {
    if (Number.isNaN(img[3 * k])) continue;
    s += lum(img[3 * k], img[3 * k + 1], img[3 * k + 2]);
    m++;
  }
  return s / m;
}

// ---------------------------------------------------------------------------------------------

const maps = new Map();
const refs = new Map();
const cells = sphereCells();

/**
 * The `clamp` lighting of eval/src/bin/accuracy.rs: luminance clamped at 30 × the map's
 * solid-angle mean (the sun and lamps are direct light that a renderer samples separately).
 */
function clampMap({ w, h, rgb }) {
  let sum = 0, omega = 0;
  for (let v = 0; v < h; v++) {
    const st = Math.sin((Math.PI * (v + 0.5)) / h);
    for (let u = 0; u < w; u++) {
      const o = 3 * (v * w + u);
      sum += st * lum(rgb[o], rgb[o + 1], rgb[o + 2]);
      omega += st;
    }
  }
  const cap = (30 * sum) / omega;
  const out = new Float32Array(rgb.length);
  for (let o = 0; o < rgb.length; o += 3) {
    const l = lum(rgb[o], rgb[o + 1], rgb[o + 2]);
    const f = l > cap ? cap / l : 1;
    out[o] = rgb[o] * f;
    out[o + 1] = rgb[o + 1] * f;
    out[o + 2] = rgb[o + 2] * f;
  }
  return { w, h, rgb: out };
}

/** The map `name` under `lighting` ("raw" or "clamp"), decoded once. */
async function getMap(name, lighting) {
  const key = `${name}|${lighting}`;
  if (!maps.has(key)) {
    if (!maps.has(name)) {
      const res = await fetch(`../envmaps/${name}.hdr`);
      if (!res.ok) throw new Error(`${name}.hdr: HTTP ${res.status}`);
      maps.set(name, decodeHdr(new Uint8Array(await res.arrayBuffer())));
    }
    const raw = maps.get(name);
    maps.set(key, prepareMap(lighting === "clamp" ? clampMap(raw) : raw));
  }
  return maps.get(key);
}

function getRef(name, map, e) {
  const key = `${name}|${map.lighting}|${e}`;
  if (!refs.has(key)) refs.set(key, reference(map, cells, e));
  return refs.get(key);
}

/**
 * Every estimator on one map: the mean relative RMSE over SEEDS probe rotations of the point
 * probe, the footprint probe (one per sampler of `samplers`) and the weighted averages of
 * their samples, QMC per pixel, and the pictures of the first rotation (footprint: the first
 * sampler).
 */
async function evaluate(wasm, name, lighting, n, e, samplers) {
  const map = await getMap(name, lighting);
  map.lighting = lighting;
  const t0 = performance.now();
  const dr = getRef(name, map, null);
  const gr = getRef(name, map, e);
  const t1 = performance.now();
  // One probe orientation is one random draw: the figures average SEEDS rotations; the
  // pictures show the first.
  const mean = () => ({ d: 0, g: 0 });
  const err = { bmc: mean(), avg: mean(), fpAvg: mean(), fp: samplers.map(mean) };
  const add = (acc, p) => {
    acc.d += relRmse(p.dp, dr) / SEEDS.length;
    acc.g += relRmse(p.gp, gr) / SEEDS.length;
  };
  let first = null;
  let deviation = 0;
  // The package's answers against the module's `bmc_shade` for the first rotation, bit for bit.
  const identical = { same: 0, total: 0 };
  const ms = { point: 0, samples: samplers.map(() => 0), footprint: 0 };
  for (const seed of SEEDS) {
    const ta = performance.now();
    const b = await bmcProbe(map, cells, n, e, seed);
    const tb = performance.now();
    if (seed === SEEDS[0]) {
      const want = new Uint32Array(bmcShade(wasm, cells, n, e, seed, b.ys).buffer);
      const got = new Uint32Array(b.shaded.buffer);
      identical.total += want.length;
      identical.same += want.filter((v, i) => v === got[i] && got.length === want.length).length;
    }
    const tc = performance.now();
    const f = footprintProbe(wasm, map, cells, n, e, seed, samplers);
    ms.footprint += (performance.now() - tc) / SEEDS.length;
    ms.point += (tb - ta) / SEEDS.length;
    f.out.forEach((o, i) => (ms.samples[i] += o.ms / SEEDS.length));
    if (samplers.length === 2) deviation = Math.max(deviation, f.deviation);
    add(err.bmc, b);
    add(err.avg, { dp: b.da, gp: b.ga });
    f.out.forEach((o, i) => add(err.fp[i], o));
    add(err.fpAvg, { dp: f.out[0].da, gp: f.out[0].ga });
    first ??= { b, f: f.out[0] };
  }
  const t2 = performance.now();
  const dq = qmcPerPixel(wasm, map, cells, n, null);
  const gq = qmcPerPixel(wasm, map, cells, n, e);
  const t3 = performance.now();
  const sampler = (i) => Object.keys(SAMPLERS).find((k) => SAMPLERS[k] === samplers[i]);
  const s = wasm.footprint_sharpness(n);
  return {
    dr, gr, dq, gq, first, err, deviation, ms, identical,
    rows: [
      ["BMC probe, point samples (JS package)", err.bmc.d, err.bmc.g],
      ["weighted average of the point samples", err.avg.d, err.avg.g],
      ...samplers.map((_, i) => [`BMC probe, footprint samples (S = ${s}, ${sampler(i)})`, err.fp[i].d, err.fp[i].g]),
      [`weighted average of the footprint samples (${sampler(0)})`, err.fpAvg.d, err.fpAvg.g],
      ["QMC per pixel (N samples each)", relRmse(dq, dr), relRmse(gq, gr)],
    ],
    refMs: t1 - t0, qmcMs: t3 - t2,
  };
}

const pct = (x) => `${(100 * x).toFixed(2)} %`;

async function show(wasm) {
  const name = $("map").value;
  const lighting = $("lighting").value;
  const n = Number($("n").value);
  const e = Number($("e").value);
  const sampler = $("sampler").value;
  $("status").textContent = `computing ${name} (${lighting}), N = ${n}, e = ${e}…`;
  await new Promise((r) => setTimeout(r, 0));
  const r = await evaluate(wasm, name, lighting, n, e, [SAMPLERS[sampler]]);
  const { b, f } = r.first;
  const sd = 0.5 / meanLum(r.dr);
  const sg = 0.8 / meanLum(r.gr);
  for (const [id, img, sc] of [
    ["diffuse-bmc", b.dp, sd], ["diffuse-fp", f.dp, sd], ["diffuse-avg", b.da, sd], ["diffuse-fpavg", f.da, sd],
    ["diffuse-qmc", r.dq, sd], ["diffuse-ref", r.dr, sd],
    ["glossy-bmc", b.gp, sg], ["glossy-fp", f.gp, sg], ["glossy-avg", b.ga, sg], ["glossy-fpavg", f.ga, sg],
    ["glossy-qmc", r.gq, sg], ["glossy-ref", r.gr, sg],
  ]) draw($(id), img, sc);
  $("sharpness").textContent = String(wasm.footprint_sharpness(n));
  $("stats").innerHTML = r.rows
    .map(([what, d, g]) => `<tr><td>${what}</td><td>${name} (${lighting})</td><td>${n}</td><td>${e}</td><td>${pct(d)}</td><td>${pct(g)}</td></tr>`)
    .join("");
  $("status").textContent =
    `reference ${r.refMs.toFixed(0)} ms (cached after first use); per orientation: point probe (JS package) ${r.ms.point.toFixed(0)} ms, ` +
    `footprint probe ${r.ms.footprint.toFixed(0)} ms (of which ${sampler} sampling ${r.ms.samples[0].toFixed(0)} ms); ` +
    `QMC per pixel ${r.qmcMs.toFixed(0)} ms`;
}

/** The package's exceptions in the browser: each `[ok, what]`. */
async function packageErrors() {
  const code = async (f) => {
    try {
      await f();
    } catch (e) {
      return e instanceof ProbeError ? e.code : `not a ProbeError: ${e}`;
    }
    return "nothing thrown";
  };
  const p = await Probe.create({ n: 16, seed: 1 });
  const bad = new Float32Array(48).fill(1);
  bad[7] = NaN;
  const got = [
    ["InvalidSize", await code(() => Probe.create({ n: 48 }))],
    ["InvalidRadiance", await code(() => p.update(bad))],
    ["LengthMismatch", await code(() => p.update(new Float32Array(16)))],
    ["InvalidDirection", await code(() => p.irradiance([0, 0, 0]))],
    ["InvalidExponent", await code(() => p.glossy([0, 0, 1], -1))],
  ];
  p.dispose();
  got.push(["InvalidHandle", await code(() => p.directions())]);
  return got.map(([want, c]) => [want === c, c]);
}

async function check(wasm) {
  // Every bundled map: one map is one noisy comparison (the benchmark's claim, and the
  // issue's target, are about the mean over maps).
  const rows = [];
  const samplers = [SAMPLERS.exact, SAMPLERS.pyramid];
  const ms = [0, 0];
  const identical = { same: 0, total: 0 };
  const errors = await packageErrors();
  for (const name of MAPS) {
    $("check").textContent = `check: running (${name})…`;
    const r = await evaluate(wasm, name, CHECK.lighting, CHECK.n, CHECK.e, samplers);
    const { bmc, avg, fp, fpAvg } = r.err;
    rows.push({
      name, bd: bmc.d, bg: bmc.g, ad: avg.d, ag: avg.g, fd: fp[0].d, fg: fp[0].g, pd: fp[1].d, pg: fp[1].g,
      fad: fpAvg.d, fag: fpAvg.g, dev: r.deviation,
    });
    r.ms.samples.forEach((t, i) => (ms[i] += t / MAPS.length));
    identical.same += r.identical.same;
    identical.total += r.identical.total;
  }
  const keys = ["bd", "bg", "ad", "ag", "fd", "fg", "pd", "pg", "fad", "fag"];
  const m = Object.fromEntries(keys.map((k) => [k, rows.reduce((s, r) => s + r[k], 0) / rows.length]));
  m.dev = Math.max(...rows.map((r) => r.dev));
  const home = rows.find((r) => r.name === CHECK.map);
  const pointBound = CHECK.footprintRatio * Math.min(m.bd, m.ad);
  const verdicts = [
    [m.bd < m.ad && m.bg < m.ag, "point probe below the weighted averages (diffuse and glossy)"],
    [home.bd < CHECK.diffuseMax && home.bg < CHECK.glossyMax, `point probe on ${CHECK.map} below ${pct(CHECK.diffuseMax)} / ${pct(CHECK.glossyMax)}`],
    [m.fd <= pointBound && m.pd <= pointBound,
      `footprint probe diffuse (exact ${pct(m.fd)}, pyramid ${pct(m.pd)}) at most ${CHECK.footprintRatio} × min(point probe, ` +
      `cosine-weighted average of point samples) = ${pct(pointBound)}`],
    [m.fg < m.bg && m.fg < m.fag && m.pg < m.bg && m.pg < m.fag,
      "footprint probe glossy (exact and pyramid) below the point probe's and the lobe-weighted average of the footprint samples"],
    [identical.total > 0 && identical.same === identical.total,
      `JS package's probe equals the module's bmc_shade bit for bit (${identical.same} of ${identical.total} values, first rotation of each map)`],
    [errors.every(([ok]) => ok), `JS package throws ProbeError (${errors.map(([ok, what]) => `${what}${ok ? "" : " ✗"}`).join(", ")})`],
    [m.dev <= CHECK.pyramidMax, `pyramid samples within ${pct(CHECK.pyramidMax)} of the exact ones (worst ${(100 * m.dev).toFixed(3)} %)`],
  ];
  const pass = verdicts.every(([ok]) => ok);
  const ratio = (a, b) => (a / b).toFixed(3);
  $("check-table").innerHTML =
    "<tr><th rowspan=2>map</th><th colspan=6>diffuse</th><th colspan=5>glossy</th><th rowspan=2>pyramid<br>deviation</th></tr>" +
    "<tr><th>point BMC</th><th>cos avg<br>(point)</th><th>footprint BMC<br>(exact)</th><th>footprint BMC<br>(pyramid)</th>" +
    "<th>cos avg<br>(footprint)</th><th>footprint /<br>cos avg (point)</th>" +
    "<th>point BMC</th><th>lobe avg<br>(point)</th><th>footprint BMC<br>(exact)</th><th>footprint BMC<br>(pyramid)</th><th>lobe avg<br>(footprint)</th></tr>" +
    [...rows, { name: "mean", ...m }]
      .map((r) => `<tr><td>${r.name}</td><td>${pct(r.bd)}</td><td>${pct(r.ad)}</td><td>${pct(r.fd)}</td><td>${pct(r.pd)}</td>` +
        `<td>${pct(r.fad)}</td><td>${ratio(r.fd, r.ad)}</td><td>${pct(r.bg)}</td><td>${pct(r.ag)}</td><td>${pct(r.fg)}</td>` +
        `<td>${pct(r.pg)}</td><td>${pct(r.fag)}</td><td>${(100 * r.dev).toFixed(3)} %</td></tr>`)
      .join("");
  const el = $("check");
  el.dataset.diffuse = String(m.bd);
  el.dataset.glossy = String(m.bg);
  el.dataset.diffuseAverage = String(m.ad);
  el.dataset.glossyAverage = String(m.ag);
  el.dataset.footprintDiffuse = String(m.fd);
  el.dataset.footprintGlossy = String(m.fg);
  el.dataset.pyramidDiffuse = String(m.pd);
  el.dataset.pyramidGlossy = String(m.pg);
  el.dataset.footprintAverageDiffuse = String(m.fad);
  el.dataset.footprintAverageGlossy = String(m.fag);
  el.dataset.pyramidDeviation = String(m.dev);
  el.dataset.packageIdentical = `${identical.same}/${identical.total}`;
  el.dataset.packageErrors = JSON.stringify(errors);
  el.dataset.samplingMs = JSON.stringify({ exact: ms[0], pyramid: ms[1] });
  el.dataset.perMap = JSON.stringify(rows);
  el.dataset.pass = String(pass);
  el.textContent =
    `check ${pass ? "PASSED" : "FAILED"} (all ${rows.length} maps, ${CHECK.lighting}, N = ${CHECK.n}, ` +
    `footprint S = ${wasm.footprint_sharpness(CHECK.n)}, e = ${CHECK.e}, ${G}×${G} grid, ${SEEDS.length} probe rotations each; ` +
    `mean relRMSE diffuse / glossy): point probe ${pct(m.bd)} / ${pct(m.bg)}, weighted averages of the point samples ` +
    `${pct(m.ad)} / ${pct(m.ag)}; footprint probe ${pct(m.fd)} / ${pct(m.fg)} (pyramid samples ${pct(m.pd)} / ${pct(m.pg)}), ` +
    `weighted averages of the footprint samples ${pct(m.fad)} / ${pct(m.fag)}; sampling ${ms[0].toFixed(0)} ms exact, ` +
    `${ms[1].toFixed(0)} ms pyramid per probe. ` +
    verdicts.map(([ok, what]) => `${ok ? "✓" : "✗"} ${what}`).join("; ");
}

async function main() {
  $("grid-size").textContent = `${G}×${G}`;
  for (const m of MAPS) $("map").add(new Option(m, m, m === CHECK.map, m === CHECK.map));
  const res = await fetch(WASM);
  if (!res.ok) throw new Error(`${WASM}: HTTP ${res.status} (build the module first)`);
  const { instance } = await WebAssembly.instantiate(await res.arrayBuffer(), {});
  const wasm = instance.exports;
  if (wasm.probe_max() < 1024) throw new Error(`probe_max() = ${wasm.probe_max()}`);
  if (cells.filter((c) => c).length > 1024) throw new Error("more cells than bmc_shade takes");
  await show(wasm);
  await check(wasm);
  $("check").dataset.done = "true";
  for (const id of ["map", "lighting", "n", "e", "sampler"]) {
    $(id).addEventListener("change", () => show(wasm).catch(fail));
  }
}

function fail(err) {
  const el = $("check");
  el.dataset.pass = "false";
  el.dataset.error = String(err);
  el.textContent = `check FAILED: ${err}`;
  el.dataset.done = "true";
  $("status").textContent = "error";
}

main().catch(fail);
