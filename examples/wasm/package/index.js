// sphere-quadrature: RGB Bayesian Monte Carlo lighting probes in WebAssembly (see README.md
// and index.d.ts). One small module per baked probe size N, wasm/probe-N.wasm, and one for
// the layout probes, wasm/layout.wasm, without imports; this file wraps their exports in the
// `Probe`, `TemporalProbe` and `LayoutProbe` classes and turns their error codes into
// `ProbeError` exceptions. Runs in browsers and in Node ≥ 18 (ES module).

/** The baked probe sizes: one module each. */
export const SIZES = Object.freeze([16, 32, 64, 128, 256]);

/** Names and messages of the module's error codes (the Rust `sphere_quadrature::Error`). */
const ERRORS = {
  1: ["InvalidDirection", "direction is zero, not finite, or too short to normalise"],
  2: ["InvalidExponent", "Phong exponent must be finite and non-negative"],
  3: ["LengthMismatch", "array lengths do not match"],
  4: ["InvalidSize", "probe size is not baked"],
  5: ["InvalidParameter", "parameter is outside its documented range"],
  6: ["InvalidSharpness", "SG sharpness must be finite and non-negative"],
  7: ["InvalidRadiance", "radiance sample is NaN or infinite"],
  8: ["TooManyMissing", "too many missing samples"],
  100: ["InvalidHandle", "the probe was disposed"],
};

/** An error of the probe: `code` names the Rust `sphere_quadrature::Error` variant. */
export class ProbeError extends Error {
  /**
   * @param {string} code
   * @param {string} message
   */
  constructor(code, message) {
    super(message);
    this.name = "ProbeError";
    this.code = code;
  }
}

/** Throws the `ProbeError` of a non-zero status `status` from call `what`. */
function check(status, what) {
  if (status === 0) return;
  const [code, message] = ERRORS[status] ?? ["Unknown", `error code ${status}`];
  throw new ProbeError(code, `${what}: ${message}`);
}

/** The exports the package uses (and all a module of the package has, with `memory`). */
const EXPORTS = [
  "memory", "probe_size", "io_ptr", "io_len", "probe_new", "probe_free", "probe_directions",
  "probe_update", "probe_irradiance", "probe_glossy", "probe_radiance_sh", "probe_radiance_sh_variance",
  "probe_three_js_sh",
  "temporal_sentinel_count", "temporal_sharpness", "temporal_new", "temporal_free", "temporal_directions",
  "temporal_sentinels", "temporal_pool", "temporal_irradiance", "temporal_radiance_sh",
  "temporal_radiance_sh_variance", "temporal_state", "temporal_three_js_sh",
];

/** The frames of the probe's directions `threeJsSh` takes: the export's rotation to y-up. */
const FRAMES = { "y-up": 0, "z-up": 1 };

/** The code of `frame` ("y-up" or "z-up"), or a `ProbeError` `InvalidParameter` from `what`. */
function frameCode(frame, what) {
  const code = Object.hasOwn(FRAMES, frame) ? FRAMES[frame] : undefined;
  if (code === undefined) {
    throw new ProbeError("InvalidParameter", `${what}: the frame of the probe's directions must be "y-up" or "z-up", got ${String(frame)}`);
  }
  return code;
}

/** The module `wasm/<file>` beside index.js, or `source` (see `ProbeOptions.wasm`), compiled. */
async function moduleOf(file, source) {
  if (source instanceof WebAssembly.Module) return source;
  if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) return WebAssembly.compile(source);
  if (typeof Response !== "undefined" && source instanceof Response) return compileResponse(source);
  const url = source === undefined ? new URL(`./wasm/${file}`, import.meta.url) : new URL(source, import.meta.url);
  if (url.protocol === "file:") {
    const { readFile } = await import("node:fs/promises");
    return WebAssembly.compile(await readFile(url));
  }
  return compileResponse(await fetch(url));
}

/** Compiles a fetched module (streaming when the server sends `application/wasm`). */
async function compileResponse(res) {
  if (!res.ok) throw new ProbeError("InvalidSize", `${res.url}: HTTP ${res.status}`);
  if (WebAssembly.compileStreaming && res.headers.get("content-type") === "application/wasm") {
    return WebAssembly.compileStreaming(res);
  }
  return WebAssembly.compile(await res.arrayBuffer());
}

/** Instances of the default modules, one per size (a promise each), shared by all probes. */
const instances = new Map();

/** The exports of a module instance for size `n`, checked. */
async function instantiate(n, source) {
  const module = await moduleOf(`probe-${n}.wasm`, source);
  if (WebAssembly.Module.imports(module).length !== 0) {
    throw new ProbeError("InvalidParameter", "the probe module must have no imports");
  }
  const { exports } = await WebAssembly.instantiate(module, {});
  for (const name of EXPORTS) {
    if (!(name in exports)) throw new ProbeError("InvalidParameter", `the probe module lacks the export ${name}`);
  }
  if (exports.probe_size() !== n) {
    throw new ProbeError("InvalidSize", `the module is for N = ${exports.probe_size()}, not ${n}`);
  }
  return exports;
}

/** The checked exports of the module for size `n`: the shared default one, or `wasm`'s. */
async function exportsFor(n, wasm, what) {
  if (!SIZES.includes(n)) throw new ProbeError("InvalidSize", `${what}: no baked probe of size ${n} (sizes ${SIZES.join(", ")})`);
  if (wasm !== undefined) return instantiate(n, wasm);
  if (!instances.has(n)) instances.set(n, instantiate(n));
  try {
    return await instances.get(n);
  } catch (e) {
    instances.delete(n);
    throw e;
  }
}

/** `seed` if it is an integer in [0, 2³²), else an `InvalidParameter` error. */
function checkedSeed(seed, what) {
  if (!Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) {
    throw new ProbeError("InvalidParameter", `${what}: seed must be an integer in [0, 2^32): ${seed}`);
  }
  return seed >>> 0;
}

/** Frees the module's probe when a `Probe` is collected without `dispose()`. */
const collected =
  typeof FinalizationRegistry === "undefined"
    ? null
    : new FinalizationRegistry(({ exports, handle }) => exports.probe_free(handle));

/** Frees the module's temporal probe when a `TemporalProbe` is collected without `dispose()`. */
const collectedTemporal =
  typeof FinalizationRegistry === "undefined"
    ? null
    : new FinalizationRegistry(({ exports, handle }) => exports.temporal_free(handle));

/** `v` (three numbers) as three numbers, or a LengthMismatch error. */
function vector(v, what) {
  if (v == null || v.length !== 3) throw new ProbeError("LengthMismatch", `${what}: expected 3 components`);
  return [v[0], v[1], v[2]];
}

/**
 * An RGB Bayesian Monte Carlo lighting probe of N samples (`Probe<N, [f32; 3]>` of the Rust
 * crate): take radiance in its `directions()`, `update` it, then ask for irradiance, glossy
 * radiance and spherical harmonics, each with its posterior variance.
 */
export class Probe {
  #exports;
  #handle;
  #n;
  #seed;

  /** Use `Probe.create`. */
  constructor(exports, handle, n, seed) {
    if (typeof exports?.probe_new !== "function") throw new TypeError("use Probe.create()");
    this.#exports = exports;
    this.#handle = handle;
    this.#n = n;
    this.#seed = seed;
    collected?.register(this, { exports, handle }, this);
  }

  /**
   * A probe of `n` samples without data on the spherical Fibonacci set, rotated by the
   * rotation sequence of `seed` (0: unrotated).
   * @param {{ n?: number, seed?: number, wasm?: any }} [options]
   * @returns {Promise<Probe>}
   */
  static async create({ n = 64, seed = 0, wasm } = {}) {
    if (!SIZES.includes(n)) throw new ProbeError("InvalidSize", `no baked probe of size ${n} (sizes ${SIZES.join(", ")})`);
    checkedSeed(seed, "Probe.create");
    const exports = await exportsFor(n, wasm, "Probe.create");
    const handle = exports.probe_new(seed >>> 0);
    if (handle < 0) check(-handle, "Probe.create");
    return new Probe(exports, handle, n, seed);
  }

  /** The number of samples N. */
  get n() {
    return this.#n;
  }

  /** The rotation seed. */
  get seed() {
    return this.#seed;
  }

  /** The exchange buffer of the module (a fresh view: memory may have grown). */
  #io(length) {
    const x = this.#exports;
    return new Float32Array(x.memory.buffer, x.io_ptr(), length);
  }

  #live(what) {
    if (this.#handle < 0) throw new ProbeError("InvalidHandle", `${what}: the probe was disposed`);
    return this.#handle;
  }

  /**
   * The N unit directions in which to sample radiance: x, y, z each (3N floats), in the
   * order `update` expects.
   * @returns {Float32Array}
   */
  directions() {
    check(this.#exports.probe_directions(this.#live("directions")), "directions");
    return this.#io(3 * this.#n).slice();
  }

  /**
   * Takes new samples: RGB radiance in `directions()`, r, g, b each (3N numbers). On error
   * the probe keeps its previous data.
   * @param {ArrayLike<number>} samples
   */
  update(samples) {
    const h = this.#live("update");
    if (samples == null || samples.length !== 3 * this.#n) {
      throw new ProbeError("LengthMismatch", `update: expected ${3 * this.#n} floats (r, g, b for each of ${this.#n} directions), got ${samples?.length}`);
    }
    this.#io(3 * this.#n).set(samples);
    check(this.#exports.probe_update(h), "update");
  }

  #estimate() {
    const io = this.#io(6);
    return { value: io.slice(0, 3), variance: io.slice(3, 6) };
  }

  /**
   * Irradiance about `normal` (need not be unit) and its posterior variance, RGB each.
   * Zero before the first update.
   * @param {ArrayLike<number>} normal
   */
  irradiance(normal) {
    const h = this.#live("irradiance");
    const [x, y, z] = vector(normal, "irradiance");
    check(this.#exports.probe_irradiance(h, x, y, z), "irradiance");
    return this.#estimate();
  }

  /**
   * Normalised Phong glossy radiance about the reflection direction `reflect` with exponent
   * `exponent` (the spherical Gaussian of the same moments) and its exact posterior variance.
   * @param {ArrayLike<number>} reflect
   * @param {number} exponent
   */
  glossy(reflect, exponent) {
    const h = this.#live("glossy");
    const [x, y, z] = vector(reflect, "glossy");
    check(this.#exports.probe_glossy(h, x, y, z, exponent), "glossy");
    return this.#estimate();
  }

  /**
   * The 9 RGB spherical-harmonic coefficients (degree ≤ 2, index l(l + 1) + m, orthonormal
   * real harmonics without the Condon–Shortley phase) of the posterior mean radiance:
   * 27 floats, r, g, b for each coefficient.
   * @returns {Float32Array}
   */
  radianceSh() {
    check(this.#exports.probe_radiance_sh(this.#live("radianceSh")), "radianceSh");
    return this.#io(27).slice();
  }

  /**
   * The posterior variance of each of `radianceSh()`'s 27 numbers.
   * @returns {Float32Array}
   */
  radianceShVariance() {
    check(this.#exports.probe_radiance_sh_variance(this.#live("radianceShVariance")), "radianceShVariance");
    return this.#io(27).slice();
  }

  /**
   * three.js `SphericalHarmonics3` coefficients of the posterior mean radiance, 27 floats for
   * `sh.fromArray(...)`: `frame` says where the probe's directions were sampled, `"y-up"`
   * (three.js world directions: unchanged) or `"z-up"` (rotated to three.js's y-up world by
   * (x, y, z) ↦ (x, z, −y)). Anything else throws `ProbeError` `InvalidParameter`.
   * @param {"y-up" | "z-up"} frame
   * @returns {Float32Array}
   */
  threeJsSh(frame) {
    const code = frameCode(frame, "threeJsSh");
    check(this.#exports.probe_three_js_sh(this.#live("threeJsSh"), code), "threeJsSh");
    return this.#io(27).slice();
  }

  /** Frees the probe in the module; any later call throws `ProbeError` `InvalidHandle`. */
  dispose() {
    if (this.#handle < 0) return;
    collected?.unregister(this);
    const h = this.#handle;
    this.#handle = -1;
    check(this.#exports.probe_free(h), "dispose");
  }
}

/** The footprints of `TemporalProbe`: the module's code for each. */
const FOOTPRINTS = { point: 0, gaussian: 1 };

/** What `pool` (`TemporalProbe`, `LayoutProbe`) did with the old evidence, by the module's code. */
const CHANGES = { 1: "first", 2: "blended", 3: "reset" };

/**
 * An RGB temporal probe of N rays per update (`TemporalProbe<N − S, [f32; 3], F, S>` of the
 * Rust crate): every update takes radiance in N − S directions of a freshly rotated spherical
 * Fibonacci set and in S sentinel directions (re-reads of earlier ones), pools the evidence of all updates, and
 * forgets it by the posterior probability that the light changed. `F` is point samples or
 * the normalised spherical Gaussian of sharpness N/8 (`footprint: "gaussian"`).
 */
export class TemporalProbe {
  #exports;
  #handle;
  #n;
  #seed;
  #footprint;
  #hazard;
  #sentinels;

  /** Use `TemporalProbe.create`. */
  constructor(exports, handle, n, seed, footprint, hazard) {
    if (typeof exports?.temporal_new !== "function") throw new TypeError("use TemporalProbe.create()");
    this.#exports = exports;
    this.#handle = handle;
    this.#n = n;
    this.#seed = seed;
    this.#footprint = footprint;
    this.#hazard = hazard;
    this.#sentinels = exports.temporal_sentinel_count();
    collectedTemporal?.register(this, { exports, handle }, this);
  }

  /**
   * A temporal probe of `n` rays per update without data: its rotations from `seed`, point
   * or Gaussian footprint samples, prior probability `hazard` that the light changes at an
   * update.
   * @param {{ n?: number, seed?: number, footprint?: "point" | "gaussian", hazard?: number, wasm?: any }} [options]
   * @returns {Promise<TemporalProbe>}
   */
  static async create({ n = 64, seed = 0, footprint = "point", hazard = 1 / 64, wasm } = {}) {
    const what = "TemporalProbe.create";
    if (!SIZES.includes(n)) throw new ProbeError("InvalidSize", `${what}: no baked probe of size ${n} (sizes ${SIZES.join(", ")})`);
    checkedSeed(seed, what);
    if (!Object.hasOwn(FOOTPRINTS, footprint)) {
      throw new ProbeError("InvalidParameter", `${what}: footprint must be "point" or "gaussian": ${footprint}`);
    }
    if (typeof hazard !== "number" || !(hazard > 0 && hazard < 1)) {
      throw new ProbeError("InvalidParameter", `${what}: hazard must be a number in (0, 1): ${hazard}`);
    }
    const exports = await exportsFor(n, wasm, what);
    const handle = exports.temporal_new(seed >>> 0, FOOTPRINTS[footprint], hazard);
    if (handle < 0) check(-handle, what);
    return new TemporalProbe(exports, handle, n, seed, footprint, hazard);
  }

  /** The rays per update N: `N − S` rotated samples and `S` sentinel readings. */
  get n() {
    return this.#n;
  }

  /** The rotation seed. */
  get seed() {
    return this.#seed;
  }

  /** The samples' footprint: `"point"` or `"gaussian"`. */
  get footprint() {
    return this.#footprint;
  }

  /** The sharpness N/8 of the Gaussian footprint (0 for point samples). */
  get sharpness() {
    return this.#footprint === "gaussian" ? this.#exports.temporal_sharpness() : 0;
  }

  /** The prior probability of a change per update. */
  get hazard() {
    return this.#hazard;
  }

  /** The number of sentinels S. */
  get sentinelCount() {
    return this.#sentinels;
  }

  /** The number of rotated samples per update, N − S. */
  get sampleCount() {
    return this.#n - this.#sentinels;
  }

  #io(length) {
    const x = this.#exports;
    return new Float32Array(x.memory.buffer, x.io_ptr(), length);
  }

  #live(what) {
    if (this.#handle < 0) throw new ProbeError("InvalidHandle", `${what}: the probe was disposed`);
    return this.#handle;
  }

  /**
   * The N − S unit directions of this update's samples, x, y, z each: a new rotation after
   * every successful update.
   * @returns {Float32Array}
   */
  directions() {
    check(this.#exports.temporal_directions(this.#live("directions")), "directions");
    return this.#io(3 * this.sampleCount).slice();
  }

  /**
   * This update's S sentinel directions, x, y, z each: directions of earlier updates,
   * re-read.
   * @returns {Float32Array}
   */
  sentinels() {
    check(this.#exports.temporal_sentinels(this.#live("sentinels")), "sentinels");
    return this.#io(3 * this.#sentinels).slice();
  }

  /**
   * Pools this update's RGB samples in `directions()` (3(N − S) numbers) and RGB sentinel
   * readings in `sentinels()` (3S numbers) with the earlier evidence, after weighing the
   * evidence of a change. Returns what it did with the old evidence: `"first"`, `"blended"`
   * or `"reset"`. On error the probe keeps its state and its directions.
   * @param {ArrayLike<number>} samples
   * @param {ArrayLike<number>} sentinels
   * @returns {"first" | "blended" | "reset"}
   */
  pool(samples, sentinels) {
    const h = this.#live("pool");
    const m = this.sampleCount, s = this.#sentinels;
    if (samples == null || samples.length !== 3 * m) {
      throw new ProbeError("LengthMismatch", `pool: expected ${3 * m} sample floats (r, g, b for each of ${m} directions), got ${samples?.length}`);
    }
    if (sentinels == null || sentinels.length !== 3 * s) {
      throw new ProbeError("LengthMismatch", `pool: expected ${3 * s} sentinel floats (r, g, b for each of ${s} sentinels), got ${sentinels?.length}`);
    }
    const io = this.#io(3 * this.#n);
    io.set(samples);
    io.set(sentinels, 3 * m);
    check(this.#exports.temporal_pool(h), "pool");
    return CHANGES[new Uint32Array(this.#exports.memory.buffer, this.#exports.io_ptr(), 1)[0]];
  }

  /**
   * Accumulated irradiance about `normal` (need not be unit) and its variance, RGB each (the
   * variance is the same for every normal). Zero before the first update.
   * @param {ArrayLike<number>} normal
   */
  irradiance(normal) {
    const h = this.#live("irradiance");
    const [x, y, z] = vector(normal, "irradiance");
    check(this.#exports.temporal_irradiance(h, x, y, z), "irradiance");
    const io = this.#io(6);
    return { value: io.slice(0, 3), variance: io.slice(3, 6) };
  }

  /**
   * The 9 accumulated RGB spherical-harmonic coefficients of the radiance (degree ≤ 2, as
   * `Probe.radianceSh`): 27 floats.
   * @returns {Float32Array}
   */
  radianceSh() {
    check(this.#exports.temporal_radiance_sh(this.#live("radianceSh")), "radianceSh");
    return this.#io(27).slice();
  }

  /**
   * three.js `SphericalHarmonics3` coefficients of the accumulated radiance, 27 floats for
   * `sh.fromArray(...)`, `frame` as in `Probe.threeJsSh`.
   * @param {"y-up" | "z-up"} frame
   * @returns {Float32Array}
   */
  threeJsSh(frame) {
    const code = frameCode(frame, "threeJsSh");
    check(this.#exports.temporal_three_js_sh(this.#live("threeJsSh"), code), "threeJsSh");
    return this.#io(27).slice();
  }

  /**
   * The variance of each of `radianceSh()`'s 27 numbers.
   * @returns {Float32Array}
   */
  radianceShVariance() {
    check(this.#exports.temporal_radiance_sh_variance(this.#live("radianceShVariance")), "radianceShVariance");
    return this.#io(27).slice();
  }

  #state(what) {
    check(this.#exports.temporal_state(this.#live(what)), what);
    const x = this.#exports;
    return { words: new Uint32Array(x.memory.buffer, x.io_ptr(), 2).slice(), floats: this.#io(6).slice(2, 6) };
  }

  /** Updates taken since the first (soft resets do not change it). */
  get updates() {
    return this.#state("updates").words[0];
  }

  /** The spherical-harmonic degree L of the state: round(log₂(N − S)) in [2, 8]. */
  get degree() {
    return this.#state("degree").words[1];
  }

  /** The weight of the pooled evidence in updates (less than the count after a reset). */
  get pooledUpdates() {
    return this.#state("pooledUpdates").floats[0];
  }

  /** The posterior probability of a change at the last update (0 for the first). */
  get lastChangeProbability() {
    return this.#state("lastChangeProbability").floats[1];
  }

  /**
   * The log Bayes factors of a change at the last update: from the rotated samples and
   * from the sentinels (0 for the first).
   * @returns {{ rotated: number, sentinels: number }}
   */
  get lastEvidence() {
    const f = this.#state("lastEvidence").floats;
    return { rotated: f[2], sentinels: f[3] };
  }

  /** Frees the probe in the module; any later call throws `ProbeError` `InvalidHandle`. */
  dispose() {
    if (this.#handle < 0) return;
    collectedTemporal?.unregister(this);
    const h = this.#handle;
    this.#handle = -1;
    check(this.#exports.temporal_free(h), "dispose");
  }
}

/** The sensor counts K of `LayoutProbe`s: one instantiation each in wasm/layout.wasm. */
export const LAYOUT_SIZES = Object.freeze([4, 5, 6, 7, 8, 12, 16]);

/** The exports of the layout module (and all it has, with `memory`). */
const LAYOUT_EXPORTS = [
  "memory", "io_ptr", "io_len", "layout_capacities", "layout_new", "layout_free", "layout_directions",
  "layout_update", "layout_pool", "layout_irradiance", "layout_irradiance_variance", "layout_phong",
  "layout_radiance_sh", "layout_state",
];

/** The shared instance of the default layout module (a promise). */
let layoutInstance = null;

/** The exports of a layout module instance, checked. */
async function instantiateLayout(source) {
  const module = await moduleOf("layout.wasm", source);
  if (WebAssembly.Module.imports(module).length !== 0) {
    throw new ProbeError("InvalidParameter", "the layout module must have no imports");
  }
  const { exports } = await WebAssembly.instantiate(module, {});
  for (const name of LAYOUT_EXPORTS) {
    if (!(name in exports)) throw new ProbeError("InvalidParameter", `the layout module lacks the export ${name}`);
  }
  const count = exports.layout_capacities();
  const sizes = Array.from(new Uint32Array(exports.memory.buffer, exports.io_ptr(), count));
  if (sizes.join() !== LAYOUT_SIZES.join()) {
    throw new ProbeError("InvalidSize", `the layout module is for K = ${sizes.join(", ")}, not ${LAYOUT_SIZES.join(", ")}`);
  }
  return exports;
}

/** The checked exports of the layout module: the shared default one, or `wasm`'s. */
async function layoutExports(wasm) {
  if (wasm !== undefined) return instantiateLayout(wasm);
  layoutInstance ??= instantiateLayout();
  try {
    return await layoutInstance;
  } catch (e) {
    layoutInstance = null;
    throw e;
  }
}

/** Frees the module's layout probe when a `LayoutProbe` is collected without `dispose()`. */
const collectedLayout =
  typeof FinalizationRegistry === "undefined"
    ? null
    : new FinalizationRegistry(({ exports, handle }) => exports.layout_free(handle));

/** The learned priors of `LayoutProbe`: the module's code for each. */
const PRIORS = { "environment": 0, "smooth-environment": 1, "sky-above": 2, "smooth-sky-above": 3 };

/** `values` (K numbers) or K copies of `fallback` when undefined, else a LengthMismatch error. */
function perSensor(values, k, fallback, what) {
  if (values === undefined) return new Float32Array(k).fill(fallback);
  if (values == null || values.length !== k) {
    throw new ProbeError("LengthMismatch", `${what}: expected ${k} numbers (one per sensor), got ${values?.length}`);
  }
  return values;
}

/**
 * An RGB probe over the K sensors of a user's layout (`LayoutProbe<K, [f32; 3]>` of the Rust
 * crate): sensors at arbitrary directions, each with a cosine-power angular response and a
 * noise scale, a Gaussian-process prior of the light, read noise; `update` (or `pool`, for a
 * stream) with the sensors' readings, then ask for irradiance, its variance, Phong
 * averages and SH coefficients.
 */
export class LayoutProbe {
  #exports;
  #handle;
  #k;
  #prior;
  #hazard;

  /** Use `LayoutProbe.create`. */
  constructor(exports, handle, k, prior, hazard) {
    if (typeof exports?.layout_new !== "function") throw new TypeError("use LayoutProbe.create()");
    this.#exports = exports;
    this.#handle = handle;
    this.#k = k;
    this.#prior = prior;
    this.#hazard = hazard;
    collectedLayout?.register(this, { exports, handle }, this);
  }

  /**
   * A layout probe without data over the sensors `directions` (3K numbers, x, y, z each; K in
   * `LAYOUT_SIZES`), their cosine powers `powers` (K numbers, default 1: bare photodiodes),
   * their noise scales `noiseScales` (K numbers, default 1), the read noise
   * `noise = { absolute, relative }`, a prior (a learned one by name, or
   * `{ squaredExponential: λ }`) and the hazard of `pool`.
   * @param {{ directions: ArrayLike<number>, powers?: ArrayLike<number>, noiseScales?: ArrayLike<number>,
   *   noise?: { absolute?: number, relative?: number }, prior?: string | { squaredExponential: number },
   *   hazard?: number, wasm?: any }} options
   * @returns {Promise<LayoutProbe>}
   */
  static async create({ directions, powers, noiseScales, noise = {}, prior = "environment", hazard = 1 / 64, wasm } = {}) {
    const what = "LayoutProbe.create";
    if (directions == null || typeof directions.length !== "number" || directions.length % 3 !== 0) {
      throw new ProbeError("LengthMismatch", `${what}: directions must be 3K numbers (x, y, z per sensor), got ${directions?.length}`);
    }
    const k = directions.length / 3;
    if (!LAYOUT_SIZES.includes(k)) {
      throw new ProbeError("InvalidSize", `${what}: no layout probe of ${k} sensors (sensor counts ${LAYOUT_SIZES.join(", ")})`);
    }
    const p = perSensor(powers, k, 1, `${what}: powers`);
    const w = perSensor(noiseScales, k, 1, `${what}: noiseScales`);
    let code, lambda = 0;
    if (typeof prior === "string" && Object.hasOwn(PRIORS, prior)) {
      code = PRIORS[prior];
    } else if (typeof prior === "object" && prior !== null && typeof prior.squaredExponential === "number") {
      code = 4;
      lambda = prior.squaredExponential;
    } else {
      throw new ProbeError("InvalidParameter", `${what}: prior must be "environment", "smooth-environment", "sky-above", "smooth-sky-above" or { squaredExponential: λ }: ${JSON.stringify(prior)}`);
    }
    if (typeof noise !== "object" || noise === null) {
      throw new ProbeError("InvalidParameter", `${what}: noise must be { absolute, relative }: ${noise}`);
    }
    const { absolute = 0, relative = 0 } = noise;
    for (const [name, v] of [["noise.absolute", absolute], ["noise.relative", relative], ["hazard", hazard]]) {
      if (typeof v !== "number") throw new ProbeError("InvalidParameter", `${what}: ${name} must be a number: ${v}`);
    }
    const exports = await layoutExports(wasm);
    const io = new Float32Array(exports.memory.buffer, exports.io_ptr(), 5 * k);
    io.set(directions);
    io.set(p, 3 * k);
    io.set(w, 4 * k);
    const handle = exports.layout_new(k, code, lambda, absolute, relative, hazard);
    if (handle < 0) check(-handle, what);
    return new LayoutProbe(exports, handle, k, typeof prior === "string" ? prior : { squaredExponential: lambda }, hazard);
  }

  /** The number of sensors K. */
  get k() {
    return this.#k;
  }

  /** The prior: its name, or `{ squaredExponential: λ }`. */
  get prior() {
    return this.#prior;
  }

  /** The prior probability of a change per `pool`. */
  get hazard() {
    return this.#hazard;
  }

  #io(length) {
    const x = this.#exports;
    return new Float32Array(x.memory.buffer, x.io_ptr(), length);
  }

  #live(what) {
    if (this.#handle < 0) throw new ProbeError("InvalidHandle", `${what}: the probe was disposed`);
    return this.#handle;
  }

  /**
   * The sensors' unit directions, x, y, z each (3K floats), in the order `update` expects.
   * @returns {Float32Array}
   */
  directions() {
    check(this.#exports.layout_directions(this.#live("directions")), "directions");
    return this.#io(3 * this.#k).slice();
  }

  #readings(readings, what) {
    const h = this.#live(what);
    if (readings == null || readings.length !== 3 * this.#k) {
      throw new ProbeError("LengthMismatch", `${what}: expected ${3 * this.#k} floats (r, g, b for each of ${this.#k} sensors), got ${readings?.length}`);
    }
    this.#io(3 * this.#k).set(readings);
    return h;
  }

  /**
   * Fits the sensors' RGB readings (3K numbers, r, g, b per sensor), forgetting earlier ones.
   * On error the probe keeps its state.
   * @param {ArrayLike<number>} readings
   */
  update(readings) {
    check(this.#exports.layout_update(this.#readings(readings, "update")), "update");
  }

  /**
   * Pools the sensors' RGB readings (3K numbers) with the earlier ones of a stream, forgetting
   * them by the posterior probability that the light changed, and fits the pooled means.
   * Returns what it did with the old readings: `"first"`, `"blended"` or `"reset"`. On error
   * the probe keeps its state.
   * @param {ArrayLike<number>} readings
   * @returns {"first" | "blended" | "reset"}
   */
  pool(readings) {
    check(this.#exports.layout_pool(this.#readings(readings, "pool")), "pool");
    return CHANGES[new Uint32Array(this.#exports.memory.buffer, this.#exports.io_ptr(), 1)[0]];
  }

  #estimate() {
    const io = this.#io(6);
    return { value: io.slice(0, 3), variance: io.slice(3, 6) };
  }

  /**
   * Irradiance about `normal` (need not be unit) with the direction-averaged posterior
   * variance, RGB each. Zero before the first update.
   * @param {ArrayLike<number>} normal
   */
  irradiance(normal) {
    const h = this.#live("irradiance");
    const [x, y, z] = vector(normal, "irradiance");
    check(this.#exports.layout_irradiance(h, x, y, z), "irradiance");
    return this.#estimate();
  }

  /**
   * The exact posterior variance of the irradiance about `normal`, RGB.
   * @param {ArrayLike<number>} normal
   * @returns {Float32Array}
   */
  irradianceVariance(normal) {
    const h = this.#live("irradianceVariance");
    const [x, y, z] = vector(normal, "irradianceVariance");
    check(this.#exports.layout_irradiance_variance(h, x, y, z), "irradianceVariance");
    return this.#io(3).slice();
  }

  /**
   * The normalised Phong average about `axis` with exponent `exponent` (the glossy term about
   * a mirror direction) with its exact posterior variance, RGB each.
   * @param {ArrayLike<number>} axis
   * @param {number} exponent
   */
  phong(axis, exponent) {
    const h = this.#live("phong");
    const [x, y, z] = vector(axis, "phong");
    check(this.#exports.layout_phong(h, x, y, z, exponent), "phong");
    return this.#estimate();
  }

  /**
   * The 9 RGB spherical-harmonic coefficients of the posterior mean radiance (the order of
   * `Probe.radianceSh()`): 27 floats.
   * @returns {Float32Array}
   */
  radianceSh() {
    check(this.#exports.layout_radiance_sh(this.#live("radianceSh")), "radianceSh");
    return this.#io(27).slice();
  }

  #state(what) {
    check(this.#exports.layout_state(this.#live(what)), what);
    const x = this.#exports;
    return { words: new Uint32Array(x.memory.buffer, x.io_ptr(), 2).slice(), floats: this.#io(7).slice(2, 7) };
  }

  /** Whether the probe has had an update. */
  get updated() {
    return this.#state("updated").words[1] === 1;
  }

  /** The effective number of readings pooled by `pool` (1 after `update`, 0 before). */
  get pooledUpdates() {
    return this.#state("pooledUpdates").floats[0];
  }

  /** The posterior probability of a change at the last `pool` (0 after `update`). */
  get lastChangeProbability() {
    return this.#state("lastChangeProbability").floats[1];
  }

  /**
   * The scale of the prior covariance chosen at the last update, RGB (0 before the first).
   * @returns {Float32Array}
   */
  get signalVariance() {
    return this.#state("signalVariance").floats.slice(2, 5);
  }

  /** Frees the probe in the module; any later call throws `ProbeError` `InvalidHandle`. */
  dispose() {
    if (this.#handle < 0) return;
    collectedLayout?.unregister(this);
    const h = this.#handle;
    this.#handle = -1;
    check(this.#exports.layout_free(h), "dispose");
  }
}
