// Types of sphere-quadrature (index.js): RGB Bayesian Monte Carlo lighting probes, temporal
// probes and probes over sensor layouts in WebAssembly.

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

/**
 * The frame of a probe's directions, for the three.js export: `"y-up"` (three.js world
 * directions, exported unchanged) or `"z-up"` (rotated to three.js's y-up world by
 * (x, y, z) ↦ (x, z, −y)).
 */
export type Frame = "y-up" | "z-up";

/** Three numbers: x, y, z of a direction (need not be unit, must be finite and non-zero). */
export type Direction = ArrayLike<number>;

/** A query's answer, RGB each. */
export interface Estimate {
  /** The posterior mean (r, g, b). */
  value: Float32Array;
  /** The posterior variance of `value` (r, g, b). */
  variance: Float32Array;
}

/** Where the module for the probe's size (or the layout module) comes from. */
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

  /**
   * three.js `SphericalHarmonics3` coefficients of the posterior mean radiance: 27 floats
   * for `lightProbe.sh.fromArray(...)`. `frame` is where the probe's directions were
   * sampled: `"y-up"` (three.js world directions: unchanged) or `"z-up"` (rotated to y-up by
   * (x, y, z) ↦ (x, z, −y)). A white `MeshLambertMaterial` lit by a `LightProbe` of these
   * (intensity 1) renders E(n)/π, E the irradiance of `radianceSh()` (Rust `ShL2::irradiance`)
   * at the z-up normal n = (x, −z, y) of its y-up world normal (x, y, z) (`"z-up"`), or at its
   * world normal (`"y-up"`).
   * @throws {ProbeError} `InvalidParameter` for another `frame`.
   */
  threeJsSh(frame: Frame): Float32Array;

  /** Frees the probe; later calls throw `ProbeError` `InvalidHandle`. Idempotent. */
  dispose(): void;
}

/** The samples' footprint of a `TemporalProbe`. */
export type Footprint = "point" | "gaussian";

/** What `pool` (`TemporalProbe.pool`, `LayoutProbe.pool`) did with the old evidence. */
export type Change =
  /** The first update: the state is this update. */
  | "first"
  /** The probability of a change was below one half: pooled with the old evidence. */
  | "blended"
  /** The probability of a change was at least one half: the state restarted. */
  | "reset";

export interface TemporalProbeOptions {
  /**
   * Rays per update: 16, 32, 64 (default), 128 or 256, of which `sentinelCount` (1, 1, 2,
   * 3, 4) are sentinels (re-reads of earlier directions) and the rest rotated samples. Anything else throws
   * `InvalidSize`.
   */
  n?: number;
  /**
   * Seed of the rotation sequence, an integer in [0, 2³²): the k-th update samples the
   * spherical Fibonacci set rotated by the k-th rotation of the crate's
   * `RotationSequence` for this seed.
   */
  seed?: number;
  /**
   * `"point"` (default): each sample is the radiance in its direction. `"gaussian"`: each
   * sample (and sentinel reading) is the radiance filtered by the normalised spherical
   * Gaussian `exp(S(t − 1))` of sharpness S = n/8 about its direction (a mip level, a cone,
   * a sensor); the probe answers for the unfiltered light.
   */
  footprint?: Footprint;
  /**
   * Prior probability that the light changes at an update, in (0, 1); default 1/64. Higher
   * resets sooner on weak evidence, lower needs stronger evidence.
   */
  hazard?: number;
  /** The module for size `n`, as in `ProbeOptions.wasm`. */
  wasm?: WasmSource;
}

/** The log Bayes factors of a change at the last update. */
export interface ChangeEvidence {
  /**
   * From the rotated samples (the innovation of their degrees ≤ 2 against the state); never
   * positive, since aliasing can fake a change there: it can only weaken the sentinels'
   * evidence.
   */
  rotated: number;
  /** From the sentinels (evidence for a change only: never negative). */
  sentinels: number;
}

/**
 * An RGB temporal probe (`TemporalProbe<N − S, [f32; 3], F, S>` of the Rust crate):
 * `pool()` takes, again and again, radiance in the N − S directions of a freshly rotated
 * spherical Fibonacci set and in S sentinel directions (re-reads of earlier ones). It pools the evidence of every
 * update (the running sum of the samples' spherical-harmonic projections, shrunk per degree
 * against the measured aliasing noise), so its error keeps falling with the updates, and
 * forgets old evidence by the posterior probability that the light changed (a re-read
 * repeats exactly on static light, so aliasing cannot fake a change there). Lives in
 * WebAssembly memory: `dispose()` frees it. Errors throw `ProbeError`.
 *
 * ```js
 * import { TemporalProbe } from "sphere-quadrature";
 * const probe = await TemporalProbe.create({ n: 64, seed: 1 });
 * for (;;) { // every frame
 *   const dirs = probe.directions(); // 3(N − S) floats, new every update
 *   const sentinels = probe.sentinels(); // 3S floats, new every update
 *   probe.pool(trace(dirs), trace(sentinels)); // r, g, b per direction
 *   const { value, variance } = probe.irradiance([0, 0, 1]);
 * }
 * ```
 */
export declare class TemporalProbe {
  private constructor();

  /**
   * A temporal probe without data (every query answers 0 until the first update).
   * @throws {ProbeError} `InvalidSize` for an unbaked `n` or a module of another size,
   *   `InvalidParameter` for a bad seed, footprint or hazard, or a module that is not the
   *   package's.
   */
  static create(options?: TemporalProbeOptions): Promise<TemporalProbe>;

  /** Rays per update N: `sampleCount` rotated samples and `sentinelCount` sentinels. */
  readonly n: ProbeSize;
  /** The rotation seed. */
  readonly seed: number;
  /** The samples' footprint. */
  readonly footprint: Footprint;
  /** The sharpness N/8 of the Gaussian footprint; 0 for point samples. */
  readonly sharpness: number;
  /** The prior probability of a change per update. */
  readonly hazard: number;
  /** The number S of sentinels: 1, 1, 2, 3, 4 for N = 16, 32, 64, 128, 256. */
  readonly sentinelCount: number;
  /** The number N − S of rotated samples per update. */
  readonly sampleCount: number;
  /** The spherical-harmonic degree L of the state: round(log₂(N − S)) in [2, 8]. */
  readonly degree: number;
  /** Updates taken since the first (soft resets do not change it). */
  readonly updates: number;
  /**
   * The weight of the pooled evidence in updates: the updates since the last full reset
   * when nothing was forgotten in between, less after partial resets.
   */
  readonly pooledUpdates: number;
  /** The posterior probability of a change at the last update (0 for the first). */
  readonly lastChangeProbability: number;
  /** The log Bayes factors of a change at the last update (0 for the first). */
  readonly lastEvidence: ChangeEvidence;

  /**
   * This update's N − S unit directions, x, y, z each (3(N − S) floats), in the order
   * `pool` expects; a new rotation after every successful `pool`.
   */
  directions(): Float32Array;

  /** This update's S sentinel directions, x, y, z each (3S floats): directions of earlier updates, re-read. */
  sentinels(): Float32Array;

  /**
   * Pools this update's RGB samples in `directions()` (3(N − S) numbers) and RGB readings
   * in `sentinels()` (3S numbers), taken the same way (for a single channel repeat it three
   * times), with the earlier evidence: weighs the evidence of a change, forgets old evidence
   * by its posterior probability, pools the samples and rotates the directions.
   * @throws {ProbeError} `LengthMismatch` for other lengths, `InvalidRadiance` for a NaN or
   *   infinite value; the probe then keeps its state and its directions.
   */
  pool(samples: ArrayLike<number>, sentinels: ArrayLike<number>): Change;

  /**
   * Accumulated irradiance E(n) = ∫ L(x)·max(0, n·x) dx about `normal` with its variance (the
   * aliasing noise left after pooling; the same for every normal), RGB each.
   * @throws {ProbeError} `InvalidDirection` for a zero or non-finite normal, `LengthMismatch`
   *   unless it has 3 components.
   */
  irradiance(normal: Direction): Estimate;

  /**
   * The accumulated spherical-harmonic coefficients of degree ≤ 2 of the radiance (for a
   * footprint probe, of the unfiltered radiance): 27 floats in the order of
   * `Probe.radianceSh()`.
   */
  radianceSh(): Float32Array;

  /** The variance of each of `radianceSh()`'s 27 numbers. */
  radianceShVariance(): Float32Array;

  /**
   * three.js `SphericalHarmonics3` coefficients of the accumulated radiance (27 floats for
   * `fromArray`), `frame` as in `Probe.threeJsSh`.
   * @throws {ProbeError} `InvalidParameter` for another `frame`.
   */
  threeJsSh(frame: Frame): Float32Array;

  /** Frees the probe; later calls throw `ProbeError` `InvalidHandle`. Idempotent. */
  dispose(): void;
}

/** The sensor counts K of `LayoutProbe`s: the module `wasm/layout.wasm` carries these. */
export declare const LAYOUT_SIZES: readonly [4, 5, 6, 7, 8, 12, 16];

/** A sensor count of `LAYOUT_SIZES`. */
export type LayoutSize = 4 | 5 | 6 | 7 | 8 | 12 | 16;

/**
 * The prior of a `LayoutProbe`'s light: a learned one by name, or the squared-exponential
 * kernel `exp(λ(x·x′ − 1))`, `0 < λ ≤ 64`, with a constant mean.
 */
export type LayoutPrior =
  /** Light in general, for layouts in any orientation (the mean angular power spectrum of real environment maps, zero mean). */
  | "environment"
  /** As `"environment"` for light without sharp features. */
  | "smooth-environment"
  /**
   * Layouts that look up (a dome, a ceiling fixture) with `+z` up: the level, the vertical
   * gradient and the zonal degree 2 of the light vary together (the maps' correlations).
   */
  | "sky-above"
  /** As `"sky-above"` for light without sharp features. */
  | "smooth-sky-above"
  | { squaredExponential: number };

/** The read noise of a layout: sensor i has variance wᵢ²·absolute² + relative²·Yᵢ². */
export interface LayoutNoise {
  /** σ, in the readings' units; default 0. */
  absolute?: number;
  /** η, a fraction of the reading; default 0. */
  relative?: number;
}

export interface LayoutProbeOptions {
  /** The sensors' directions, x, y, z each (3K numbers, K in `LAYOUT_SIZES`; need not be unit). */
  directions: ArrayLike<number>;
  /**
   * Each sensor's angular response `(P + 1)/(2π)·max(0, t)ᴾ`, as its power P in [0, 4096]
   * (K numbers; default 1, a bare photodiode; larger: a lens or a diffuser; 0: a
   * hemisphere). At most four distinct powers.
   */
  powers?: ArrayLike<number>;
  /** Each sensor's absolute noise relative to `noise.absolute`, positive (K numbers; default 1). */
  noiseScales?: ArrayLike<number>;
  /** The read noise; default none (exact readings). */
  noise?: LayoutNoise;
  /** The prior of the light; default `"environment"`. */
  prior?: LayoutPrior;
  /** Prior probability that the light changes at a `pool`, in (0, 1); default 1/64. */
  hazard?: number;
  /** The layout module, when it is not at the default `wasm/layout.wasm` beside index.js. */
  wasm?: WasmSource;
}

/**
 * An RGB probe over the K sensors of a user's layout (`LayoutProbe<K, [f32; 3]>` of the Rust
 * crate): photodiodes on the faces of a cube, a dome of five, a ring on a fixture, each with
 * its own direction, angular response and noise. `update()` (or `pool()` for a stream of
 * readings) with the readings, then query irradiance for any normal with an error bar,
 * Phong averages and SH coefficients. Lives in WebAssembly memory: `dispose()` frees it.
 * Errors throw `ProbeError`.
 *
 * ```js
 * import { LayoutProbe } from "sphere-quadrature";
 * const cube = [1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1];
 * const probe = await LayoutProbe.create({ directions: cube, noise: { absolute: 0.01 } });
 * probe.pool(readings); // r, g, b per sensor, 18 numbers
 * const { value, variance } = probe.irradiance([0, 0, 1]);
 * ```
 */
export declare class LayoutProbe {
  private constructor();

  /**
   * A layout probe without data (every query answers 0 until the first update).
   * @throws {ProbeError} `InvalidSize` for a sensor count not in `LAYOUT_SIZES` (or a layout
   *   module for other counts), `LengthMismatch` for directions that are not 3K numbers or
   *   powers or noise scales that are not K, `InvalidDirection` for a zero or non-finite
   *   direction, `InvalidParameter` for a bad power, noise scale, noise, prior, λ or hazard,
   *   more than four distinct powers, or a module that is not the layout module.
   */
  static create(options: LayoutProbeOptions): Promise<LayoutProbe>;

  /** The number of sensors K. */
  readonly k: LayoutSize;
  /** The prior. */
  readonly prior: LayoutPrior;
  /** The prior probability of a change per `pool`. */
  readonly hazard: number;
  /** Whether the probe has had an `update` or a `pool`. */
  readonly updated: boolean;
  /**
   * The effective number of readings pooled by `pool` (1 after `update`, 0 before any):
   * the updates since the last full reset when nothing was forgotten in between.
   */
  readonly pooledUpdates: number;
  /** The posterior probability of a change at the last `pool` (1 at the first, 0 after `update`). */
  readonly lastChangeProbability: number;
  /** The scale σ_f² of the prior covariance chosen at the last fit, RGB (0 before the first). */
  readonly signalVariance: Float32Array;

  /** The sensors' unit directions, x, y, z each (3K floats), in the order `update` expects. */
  directions(): Float32Array;

  /**
   * Fits the sensors' RGB readings (3K numbers, r, g, b per sensor; a single channel: repeat
   * it), forgetting earlier ones.
   * @throws {ProbeError} `LengthMismatch` unless there are 3K numbers, `InvalidRadiance` for
   *   a NaN or infinite reading; the probe then keeps its state.
   */
  update(readings: ArrayLike<number>): void;

  /**
   * Pools the sensors' RGB readings (3K numbers) with the earlier ones of a stream of static
   * light, forgetting them by the posterior probability that the light changed, and fits the
   * pooled means (on static light the noise's share of the error falls like 1/√updates).
   * @throws {ProbeError} as `update`; the probe then keeps its state.
   */
  pool(readings: ArrayLike<number>): Change;

  /**
   * Irradiance E(n) = ∫ L(x)·max(0, n·x) dx about `normal` with the posterior variance
   * averaged over all normals (the same for every normal; `irradianceVariance` is the exact
   * one), RGB each.
   * @throws {ProbeError} `InvalidDirection` for a zero or non-finite normal, `LengthMismatch`
   *   unless it has 3 components.
   */
  irradiance(normal: Direction): Estimate;

  /** The exact posterior variance of the irradiance about `normal`, RGB. Throws as `irradiance`. */
  irradianceVariance(normal: Direction): Float32Array;

  /**
   * The normalised Phong average ∫ L(x)·(e + 1)/(2π)·max(0, axis·x)ᵉ dx about `axis` (the
   * glossy term about a mirror direction) with its exact posterior variance, RGB each.
   * @throws {ProbeError} `InvalidDirection` for a bad axis, `InvalidExponent` for an
   *   exponent that is negative, not finite or above 1e8, `LengthMismatch` unless the axis
   *   has 3 components.
   */
  phong(axis: Direction, exponent: number): Estimate;

  /**
   * The spherical-harmonic coefficients of degree ≤ 2 of the posterior mean radiance: 27
   * floats in the order of `Probe.radianceSh()`.
   */
  radianceSh(): Float32Array;

  /** Frees the probe; later calls throw `ProbeError` `InvalidHandle`. Idempotent. */
  dispose(): void;
}
