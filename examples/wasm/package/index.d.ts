// Types of sphere-quadrature (index.js): RGB Bayesian Monte Carlo lighting probes in
// WebAssembly.

/** The baked probe sizes N; each has its own module, `wasm/probe-N.wasm`. */
export declare const SIZES: readonly [16, 32, 64, 128, 256];

/** A baked probe size. */
export type ProbeSize = 16 | 32 | 64 | 128 | 256;

/**
 * What went wrong: the variant of the Rust `sphere_quadrature::Error`, or `InvalidHandle`
 * for a call on a disposed probe (`Unknown` for a code this version does not know).
 */
export type ProbeErrorCode =
  | "InvalidDirection"
  | "InvalidExponent"
  | "LengthMismatch"
  | "InvalidSize"
  | "InvalidParameter"
  | "InvalidSharpness"
  | "InvalidRadiance"
  | "TooManyMissing"
  | "InvalidHandle"
  | "Unknown";

/** Every refusal of the package: bad input, an unbaked size, a disposed probe. */
export declare class ProbeError extends Error {
  constructor(code: ProbeErrorCode, message: string);
  readonly name: "ProbeError";
  /** The error's kind. */
  readonly code: ProbeErrorCode;
}

/** Three numbers: x, y, z of a direction (need not be unit, must be finite and non-zero). */
export type Direction = ArrayLike<number>;

/** A query's answer, RGB each. */
export interface Estimate {
  /** The posterior mean (r, g, b). */
  value: Float32Array;
  /** The posterior variance of `value` (r, g, b). */
  variance: Float32Array;
}

/** Where the module for the probe's size comes from. */
export type WasmSource = WebAssembly.Module | BufferSource | Response | URL | string;

export interface ProbeOptions {
  /** Number of samples: 16, 32, 64 (default), 128 or 256. Anything else throws `InvalidSize`. */
  n?: number;
  /**
   * Rotation seed, an integer in [0, 2³²): the sample set is the spherical Fibonacci set
   * rotated by the first rotation of the crate's `RotationSequence` for this seed (0:
   * unrotated). Rotating per probe (or per frame) turns the set's fixed error pattern into
   * noise.
   */
  seed?: number;
  /**
   * The module for size `n`, when it is not at the default `wasm/probe-<n>.wasm` beside
   * index.js (a bundler or a CDN may move it): a compiled module, its bytes, a fetch
   * `Response`, or a URL (relative to index.js). Without it the default module is loaded
   * once per size and shared by all probes of that size.
   */
  wasm?: WasmSource;
}

/**
 * An RGB Bayesian Monte Carlo lighting probe of N samples (`Probe<N, [f32; 3]>` of the Rust
 * crate `sphere-quadrature`, point samples): sample radiance in `directions()`, `update()`,
 * then query irradiance, glossy radiance and the SH L2 expansion of the radiance, each with
 * its posterior variance. The probe lives in WebAssembly memory: `dispose()` frees it (a
 * collected probe is freed too). Errors throw `ProbeError`.
 *
 * ```js
 * import { Probe } from "sphere-quadrature";
 * const probe = await Probe.create({ n: 64, seed: 1 });
 * const dirs = probe.directions(); // 3N floats
 * const samples = new Float32Array(3 * probe.n); // r, g, b radiance in each direction
 * probe.update(samples);
 * const { value, variance } = probe.irradiance([0, 0, 1]);
 * ```
 */
export declare class Probe {
  private constructor();

  /**
   * A probe without data (every query answers 0 until the first update).
   * @throws {ProbeError} `InvalidSize` for an unbaked `n` or a module of another size,
   *   `InvalidParameter` for a bad seed or a module that is not the package's.
   */
  static create(options?: ProbeOptions): Promise<Probe>;

  /** The number of samples N. */
  readonly n: ProbeSize;
  /** The rotation seed. */
  readonly seed: number;

  /** The N unit directions, x, y, z each (3N floats), in the order `update` expects. */
  directions(): Float32Array;

  /**
   * Takes new samples: RGB radiance in `directions()`, r, g, b each (3N numbers; for a
   * single channel repeat it three times). Picks the kernel of highest marginal likelihood.
   * @throws {ProbeError} `LengthMismatch` unless there are 3N numbers, `InvalidRadiance` for
   *   a NaN or infinite sample; the probe then keeps its previous data.
   */
  update(samples: ArrayLike<number>): void;

  /**
   * Irradiance E(n) = ∫ L(x)·max(0, n·x) dx about `normal` (divide by π for the radiance a
   * white Lambertian surface reflects) with its posterior variance, RGB each.
   * @throws {ProbeError} `InvalidDirection` for a zero or non-finite normal, `LengthMismatch`
   *   unless it has 3 components.
   */
  irradiance(normal: Direction): Estimate;

  /**
   * Normalised Phong glossy radiance about the reflection direction `reflect`, exponent
   * `exponent` (the spherical Gaussian of sharpness e + 2 with the Phong lobe's integral and
   * first moment), with its exact posterior variance, RGB each.
   * @throws {ProbeError} `InvalidDirection` for a bad direction, `InvalidExponent` for a
   *   negative or non-finite exponent, `LengthMismatch` unless it has 3 components.
   */
  glossy(reflect: Direction, exponent: number): Estimate;

  /**
   * The spherical-harmonic coefficients of degree ≤ 2 of the posterior mean radiance,
   * exactly: 27 floats, r, g, b of coefficient k = l(l + 1) + m for k = 0 … 8 (orthonormal
   * real harmonics without the Condon–Shortley phase).
   */
  radianceSh(): Float32Array;

  /** The posterior variance of each of `radianceSh()`'s 27 numbers. */
  radianceShVariance(): Float32Array;

  /** Frees the probe; later calls throw `ProbeError` `InvalidHandle`. Idempotent. */
  dispose(): void;
}
