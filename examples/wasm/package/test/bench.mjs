// Rough per-call timings of the package in Node (not run by CI): from the consumer project
// that test/run.sh installs, `node bench.mjs`.
import { LayoutProbe, Probe, TemporalProbe } from "sphere-quadrature";
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
    const u = time(() => t.pool(ys(), ss), n === 256 ? 100 : 500);
    const i = time(() => t.irradiance([0.2, 0.3, 1]), 5000);
    const s = time(() => t.radianceSh(), 5000);
    console.log(`N=${n} temporal ${footprint}: pool ${u.toFixed(1)} µs (directions included), irradiance ${i.toFixed(2)} µs, radianceSh ${s.toFixed(2)} µs`);
    t.dispose();
  }
}
// The layout module is loaded by the first create(): not timed.
(await LayoutProbe.create({ directions: [1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1] })).dispose();
for (const k of [5, 6, 16]) {
  const dirs = new Float32Array(3 * k);
  for (let i = 0; i < k; i++) {
    const z = 1 - (2 * i + 1) / k, r = Math.sqrt(1 - z * z), phi = 2.399963229728653 * i;
    dirs.set([r * Math.cos(phi), r * Math.sin(phi), z], 3 * i);
  }
  const time = (f, reps) => { f(); const s = performance.now(); for (let i = 0; i < reps; i++) f(); return (1000 * (performance.now() - s)) / reps; };
  // create() is async (the module is loaded once): timed with its await.
  const t0 = performance.now();
  for (let i = 0; i < 20; i++) (await LayoutProbe.create({ directions: dirs, noise: { absolute: 0.01, relative: 0.02 } })).dispose();
  const created = (1000 * (performance.now() - t0)) / 20;
  const p = await LayoutProbe.create({ directions: dirs, noise: { absolute: 0.01, relative: 0.02 } });
  const ys = Float32Array.from({ length: 3 * k }, (_, j) => 1 + 0.5 * dirs[j - (j % 3) + 2] + (j % 3));
  const noisy = () => ys.map((v, j) => v * (1 + 0.01 * Math.sin(7 * j + performance.now())));
  const u = time(() => p.update(ys), 500);
  const a = time(() => p.pool(noisy()), 500);
  const i = time(() => p.irradiance([0.2, 0.3, 1]), 5000);
  const v = time(() => p.irradianceVariance([0.2, 0.3, 1]), 5000);
  const g = time(() => p.phong([0.2, 0.3, 1], 20), 2000);
  const s = time(() => p.radianceSh(), 5000);
  console.log(`K=${k} layout: create ${created.toFixed(0)} µs, update ${u.toFixed(1)} µs, pool ${a.toFixed(1)} µs, irradiance ${i.toFixed(2)} µs, irradianceVariance ${v.toFixed(2)} µs, phong ${g.toFixed(1)} µs, radianceSh ${s.toFixed(2)} µs`);
  p.dispose();
}
