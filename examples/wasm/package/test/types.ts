// Type check of the package's index.d.ts from a consumer (tsc --noEmit, test/run.sh): the
// README's usage compiles, misuse does not (each @ts-expect-error must meet an error).
import {
  LAYOUT_SIZES, LayoutProbe, Probe, ProbeError, SIZES, TemporalProbe, type Change, type ChangeEvidence, type Estimate,
  type Footprint, type Frame, type LayoutPrior, type LayoutSize, type ProbeErrorCode, type ProbeSize,
} from "sphere-quadrature";

export async function shade(radiance: (x: number, y: number, z: number) => [number, number, number]): Promise<number> {
  const probe: Probe = await Probe.create({ n: 64, seed: 1 });
  const n: ProbeSize = probe.n;
  const dirs: Float32Array = probe.directions();
  const samples = new Float32Array(3 * n);
  for (let j = 0; j < n; j++) samples.set(radiance(dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]), 3 * j);
  probe.update(samples);
  const e: Estimate = probe.irradiance([0, 0, 1]);
  const g = probe.glossy(new Float32Array([0, 1, 0]), 20);
  const sh: Float32Array = probe.radianceSh();
  const shVar: Float32Array = probe.radianceShVariance();
  const frame: Frame = "z-up";
  const three: Float32Array = probe.threeJsSh(frame);
  // @ts-expect-error: the frame is "y-up" or "z-up"
  probe.threeJsSh("x-up");
  // @ts-expect-error: the frame is required
  probe.threeJsSh();
  let code: ProbeErrorCode | null = null;
  try {
    probe.irradiance([0, 0, 0]);
  } catch (err) {
    if (err instanceof ProbeError) code = err.code;
  }
  probe.dispose();
  const first: 16 = SIZES[0];
  return e.value[0] + e.variance[0] + g.value[1] + sh[0] + shVar[0] + three[0] + first + (code === "InvalidDirection" ? 1 : 0);
}

export async function pool(trace: (dirs: Float32Array) => Float32Array): Promise<number> {
  const probe: TemporalProbe = await TemporalProbe.create({ n: 64, seed: 1, footprint: "gaussian", hazard: 0.01 });
  const sentinels: Float32Array = probe.sentinels();
  let resets = 0;
  for (let frame = 0; frame < 8; frame++) {
    const change: Change = probe.pool(trace(probe.directions()), trace(sentinels));
    if (change === "reset") resets++;
  }
  const e: Estimate = probe.irradiance([0, 0, 1]);
  const evidence: ChangeEvidence = probe.lastEvidence;
  const footprint: Footprint = probe.footprint;
  const counts: number = probe.sampleCount + probe.sentinelCount + probe.degree + probe.sharpness + probe.hazard;
  const state: number = probe.updates + probe.pooledUpdates + probe.lastChangeProbability;
  const sh: Float32Array = probe.radianceSh();
  const shVar: Float32Array = probe.radianceShVariance();
  const n: ProbeSize = probe.n;
  probe.dispose();
  return e.value[0] + evidence.rotated + evidence.sentinels + (footprint === "point" ? 1 : 0) + counts + state + sh[0] +
    shVar[0] + n + resets;
}

export async function sensors(read: () => Float32Array): Promise<number> {
  const cube = [1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1];
  const prior: LayoutPrior = { squaredExponential: 4 };
  const probe: LayoutProbe = await LayoutProbe.create({
    directions: cube, powers: [1, 1, 1, 1, 2, 2], noiseScales: new Float32Array(6).fill(1),
    noise: { absolute: 0.01, relative: 0.02 }, prior, hazard: 1 / 32,
  });
  const dome = await LayoutProbe.create({ directions: new Float32Array(15), prior: "sky-above" });
  probe.update(read());
  const change: Change = probe.pool(read());
  const e: Estimate = probe.irradiance([0, 0, 1]);
  const exact: Float32Array = probe.irradianceVariance([0, 0, 1]);
  const glossy: Estimate = probe.phong([0, 1, 0], 20);
  const sh: Float32Array = probe.radianceSh();
  const k: LayoutSize = probe.k;
  const state: number = probe.pooledUpdates + probe.lastChangeProbability + probe.signalVariance[0] + probe.hazard;
  const updated: boolean = probe.updated;
  const first: 4 = LAYOUT_SIZES[0];
  const dirs: Float32Array = dome.directions();
  probe.dispose();
  dome.dispose();
  return e.value[0] + exact[0] + glossy.variance[0] + sh[0] + k + state + first + dirs[0] + (updated ? 1 : 0) +
    (change === "reset" ? 1 : 0);
}

export async function misuse(): Promise<void> {
  // @ts-expect-error: n is a number
  await Probe.create({ n: "64" });
  // @ts-expect-error: no such option
  await Probe.create({ size: 64 });
  // @ts-expect-error: the constructor is private; use Probe.create
  new Probe();
  const p = await Probe.create();
  // @ts-expect-error: glossy needs an exponent
  p.glossy([0, 0, 1]);
  // @ts-expect-error: the normal is an array of numbers
  p.irradiance("up");
  // @ts-expect-error: n is read-only
  p.n = 32;
  // @ts-expect-error: not a ProbeErrorCode
  const c: ProbeErrorCode = "NotACode";
  void c;
  // @ts-expect-error: no such footprint
  await TemporalProbe.create({ footprint: "cone" });
  // @ts-expect-error: the constructor is private; use TemporalProbe.create
  new TemporalProbe();
  const t = await TemporalProbe.create();
  // @ts-expect-error: pool needs the sentinel readings
  t.pool(new Float32Array(3 * t.sampleCount));
  // @ts-expect-error: pool's answer is a Change, not a boolean
  const reset: boolean = t.pool(new Float32Array(186), new Float32Array(6));
  void reset;
  // @ts-expect-error: pooledUpdates is read-only
  t.pooledUpdates = 4;
  // @ts-expect-error: a temporal probe pools; 0.1's update is pool
  t.update(new Float32Array(186), new Float32Array(6));
  // @ts-expect-error: 0.1's effectiveUpdates is pooledUpdates
  void t.effectiveUpdates;
  // @ts-expect-error: a layout probe needs its directions
  await LayoutProbe.create({ prior: "environment" });
  // @ts-expect-error: no such prior
  await LayoutProbe.create({ directions: [0, 0, 1, 0, 0, -1, 1, 0, 0, -1, 0, 0], prior: "sky" });
  // @ts-expect-error: the constructor is private; use LayoutProbe.create
  new LayoutProbe();
  const l = await LayoutProbe.create({ directions: new Float32Array(12) });
  // @ts-expect-error: phong needs an exponent
  l.phong([0, 0, 1]);
  // @ts-expect-error: pool's answer is a Change, not a boolean
  const blended: boolean = l.pool(new Float32Array(12));
  void blended;
  // @ts-expect-error: update replaces and answers nothing
  const replaced: Change = l.update(new Float32Array(12));
  void replaced;
  // @ts-expect-error: 0.1's accumulate is pool
  l.accumulate(new Float32Array(12));
  // @ts-expect-error: pooledUpdates is read-only
  l.pooledUpdates = 2;
}
