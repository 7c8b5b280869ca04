// Headless browser test of examples/wasm/index.html: serves the repository root on localhost,
// opens the page in Chromium (Debian `chromium`, through playwright-core), waits for the page's
// own numeric check (the probes against the reference, the JS package, and the temporal probe
// against DDGI's blend across a switch of the light), prints its numbers, saves a screenshot
// (target/wasm_probe.png) and exits non-zero when the check fails.
//
//   (cd examples/wasm && npm ci && cargo build --release --target wasm32-unknown-unknown)
//   examples/wasm/package/build.sh      # the JS package's modules (the page's BMC probe)
//   node examples/wasm/browser_test.mjs
//
// Environment: CHROMIUM (default /usr/bin/chromium), SCREENSHOT (default target/wasm_probe.png;
// SCREENSHOT=docs/wasm_probe.png updates the committed one),
// TIMEOUT_MS (default 120000).
import { createServer } from "node:http";
import { readFileSync, statSync } from "node:fs";
import { extname, join, normalize, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const ROOT = resolve(fileURLToPath(new URL("../..", import.meta.url)));
const SHOT = resolve(ROOT, process.env.SCREENSHOT ?? "target/wasm_probe.png");
const EXE = process.env.CHROMIUM ?? "/usr/bin/chromium";
const TIMEOUT = Number(process.env.TIMEOUT_MS ?? 120000);
const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".wasm": "application/wasm",
  ".hdr": "application/octet-stream",
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
    const body = readFileSync(file);
    res.writeHead(200, { "content-type": TYPES[extname(file)] ?? "application/octet-stream" });
    res.end(body);
  } catch {
    res.writeHead(404).end();
  }
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const url = `http://127.0.0.1:${server.address().port}/examples/wasm/index.html`;

// `launch` runs headless with a fresh temporary profile (--user-data-dir) of its own.
const browser = await chromium.launch({
  executablePath: EXE,
  headless: true,
  args: [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
  ],
});
let status = 1;
try {
  const page = await browser.newPage({ viewport: { width: 1240, height: 900 } });
  const logs = [];
  page.on("console", (m) => logs.push(`console.${m.type()}: ${m.text()}`));
  page.on("pageerror", (e) => logs.push(`pageerror: ${e}`));
  await page.goto(url);
  await page.waitForSelector("#check[data-done]", { timeout: TIMEOUT });
  const r = await page.$eval("#check", (el) => ({ ...el.dataset, text: el.textContent }));
  const stats = await page.$eval("#status", (el) => el.textContent);
  await page.screenshot({ path: SHOT, fullPage: true });
  console.log(r.text);
  const pct = (x) => `${(100 * x).toFixed(2)} %`;
  for (const m of JSON.parse(r.perMap ?? "[]")) {
    console.log(
      `  ${m.name.padEnd(9)} diffuse: point BMC ${pct(m.bd)}, cos avg ${pct(m.ad)}, footprint BMC ${pct(m.fd)} ` +
        `(pyramid ${pct(m.pd)}, ratio to cos avg ${(m.fd / m.ad).toFixed(3)}), cos avg of footprint samples ${pct(m.fad)}; ` +
        `glossy: point BMC ${pct(m.bg)}, lobe avg ${pct(m.ag)}, footprint BMC ${pct(m.fg)} (pyramid ${pct(m.pg)}), ` +
        `lobe avg of footprint samples ${pct(m.fag)}; pyramid deviation ${(100 * m.dev).toFixed(3)} %`,
    );
  }
  console.log(`JS package: ${r.packageIdentical} values equal to bmc_shade bit for bit; errors ${r.packageErrors}`);
  const fig = (m) =>
    `temporal ${pct(m.t1)} after 1 update, ${pct(m.tStatic)} after 32 static (DDGI ${pct(m.dStatic)}); ` +
    `switch: ${pct(m.tSwitch)}, +4 ${pct(m.tLag)} (DDGI ${pct(m.dLag)}), +32 ${pct(m.tEnd)} (DDGI ${pct(m.dEnd)}, ` +
    `running mean ${pct(m.mEnd)}); reset at the switch ${pct(m.detected)}, static resets ${m.falseResets}`;
  for (const m of JSON.parse(r.temporalPerMap ?? "[]")) console.log(`  ${m.name.padEnd(19)} ${fig(m)}`);
  // The temporal figures must be there (the page's verdicts use them).
  const t = JSON.parse(r.temporal ?? "null");
  if (t === null || !Number.isFinite(t.tStatic)) throw new Error("the page reported no temporal figures");
  console.log(`temporal, mean over maps: ${fig(t)}`);
  console.log(`timing: ${stats}`);
  console.log(`screenshot: ${SHOT}`);
  for (const l of logs) console.log(l);
  status = r.pass === "true" ? 0 : 1;
} catch (e) {
  console.error(`browser test error: ${e}`);
} finally {
  await browser.close();
  server.close();
}
process.exit(status);
