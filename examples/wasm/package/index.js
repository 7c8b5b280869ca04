// sphere-quadrature: RGB Bayesian Monte Carlo lighting probes in WebAssembly (see README.md
// and index.d.ts). One small module per baked probe size N, wasm/probe-N.wasm, without
// imports; this file wraps its exports in the `Probe` class and turns its error codes into
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
];

/** Bytes of the module for size `n` from `source` (see `ProbeOptions.wasm`), or the module. */
async function moduleOf(n, source) {
  if (source instanceof WebAssembly.Module) return source;
  if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) return WebAssembly.compile(source);
  if (typeof Response !== "undefined" && source instanceof Response) return compileResponse(source);
  const url = source === undefined ? new URL(`./wasm/probe-${n}.wasm`, import.meta.url) : new URL(source, import.meta.url);
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
  const module = await moduleOf(n, source);
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

/** Frees the module's probe when a `Probe` is collected without `dispose()`. */
const collected =
  typeof FinalizationRegistry === "undefined"
    ? null
    : new FinalizationRegistry(({ exports, handle }) => exports.probe_free(handle));

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
    if (!Number.isInteger(seed) || seed < 0 || seed > 0xffffffff) {
      throw new ProbeError("InvalidParameter", `seed must be an integer in [0, 2^32): ${seed}`);
    }
    let exports;
    if (wasm === undefined) {
      if (!instances.has(n)) instances.set(n, instantiate(n));
      try {
        exports = await instances.get(n);
      } catch (e) {
        instances.delete(n);
        throw e;
      }
    } else {
      exports = await instantiate(n, wasm);
    }
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

  /** Frees the probe in the module; any later call throws `ProbeError` `InvalidHandle`. */
  dispose() {
    if (this.#handle < 0) return;
    collected?.unregister(this);
    const h = this.#handle;
    this.#handle = -1;
    check(this.#exports.probe_free(h), "dispose");
  }
}
