// Rough per-call timings of the package in Node (not run by CI): from the consumer project
// that test/run.sh installs, `node bench.mjs`.
import { Probe, TemporalProbe } from "sphere-quadrature";
for (const n of [16, 64, 256]) {
  const p = await Probe.create({ n, seed: 1 });
  const d = p.directions();
  const ys = Float32Array.from({ length: 3 * n }, (_, k) => 1 + 0.5 * d[k - (k % 3) + 2] + (k % 3));
  const time = (f, reps) => { f(); const t = performance.now(); for (let i = 0; i < reps; i++) f(); return (1000 * (performance.now() - t)) / reps; };
  const u = time(() => p.update(ys), n === 256 ? 50 : 500);
  const i = time(() => p.irradiance([0.2, 0.3, 1]), 5000);
  const g = time(() => p.glossy([0.2, 0.3, 1], 20), n === 256 ? 500 : 5000);
  const s = time(() => p.radianceSh(), 5000);
  const v = time(() => p.radianceShVariance(), n === 256 ? 200 : 2000);
  console.log(`N=${n}: update ${u.toFixed(1)} µs, irradiance ${i.toFixed(2)} µs, glossy ${g.toFixed(1)} µs, radianceSh ${s.toFixed(2)} µs, radianceShVariance ${v.toFixed(1)} µs`);
}
for (const n of [16, 64, 256]) {
  for (const footprint of ["point", "gaussian"]) {
    const t = await TemporalProbe.create({ n, seed: 1, footprint });
    const ss = Float32Array.from({ length: 3 * t.sentinelCount }, (_, k) => 1 + (k % 3));
    const ys = () => {
      const d = t.directions();
      return Float32Array.from({ length: d.length }, (_, k) => 1 + 0.5 * d[k - (k % 3) + 2] + (k % 3));
    };
    const time = (f, reps) => { f(); const s = performance.now(); for (let i = 0; i < reps; i++) f(); return (1000 * (performance.now() - s)) / reps; };
    const u = time(() => t.update(ys(), ss), n === 256 ? 100 : 500);
    const i = time(() => t.irradiance([0.2, 0.3, 1]), 5000);
    const s = time(() => t.radianceSh(), 5000);
    console.log(`N=${n} temporal ${footprint}: update ${u.toFixed(1)} µs (directions included), irradiance ${i.toFixed(2)} µs, radianceSh ${s.toFixed(2)} µs`);
    t.dispose();
  }
}
