// Type check of the package's index.d.ts from a consumer (tsc --noEmit, test/run.sh): the
// README's usage compiles, misuse does not (each @ts-expect-error must meet an error).
import { Probe, ProbeError, SIZES, type Estimate, type ProbeErrorCode, type ProbeSize } from "sphere-quadrature";

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
  let code: ProbeErrorCode | null = null;
  try {
    probe.irradiance([0, 0, 0]);
  } catch (err) {
    if (err instanceof ProbeError) code = err.code;
  }
  probe.dispose();
  const first: 16 = SIZES[0];
  return e.value[0] + e.variance[0] + g.value[1] + sh[0] + shVar[0] + first + (code === "InvalidDirection" ? 1 : 0);
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
}
