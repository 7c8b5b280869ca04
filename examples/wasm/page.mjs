// The browser page of examples/wasm (index.html): shades a sphere from a bundled environment
// map with one Bayesian Monte Carlo probe of N samples (diffuse irradiance + normalised Phong
// glossy, N selectable), from point samples and from footprint samples (the module filters
// the map with a spherical Gaussian of sharpness N/8 about each direction), next to the
// weighted averages of the same samples, QMC with N samples per pixel, and a brute-force
// reference over every map pixel; a temporal probe updated again and again on the same map
// and then on another (a switch of the light) next to DDGI's blend of the same rays; and runs
// the page's own numeric check (see CHECK and TEMPORAL).
// Served from the repository root (examples/wasm/browser_test.mjs does that), so the map is at
// ../envmaps/<name>.hdr and the module at target/… relative to this page.

import { Probe, ProbeError, TemporalProbe } from "./package/index.js";

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
/**
 * The temporal view and its check: a `TemporalProbe` (point samples, through the package) and
 * DDGI v1.3.7's blend (`ddgiBlend`) get the same N rays per update, `static` updates of a map
 * and then `after` updates of the next map in MAPS (cyclically), each map scaled to a mean
 * irradiance of 1 (DDGI's thresholds are absolute, as in eval/src/bin/temporal.rs). The error
 * is the page's relative RMSE of luminance over the sphere's normals, per update. The check
 * runs every map at clamp, N = `n`, for each seed of `seeds`, and requires (means over maps
 * and seeds):
 * - every curve finite;
 * - on static light: the temporal probe's error after `static` updates at most `converged`
 *   times its error after one (pooling: the running mean of the samples' cosine-weighted
 *   averages falls like 1/√k, 0.18× from 1 to 32 updates), below DDGI's there, and no reset;
 * - after the switch: the temporal probe reports a reset within two updates in at least
 *   `detected` of the runs, its error `lag` updates after the switch is below DDGI's (whose
 *   hysteresis and brightness limit make it lag), and its error after `after` updates is at
 *   most `converged` times its error at the switch.
 */
const TEMPORAL = {
  n: 64, static: 32, after: 32, seeds: [1, 2], converged: 0.5, detected: 0.8, lag: 4,
  thresholds: [0.25, 0.1],
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

// ---------------------------------------------------------------------------------------------
// Temporal accumulation: the package's TemporalProbe against DDGI's blend on the same rays.

/**
 * DDGI v1.3.7's blend of one texel (RGB irradiance `prev` with the update's `next`), as
 * eval/src/bin/temporal.rs implements it (`ddgi_blend`): in gamma-5 encoded space,
 * hysteresis 0.97, lowered by 0.75 when the largest component of (mean − new) exceeds the
 * irradiance threshold, the change times 0.25 when the luminance of (new − mean) exceeds the
 * brightness threshold, a darkening moving at least 1/1024 per update.
 */
function ddgiBlend(prev, next, [irradianceThreshold, brightnessThreshold]) {
  const enc = (x) => x.map((c) => Math.max(c, 0) ** 0.2);
  const p = enc(prev), r = enc(next);
  const max3 = (x) => Math.max(x[0], x[1], x[2]);
  let hysteresis = 0.97;
  if (max3([p[0] - r[0], p[1] - r[1], p[2] - r[2]]) > irradianceThreshold) hysteresis = Math.max(hysteresis - 0.75, 0);
  let delta = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
  if (lum(delta[0], delta[1], delta[2]) > brightnessThreshold) delta = delta.map((d) => d * 0.25);
  let step = delta.map((d) => (1 - hysteresis) * d);
  if (max3(r) < max3(p)) {
    step = step.map((st, c) => Math.sign(st) * Math.min(Math.max(Math.abs(st), 1 / 1024), Math.abs(delta[c])));
  }
  return [0, 1, 2].map((c) => (p[c] + step[c]) ** 5);
}

/** The factor that scales `map` to a mean irradiance of 1 (luminance). */
function unitIrradianceScale(map) {
  let sum = 0;
  for (let i = 0; i < map.wr.length; i++) sum += lum(map.wr[i], map.wg[i], map.wb[i]);
  return 1 / (Math.PI * (sum / (4 * Math.PI)));
}

/**
 * One run of the temporal view: `lights` (each `{ map, ref, scale }`: the map, its diffuse
 * reference, the factor to mean irradiance 1) for `counts` updates each, N rays per update.
 * The temporal probe samples its N − S rotated directions and S sentinels; DDGI (per sphere
 * normal) and the running mean of the cosine-weighted averages, restarted at the switch,
 * average the same N rays. Per update: the relative RMSE of each, the mean luminance of each
 * over the sphere (and of the truth), what the temporal probe did and its probability of a
 * change; the pictures `picture` updates after the switch.
 */
async function temporalRun(lights, counts, n, seed, picture) {
  const probe = await TemporalProbe.create({ n, seed });
  try {
    const live = cells.filter((c) => c);
    const S = probe.sentinelCount;
    let ddgi = null;
    let mean = null;
    const out = {
      error: { temporal: [], ddgi: [], mean: [] }, level: { truth: [], temporal: [], ddgi: [], mean: [] },
      change: [], probability: [], pictures: null,
    };
    for (const [li, { map, ref, scale }] of lights.entries()) {
      for (let k = 0; k < counts[li]; k++) {
        const dirs = probe.directions();
        const all = new Float32Array(3 * n);
        all.set(dirs);
        all.set(probe.sentinels(), dirs.length);
        const ys = new Float32Array(3 * n);
        for (let j = 0; j < n; j++) {
          const i = pixelOf(map, all[3 * j], all[3 * j + 1], all[3 * j + 2]);
          for (let ch = 0; ch < 3; ch++) ys[3 * j + ch] = map.rgb[i + ch] * scale;
        }
        out.change.push(probe.pool(ys.subarray(0, 3 * (n - S)), ys.subarray(3 * (n - S))));
        out.probability.push(probe.lastChangeProbability);
        // The cosine-weighted average of the N rays about each normal (irradiance units).
        const cos = live.map((c) => {
          let w = 0;
          const e = [0, 0, 0];
          for (let j = 0; j < n; j++) {
            const t = Math.max(0, c.n[0] * all[3 * j] + c.n[1] * all[3 * j + 1] + c.n[2] * all[3 * j + 2]);
            w += t;
            for (let ch = 0; ch < 3; ch++) e[ch] += t * ys[3 * j + ch];
          }
          return e.map((v) => (w > 0 ? (Math.PI * v) / w : 0));
        });
        ddgi = ddgi === null ? cos : ddgi.map((d, q) => ddgiBlend(d, cos[q], TEMPORAL.thresholds));
        mean = k === 0 ? cos.map((e) => e.slice()) : mean.map((o, q) => o.map((v, ch) => v + (cos[q][ch] - v) / (k + 1)));
        // Pictures and errors in the page's units (irradiance / π).
        const img = {};
        for (const m of ["temporal", "ddgi", "mean", "truth"]) img[m] = new Float32Array(3 * G * G).fill(NaN);
        live.forEach((c, q) => {
          const t = probe.irradiance(c.n).value;
          for (let ch = 0; ch < 3; ch++) {
            img.temporal[3 * c.k + ch] = t[ch] / Math.PI;
            img.ddgi[3 * c.k + ch] = ddgi[q][ch] / Math.PI;
            img.mean[3 * c.k + ch] = mean[q][ch] / Math.PI;
            img.truth[3 * c.k + ch] = ref[3 * c.k + ch] * scale;
          }
        });
        for (const m of ["temporal", "ddgi", "mean"]) {
          out.error[m].push(relRmse(img[m], img.truth));
          out.level[m].push(meanLum(img[m]));
        }
        out.level.truth.push(meanLum(img.truth));
        if (li === 1 && k + 1 === picture) out.pictures = img;
      }
    }
    return out;
  } finally {
    probe.dispose();
  }
}

/** The two lights of the temporal view for map `name`: it, then the next map of MAPS. */
async function temporalLights(name, lighting) {
  const next = MAPS[(MAPS.indexOf(name) + 1) % MAPS.length];
  const lights = [];
  for (const m of [name, next]) {
    const map = await getMap(m, lighting);
    map.lighting = lighting;
    lights.push({ name: m, map, ref: getRef(m, map, null), scale: unitIrradianceScale(map) });
  }
  return lights;
}

/** A line plot of `series` (`{ label, color, values, dash }`) against the update, 1-based. */
function plot(canvas, series, { title, ylog = false, switchAt, marks = [] }) {
  const W = 560, H = 260, L = 56, R = 10, T = 24, B = 34;
  canvas.width = W;
  canvas.height = H;
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#fff";
  ctx.fillRect(0, 0, W, H);
  const count = Math.max(...series.map((s) => s.values.length));
  const all = series.flatMap((s) => s.values).filter((v) => Number.isFinite(v) && (!ylog || v > 0));
  let lo = Math.min(...all), hi = Math.max(...all);
  if (ylog) {
    lo = 10 ** Math.floor(Math.log10(lo));
    hi = 10 ** Math.ceil(Math.log10(hi));
  } else {
    lo = Math.min(0, lo);
    hi *= 1.05;
  }
  const f = (v) => (ylog ? Math.log10(v) : v);
  const x = (k) => L + ((k - 1) / Math.max(1, count - 1)) * (W - L - R);
  const y = (v) => T + (1 - (f(v) - f(lo)) / (f(hi) - f(lo))) * (H - T - B);
  ctx.strokeStyle = "#ddd";
  ctx.fillStyle = "#333";
  ctx.font = "11px system-ui, sans-serif";
  ctx.lineWidth = 1;
  const ticks = ylog
    ? Array.from({ length: Math.round(Math.log10(hi / lo)) + 1 }, (_, i) => lo * 10 ** i)
    : Array.from({ length: 5 }, (_, i) => lo + ((hi - lo) * i) / 4);
  for (const v of ticks) {
    ctx.beginPath();
    ctx.moveTo(L, y(v));
    ctx.lineTo(W - R, y(v));
    ctx.stroke();
    ctx.fillText(ylog ? `${+(100 * v).toPrecision(2)} %` : v.toFixed(2), 4, y(v) + 4);
  }
  for (let k = 1; k <= count; k += count > 40 ? 8 : 4) ctx.fillText(String(k), x(k) - 4, H - B + 14);
  ctx.fillText("update", W / 2 - 16, H - 6);
  ctx.font = "600 12px system-ui, sans-serif";
  ctx.fillText(title, 4, 15);
  ctx.font = "11px system-ui, sans-serif";
  if (switchAt) {
    ctx.strokeStyle = "#999";
    ctx.setLineDash([4, 3]);
    ctx.beginPath();
    ctx.moveTo(x(switchAt), T);
    ctx.lineTo(x(switchAt), H - B);
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = "#666";
    ctx.fillText("switch", x(switchAt) + 3, H - B - 10);
  }
  ctx.fillStyle = "#c00";
  for (const k of marks) ctx.fillRect(x(k) - 2, H - B - 6, 4, 6);
  series.forEach((s, i) => {
    ctx.strokeStyle = s.color;
    ctx.lineWidth = 2;
    ctx.setLineDash(s.dash ?? []);
    ctx.beginPath();
    s.values.forEach((v, k) => (k === 0 ? ctx.moveTo(x(k + 1), y(v)) : ctx.lineTo(x(k + 1), y(v))));
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = s.color;
    ctx.fillText(s.label, W - R - 210, T + 12 + 13 * i);
  });
}

/** The temporal view for the selected map, lighting and N; its time per update (ms). */
async function temporalView(name, lighting, n) {
  const lights = await temporalLights(name, lighting);
  const counts = [TEMPORAL.static, TEMPORAL.after];
  const t0 = performance.now();
  const r = await temporalRun(lights, counts, n, TEMPORAL.seeds[0], TEMPORAL.lag);
  const ms = (performance.now() - t0) / (counts[0] + counts[1]);
  const switchAt = counts[0] + 1;
  const resets = r.change.flatMap((c, k) => (c === "reset" ? [k + 1] : []));
  $("temporal-maps").textContent = `${lights[0].name} → ${lights[1].name}`;
  plot($("temporal-error"), [
    { label: "temporal probe (JS package)", color: "#06c", values: r.error.temporal },
    { label: "DDGI blend (same rays)", color: "#d60", values: r.error.ddgi },
    { label: "running mean, restarted at switch", color: "#888", values: r.error.mean, dash: [5, 4] },
  ], { title: `diffuse relRMSE, N = ${n} (red ticks: resets)`, ylog: true, switchAt, marks: resets });
  plot($("temporal-level"), [
    { label: "truth", color: "#000", values: r.level.truth },
    { label: "temporal probe", color: "#06c", values: r.level.temporal },
    { label: "DDGI blend", color: "#d60", values: r.level.ddgi },
  ], { title: "mean luminance of irradiance / π over the sphere", switchAt, marks: resets });
  const sd = 0.5 / meanLum(r.pictures.truth);
  draw($("temporal-probe"), r.pictures.temporal, sd);
  draw($("temporal-ddgi"), r.pictures.ddgi, sd);
  draw($("temporal-ref"), r.pictures.truth, sd);
  const at = (k) => `<td>${pct(r.error.temporal[k - 1])}</td><td>${pct(r.error.ddgi[k - 1])}</td><td>${pct(r.error.mean[k - 1])}</td>`;
  const rows = [
    [1, "1"], [4, "4"], [counts[0], `${counts[0]} (static)`], [switchAt, `${switchAt} (the switch)`],
    [switchAt + TEMPORAL.lag - 1, `${switchAt + TEMPORAL.lag - 1} (${TEMPORAL.lag} after the switch)`],
    [counts[0] + counts[1], `${counts[0] + counts[1]} (${counts[1]} after the switch)`],
  ];
  $("temporal-stats").innerHTML =
    "<tr><th>update</th><th>temporal probe</th><th>DDGI blend</th><th>running mean</th><th>temporal probe: update, P(change)</th></tr>" +
    rows.map(([k, what]) => `<tr><td>${what}</td>${at(k)}<td>${r.change[k - 1]}, ${r.probability[k - 1].toPrecision(2)}</td></tr>`).join("");
  return ms;
}

/** The temporal check over every map (see TEMPORAL): its verdicts, runs and means. */
async function temporalCheck(lighting) {
  const counts = [TEMPORAL.static, TEMPORAL.after];
  const k0 = counts[0], k1 = counts[0] + counts[1], lag = TEMPORAL.lag;
  const runs = [];
  for (const name of MAPS) {
    $("check").textContent = `check: running (temporal, ${name})…`;
    const lights = await temporalLights(name, lighting);
    for (const seed of TEMPORAL.seeds) {
      const r = await temporalRun(lights, counts, TEMPORAL.n, seed, lag);
      const e = r.error;
      runs.push({
        name: `${name} → ${lights[1].name}`, seed,
        t1: e.temporal[0], tStatic: e.temporal[k0 - 1], dStatic: e.ddgi[k0 - 1], tSwitch: e.temporal[k0],
        tLag: e.temporal[k0 + lag - 1], dLag: e.ddgi[k0 + lag - 1], tEnd: e.temporal[k1 - 1], dEnd: e.ddgi[k1 - 1],
        mEnd: e.mean[k1 - 1],
        falseResets: r.change.slice(1, k0).filter((c) => c === "reset").length,
        detected: r.change.slice(k0, k0 + 2).includes("reset"),
        finite: [e.temporal, e.ddgi, e.mean].every((c) => c.length === k1 && c.every(Number.isFinite)),
      });
    }
  }
  const keys = ["t1", "tStatic", "dStatic", "tSwitch", "tLag", "dLag", "tEnd", "dEnd", "mEnd"];
  // Means over a set of runs: the figures, the static resets and the share of detections.
  const summary = (rs) => ({
    ...Object.fromEntries(keys.map((k) => [k, rs.reduce((a, r) => a + r[k], 0) / rs.length])),
    falseResets: rs.reduce((a, r) => a + r.falseResets, 0),
    detected: rs.filter((r) => r.detected).length / rs.length,
  });
  const m = summary(runs);
  const perMap = MAPS.map((name) => ({ name: runs.find((r) => r.name.startsWith(`${name} `)).name, ...summary(runs.filter((r) => r.name.startsWith(`${name} `))) }));
  const C = TEMPORAL;
  const verdicts = [
    [runs.length === MAPS.length * C.seeds.length && runs.every((r) => r.finite),
      `temporal view: every curve finite (${runs.length} runs of ${k1} updates)`],
    [m.tStatic <= C.converged * m.t1,
      `temporal probe converges on static light: ${pct(m.t1)} after 1 update, ${pct(m.tStatic)} after ${k0} (at most ${C.converged}×)`],
    [m.tStatic < m.dStatic, `temporal probe below DDGI's blend after ${k0} static updates (${pct(m.tStatic)} vs ${pct(m.dStatic)})`],
    [m.falseResets === 0, `temporal probe: no reset on static light (${m.falseResets})`],
    [m.detected >= C.detected,
      `temporal probe resets within 2 updates of the switch in ${pct(m.detected)} of the runs (at least ${pct(C.detected)})`],
    [m.tLag < m.dLag, `${lag} updates after the switch the temporal probe is below DDGI's blend (${pct(m.tLag)} vs ${pct(m.dLag)})`],
    [m.tEnd <= C.converged * m.tSwitch,
      `temporal probe converges after the switch: ${pct(m.tSwitch)} at the switch, ${pct(m.tEnd)} ${counts[1]} updates later (at most ${C.converged}×)`],
  ];
  return { verdicts, runs, perMap, m };
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
  const temporalMs = await temporalView(name, lighting, n);
  $("status").textContent =
    `reference ${r.refMs.toFixed(0)} ms (cached after first use); per orientation: point probe (JS package) ${r.ms.point.toFixed(0)} ms, ` +
    `footprint probe ${r.ms.footprint.toFixed(0)} ms (of which ${sampler} sampling ${r.ms.samples[0].toFixed(0)} ms); ` +
    `QMC per pixel ${r.qmcMs.toFixed(0)} ms; temporal view ${temporalMs.toFixed(1)} ms per update`;
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
  const temporal = await temporalCheck(CHECK.lighting);
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
    ...temporal.verdicts,
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
  el.dataset.temporal = JSON.stringify(temporal.m);
  el.dataset.temporalPerMap = JSON.stringify(temporal.perMap);
  const t = temporal.m;
  const keysT = ["t1", "tStatic", "dStatic", "tSwitch", "tLag", "dLag", "tEnd", "dEnd", "mEnd"];
  $("temporal-check-table").innerHTML =
    `<tr><th>map → next<br>(${TEMPORAL.seeds.length} runs each)</th><th>temporal,<br>1 update</th><th>temporal,<br>${TEMPORAL.static} static</th>` +
    `<th>DDGI,<br>${TEMPORAL.static} static</th><th>temporal,<br>at switch</th><th>temporal,<br>+${TEMPORAL.lag}</th>` +
    `<th>DDGI,<br>+${TEMPORAL.lag}</th><th>temporal,<br>+${TEMPORAL.after}</th><th>DDGI,<br>+${TEMPORAL.after}</th>` +
    `<th>running mean,<br>+${TEMPORAL.after}</th><th>reset at<br>switch</th><th>static<br>resets</th></tr>` +
    [...temporal.perMap, { name: "mean", ...t }]
      .map((r) => `<tr><td>${r.name}</td>${keysT.map((k) => `<td>${pct(r[k])}</td>`).join("")}` +
        `<td>${pct(r.detected)}</td><td>${r.falseResets}</td></tr>`)
      .join("");
  el.dataset.pass = String(pass);
  el.textContent =
    `check ${pass ? "PASSED" : "FAILED"} (all ${rows.length} maps, ${CHECK.lighting}, N = ${CHECK.n}, ` +
    `footprint S = ${wasm.footprint_sharpness(CHECK.n)}, e = ${CHECK.e}, ${G}×${G} grid, ${SEEDS.length} probe rotations each; ` +
    `mean relRMSE diffuse / glossy): point probe ${pct(m.bd)} / ${pct(m.bg)}, weighted averages of the point samples ` +
    `${pct(m.ad)} / ${pct(m.ag)}; footprint probe ${pct(m.fd)} / ${pct(m.fg)} (pyramid samples ${pct(m.pd)} / ${pct(m.pg)}), ` +
    `weighted averages of the footprint samples ${pct(m.fad)} / ${pct(m.fag)}; sampling ${ms[0].toFixed(0)} ms exact, ` +
    `${ms[1].toFixed(0)} ms pyramid per probe. Temporal (N = ${TEMPORAL.n}, ${TEMPORAL.static} updates of each map, ` +
    `then ${TEMPORAL.after} of the next, ${TEMPORAL.seeds.length} runs each): ${pct(t.t1)} after 1 update, ${pct(t.tStatic)} ` +
    `after ${TEMPORAL.static} (DDGI ${pct(t.dStatic)}); ${TEMPORAL.lag} after the switch ${pct(t.tLag)} (DDGI ${pct(t.dLag)}), ` +
    `${TEMPORAL.after} after ${pct(t.tEnd)} (DDGI ${pct(t.dEnd)}). ` +
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
