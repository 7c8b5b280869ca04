// The sphere-quadrature JS package driving three.js in headless Chromium (examples/threejs):
// serves the repository root on localhost, opens index.html (page.mjs) in Chromium (Debian
// `chromium`, through playwright-core) with WebGL2 on SwiftShader, and prints
//   1. conventions: a sphere lit only by a three.js LightProbe of the package's
//      `threeJsSh("z-up")`, rendered by WebGLRenderer into a float target and read back,
//      against the crate's SH irradiance E(n)/π at each pixel's normal; fails (exit 1) unless
//      every pixel with n·view > 0.2 is within 1 %;
//   2. a dynamic probe against three.js's own: the package's Probe fed from a CubeCamera's
//      HalfFloat cube render target against LightProbeGenerator.fromCubeRenderTarget on the
//      same target, irradiance error against a brute-force 256² reference and milliseconds
//      per update, readback included (printed, never asserted).
//
//   (cd examples/threejs && npm ci)
//   (cd examples/wasm && npm ci)                 # binaryen's wasm-opt for the package build
//   examples/wasm/package/build.sh               # the package's modules
//   node examples/threejs/driver.mjs [--out DIR] [--csv FILE] [--quick] [--map NAME]
//
// Options:
//   --out DIR    write DIR/threejs.md, the report (default target/threejs; `--out docs`
//                rewrites the committed docs/threejs.md)
//   --csv FILE   write the rows `threejs,<method>,<metric>,<value>` to FILE
//   --quick      3 timed repeats per method instead of 15 (CI)
//   --map NAME   the map of examples/envmaps for the conventions check (default park)
//   --help       this text
// Environment: CHROMIUM (default /usr/bin/chromium), TIMEOUT_MS (default 240000).
import { createServer } from "node:http";
import { mkdirSync, readFileSync, statSync, writeFileSync } from "node:fs";
import { dirname, extname, join, normalize, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const ROOT = resolve(fileURLToPath(new URL("../..", import.meta.url)));
const HELP = readFileSync(fileURLToPath(import.meta.url), "utf8").split("\nimport ")[0].replace(/^\/\/ ?/gm, "");
const opts = { out: "target/threejs", csv: null, quick: false, map: "park" };
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i++) {
  const a = argv[i];
  const value = () => {
    if (i + 1 >= argv.length) { console.error(`${a} needs a value`); process.exit(2); }
    return argv[++i];
  };
  if (a === "--help" || a === "-h") { console.log(HELP); process.exit(0); }
  else if (a === "--out") opts.out = value();
  else if (a === "--csv") opts.csv = value();
  else if (a === "--map") opts.map = value();
  else if (a === "--quick") opts.quick = true;
  else { console.error(`unknown option ${a}\n\n${HELP}`); process.exit(2); }
}
if (!/^[a-z]+$/.test(opts.map)) { console.error(`--map: a name of examples/envmaps, got ${opts.map}`); process.exit(2); }

const EXE = process.env.CHROMIUM ?? "/usr/bin/chromium";
const TIMEOUT = Number(process.env.TIMEOUT_MS ?? 240000);
const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".wasm": "application/wasm",
};
// Static files under ROOT, GET only, no directory listings, no escaping the root.
const server = createServer((req, res) => {
  const path = normalize(decodeURIComponent(new URL(req.url, "http://localhost").pathname));
  const file = join(ROOT, path);
  if (req.method !== "GET" || !(file === ROOT || file.startsWith(ROOT + sep))) {
    res.writeHead(403).end();
    return;
  }
  try {
    if (!statSync(file).isFile()) throw new Error("not a file");
    res.writeHead(200, { "content-type": TYPES[extname(file)] ?? "application/octet-stream" });
    res.end(readFileSync(file));
  } catch {
    res.writeHead(404).end();
  }
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const query = `map=${opts.map}&repeats=${opts.quick ? 3 : 15}`;
const url = `http://127.0.0.1:${server.address().port}/examples/threejs/index.html?${query}`;

// WebGL2 without a GPU: ANGLE on SwiftShader (EXT_color_buffer_float for the float targets).
const browser = await chromium.launch({
  executablePath: EXE,
  headless: true,
  args: [
    "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
    "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
  ],
});
let status = 1;
try {
  const page = await browser.newPage();
  const logs = [];
  page.on("console", (m) => logs.push(`console.${m.type()}: ${m.text()}`));
  page.on("pageerror", (e) => logs.push(`pageerror: ${e}`));
  await page.goto(url);
  await page.waitForSelector("#result[data-done]", { timeout: TIMEOUT });
  const { text, ok } = await page.$eval("#result", (el) => ({ text: el.textContent, ok: el.dataset.ok }));
  const r = JSON.parse(text);
  if (r.error) {
    console.log(`page error: ${r.error}`);
    for (const l of logs) console.log(l);
  } else {
    report(r);
    status = ok === "1" ? 0 : 1;
  }
} finally {
  await browser.close();
  server.close();
}
process.exit(status);

function report(r) {
  const pct = (x) => (x < 1e-4 ? `${(100 * x).toExponential(1)} %` : `${(100 * x).toFixed(x < 0.001 ? 4 : 2)} %`);
  const c = r.conventions;
  const lines = [];
  lines.push("# sphere-quadrature × three.js");
  lines.push("");
  lines.push(`Generated by \`node examples/threejs/driver.mjs${opts.quick ? " --quick" : ""} --out DIR\` (examples/threejs):`);
  lines.push(`three.js r${r.info.three} \`WebGLRenderer\`, WebGL2 on \`${r.info.renderer}\` in headless Chromium,`);
  lines.push(`EXT_color_buffer_float ${r.info.colorBufferFloat ? "present" : "absent"}.`);
  lines.push("");
  lines.push("## 1. Conventions: the package's SH export lighting a three.js sphere");
  lines.push("");
  lines.push(`A \`Probe\` (N = ${c.n}) of the JS package sampled \`${c.map}.hdr\` (examples/envmaps), turned by`);
  lines.push("1.1 rad about the axis (0.31, 0.8, 0.52), in the crate's z-up frame. `threeJsSh(\"z-up\")` lights a");
  lines.push("white `MeshLambertMaterial` sphere through a `LightProbe` (intensity 1), rendered into a");
  lines.push(`${c.size}² \`FloatType\` target without tone mapping and read back. Each pixel is compared with`);
  lines.push("E(n)/π, E the irradiance of the probe's own z-up coefficients `radianceSh()` at the z-up normal");
  lines.push("n = (m.x, −m.z, m.y) of the pixel's world normal m (a second pass of the same mesh writes m),");
  lines.push("evaluated in the page by the crate's formula (`ShL2::irradiance`: Σ Â_l·c_lm·Y_lm(n), Â = π, 2π/3,");
  lines.push("π/4, full-precision constants). three.js's `shGetIrradianceAt` returns E, and `BRDF_Lambert`");
  lines.push("multiplies it by albedo/π. The last column reads the same coefficients as if they were");
  lines.push("three.js's already (E at m): what a missing rotation would render.");
  lines.push("");
  lines.push("| pixels (n·view > 0.2) | max relative error | mean relative error | the same coefficients unrotated: max, mean |");
  lines.push("| ---: | ---: | ---: | ---: |");
  lines.push(`| ${c.pixels} | ${pct(c.maxRel)} | ${pct(c.meanRel)} | ${pct(c.unrotatedMaxRel)}, ${pct(c.unrotatedMeanRel)} |`);
  lines.push("");
  const w = c.worst;
  lines.push(`Largest error: ${w.rendered.toPrecision(6)} rendered, ${w.expected.toPrecision(6)} expected (channel ${"rgb"[w.channel]}).`);
  lines.push(`The check passes at a maximum of 1 %: ${c.ok ? "passed" : "FAILED"}.`);
  const d = r.dynamic;
  if (d) {
    lines.push("");
    lines.push("## 2. A dynamic probe against three.js's LightProbeGenerator");
    lines.push("");
    lines.push(`A room (coloured walls, three boxes, an emissive panel) rendered by a \`CubeCamera\` into a`);
    lines.push(`${d.cube}² \`HalfFloatType\` cube render target. \`LightProbeGenerator.fromCubeRenderTarget\` reads`);
    lines.push("back its six faces and projects every texel; the package's `Probe` takes N point samples, one");
    lines.push("bilinear texel lookup per direction (level 0) by a shader into an N × 1 float target, N texels");
    lines.push("read back, `update`, then `threeJsSh(\"y-up\")`. The `TemporalProbe` with `footprint: \"gaussian\"`");
    lines.push("(sharpness N/8) reads each of its directions and sentinels as 32 lookups drawn from that");
    lines.push("Gaussian on the mip level whose texels are half its width, then `pool`s: `-1` after the first");
    lines.push("update, `-8` after eight of the static room (a fresh rotation each). Error: relative RMS (and largest relative");
    lines.push(`error) of the irradiance at ${d.normals} Fibonacci normals against the brute-force integral of a ${d.referenceSize}²`);
    lines.push("`FloatType` cube render of the same scene (each texel weighted by its exact solid angle).");
    lines.push(`Time: median of ${d.repeats} updates, readback included, the cube render itself excluded (the same for`);
    lines.push("all); on SwiftShader, a CPU rasteriser, so the ratios and not the milliseconds carry over.");
    lines.push("");
    lines.push("| method | samples | irradiance error (RMS) | largest | SH export error (RMS) | ms per update | error / LPG | time / LPG |");
    lines.push("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (const m of d.methods) {
      const sh = m.shRms === undefined ? "—" : pct(m.shRms);
      lines.push(`| \`${m.method}\` | ${m.samples} | ${pct(m.rms)} | ${pct(m.max)} | ${sh} | ${m.ms.toFixed(2)} | ${m.errorRatio.toFixed(2)} | ${m.timeRatio.toFixed(3)} |`);
    }
    lines.push("");
    lines.push("The package's irradiance is the probe's own (`Probe.irradiance`, `TemporalProbe.irradiance`);");
    lines.push("the SH export column is the irradiance three.js shades from `threeJsSh(\"y-up\")` (its");
    lines.push("`getIrradianceAt`), which keeps degrees ≤ 2 only, as `LightProbeGenerator`'s does.");
    const g = d.grid;
    if (g) {
      lines.push("");
      lines.push("### three.js's LightProbeGridWebGL");
      lines.push("");
      lines.push("A `LightProbeGridWebGL` of 3 × 3 × 3 probes 0.02 apart (the room is 6 wide) about the same point renders its own");
      lines.push(`${d.cube}² cubes and projects them to SH on the GPU, into a 3D texture: nothing is read back. Its`);
      lines.push("irradiance is read through rendering: a white `MeshLambertMaterial` ball (radius 0.015) at the");
      lines.push("point lit by the grid alone, E = π·pixel at each pixel's world normal (the shader samples the");
      lines.push("grid half a cell off the surface, so the centre probe cannot be read alone, and its close");
      lines.push(`neighbours blend in). Relative RMS error at the ball's ${g.normals} visible`);
      lines.push("normals (n·view > 0.2) against the brute-force reference at those normals, with the other");
      lines.push("methods' irradiance at the same normals:");
      lines.push("");
      lines.push("| method | irradiance error (RMS), visible hemisphere |");
      lines.push("| --- | ---: |");
      lines.push(`| \`LightProbeGridWebGL\` | ${pct(g.grid)} |`);
      lines.push(`| \`light-probe-generator\` | ${pct(g.lpg)} |`);
      lines.push(`| \`package-temporal-64-gaussian-1\` | ${pct(g.temporal)} |`);
      lines.push("");
      lines.push(`Baking the centre probe alone (\`start: 13, count: 1\`, with \`gl.finish()\` after it) takes ${g.ms.toFixed(2)} ms`);
      lines.push("(median), its SH left on the GPU; the other methods' times above include reading back.");
    }
    const mv = d.moving;
    if (mv) {
      const pct1 = (x) => `${(100 * x).toFixed(2)} %`;
      const mean = (xs) => xs.reduce((a, b) => a + b, 0) / xs.length;
      lines.push("");
      lines.push("### A moving light");
      lines.push("");
      lines.push(`The panel slides 3.5 units (the room is 6 wide) along the ceiling over ${mv.frames} frames; the cube target is re-rendered every frame.`);
      lines.push("`LightProbeGenerator` projects each frame's target; a `TemporalProbe` (N = 64, Gaussian footprint)");
      lines.push("pools one update per frame, forgetting old evidence by its probability of a change (prior");
      lines.push("probability `hazard` per update: the default 1/64, and 1/4). Irradiance");
      lines.push("error (relative RMS over the 64 normals) against each frame's brute-force reference:");
      lines.push("");
      lines.push(`| frame | ${mv.lpg.map((_, i) => i + 1).join(" | ")} | mean |`);
      lines.push(`| --- | ${mv.lpg.map(() => "---:").join(" | ")} | ---: |`);
      lines.push(`| \`LightProbeGenerator\` | ${mv.lpg.map(pct1).join(" | ")} | ${pct1(mean(mv.lpg))} |`);
      for (const t of mv.temporal) {
        lines.push(`| \`TemporalProbe\`, hazard 1/${Math.round(1 / t.hazard)} | ${t.errors.map(pct1).join(" | ")} | ${pct1(mean(t.errors))} |`);
      }
      lines.push("");
      for (const t of mv.temporal) {
        lines.push(`What \`pool\` did at hazard 1/${Math.round(1 / t.hazard)}: ${Object.entries(t.changes).map(([k, v]) => `${k} ${v}`).join(", ")}.`);
      }
    }
  }
  const md = `${lines.join("\n")}\n`;
  console.log(md);
  const outDir = resolve(ROOT, opts.out);
  mkdirSync(outDir, { recursive: true });
  writeFileSync(join(outDir, "threejs.md"), md);
  console.log(`wrote ${join(outDir, "threejs.md")}`);
  if (opts.csv) {
    const file = resolve(process.cwd(), opts.csv);
    mkdirSync(dirname(file), { recursive: true });
    writeFileSync(file, `${r.rows.join("\n")}\n`);
    console.log(`wrote ${r.rows.length} rows to ${file}`);
  }
}
