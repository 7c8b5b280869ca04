// The page of examples/threejs (index.html; driver.mjs opens it in headless Chromium): the
// sphere-quadrature JS package driving three.js's WebGLRenderer (WebGL2), no mocks.
//
// 1. Conventions. A probe of the package is fed a real map (examples/envmaps, turned by a
//    rotation that leaves no axis of symmetry), in the crate's z-up frame. Its three.js export
//    `threeJsSh("z-up")` lights a white MeshLambertMaterial sphere through a LightProbe; the
//    sphere is rendered into a float render target (no tone mapping, linear colour) and read
//    back, and a second pass of the same mesh writes each pixel's world normal m. Every pixel
//    with m·view > 0.2 must equal E(n)/π (albedo 1 times three.js's BRDF_Lambert = 1/π), E
//    the irradiance of the probe's z-up SH coefficients `radianceSh()` at the z-up normal
//    n = (m.x, −m.z, m.y), by the crate's formula (ShL2::irradiance, Σ Â_l·c_lm·Y_lm(n),
//    evaluated here), within 1 %.
// 2. A dynamic probe against three.js's own. A room of coloured walls, boxes and an emissive
//    panel is rendered by a CubeCamera into a HalfFloat cube render target. The package's
//    Probe (point samples: one texel lookup per direction, by a shader into an N×1 float
//    target, N texels read back), its TemporalProbe with the Gaussian footprint (32 lookups
//    per direction on a mip level) and LightProbeGenerator.fromCubeRenderTarget (all six
//    faces read back and projected) run on that same render target; both are compared with the
//    brute-force irradiance of a 256² float cube render of the scene, and timed per update,
//    readback included.
//
// Results go to #result (JSON) with data-done; data-ok says whether the conventions check passed.
import * as THREE from "three";
import { HDRLoader } from "three/addons/loaders/HDRLoader.js";
import { LightProbeGenerator } from "three/addons/lights/LightProbeGenerator.js";
import { LightProbeGridWebGL } from "three/addons/lighting/LightProbeGridWebGL.js";
import { Probe, TemporalProbe } from "sphere-quadrature";

const params = new URLSearchParams(location.search);
const MAP = params.get("map") ?? "park";
const REPEATS = Number(params.get("repeats") ?? 15);
const out = document.getElementById("result");

const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.setSize(16, 16);
renderer.toneMapping = THREE.NoToneMapping;
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
const gl = renderer.getContext();
const info = {
  three: THREE.REVISION,
  webgl2: renderer.capabilities.isWebGL2 !== false,
  colorBufferFloat: renderer.extensions.has("EXT_color_buffer_float"),
  renderer: (() => {
    const ext = gl.getExtension("WEBGL_debug_renderer_info");
    return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
  })(),
};

// ---- the crate's SH irradiance: E(n) = Σ Â_l·c_lm·Y_lm(n) (src/sh.rs, "Irradiance"), channel c
// of 27 floats (r, g, b per coefficient), unit n in the frame of the coefficients.
const Y0 = 0.5 * Math.sqrt(1 / Math.PI), Y1 = 0.5 * Math.sqrt(3 / Math.PI), Y2 = 0.5 * Math.sqrt(15 / Math.PI);
const Y20 = 0.25 * Math.sqrt(5 / Math.PI), Y22 = 0.25 * Math.sqrt(15 / Math.PI);
function shIrradiance(sh, [x, y, z], c) {
  const k = (i) => sh[3 * i + c];
  return Math.PI * Y0 * k(0) + ((2 * Math.PI) / 3) * Y1 * (k(1) * y + k(2) * z + k(3) * x) +
    (Math.PI / 4) * (Y2 * (k(4) * x * y + k(5) * y * z + k(7) * x * z) + Y20 * k(6) * (3 * z * z - 1) + Y22 * k(8) * (x * x - y * y));
}

// ---- 1. Conventions -------------------------------------------------------------------------
async function conventions() {
  const tex = await new HDRLoader().setDataType(THREE.FloatType).loadAsync(`../envmaps/${MAP}.hdr`);
  const { data, width: W, height: H } = tex.image;
  // L(d) for a z-up direction d: the map (θ from +z, φ = atan2(y, x); row 0 at θ = 0, bilinear)
  // at Rᵀd, R a rotation about an oblique axis.
  const R = new THREE.Matrix4().makeRotationAxis(new THREE.Vector3(0.31, 0.8, 0.52).normalize(), 1.1);
  const Rt = R.clone().transpose();
  const v = new THREE.Vector3();
  const texel = (i, j, c) => data[4 * (Math.min(H - 1, Math.max(0, j)) * W + (((i % W) + W) % W)) + c];
  const radiance = (d) => {
    v.set(d[0], d[1], d[2]).applyMatrix4(Rt).normalize();
    const theta = Math.acos(Math.min(1, Math.max(-1, v.z)));
    const phi = Math.atan2(v.y, v.x);
    const fx = ((phi / (2 * Math.PI) + 0.5) * W) - 0.5, fy = (theta / Math.PI) * H - 0.5;
    const i0 = Math.floor(fx), j0 = Math.floor(fy), tx = fx - i0, ty = fy - j0;
    return [0, 1, 2].map((c) =>
      (1 - ty) * ((1 - tx) * texel(i0, j0, c) + tx * texel(i0 + 1, j0, c)) + ty * ((1 - tx) * texel(i0, j0 + 1, c) + tx * texel(i0 + 1, j0 + 1, c)));
  };
  const probe = await Probe.create({ n: 256, seed: 7 });
  const dirs = probe.directions();
  const samples = new Float32Array(3 * probe.n);
  for (let j = 0; j < probe.n; j++) samples.set(radiance([dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2]]), 3 * j);
  probe.update(samples);
  const shZ = probe.radianceSh(); // the crate's frame, z-up
  const shThree = probe.threeJsSh("z-up");
  probe.dispose();

  const S = 256;
  const scene = new THREE.Scene();
  const light = new THREE.LightProbe();
  light.sh.fromArray(shThree);
  light.intensity = 1;
  scene.add(light);
  const geometry = new THREE.SphereGeometry(1, 256, 128);
  const sphere = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({ color: new THREE.Color(1, 1, 1) }));
  scene.add(sphere);
  const camera = new THREE.OrthographicCamera(-1.05, 1.05, 1.05, -1.05, 0.1, 10);
  const eye = new THREE.Vector3(2.2, 1.3, 1.7).normalize();
  camera.position.copy(eye).multiplyScalar(4);
  camera.lookAt(0, 0, 0);
  const target = new THREE.WebGLRenderTarget(S, S, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: true });
  const read = () => {
    const px = new Float32Array(S * S * 4);
    renderer.readRenderTargetPixels(target, 0, 0, S, S, px);
    return px;
  };
  renderer.setClearColor(0x000000, 0);
  renderer.setRenderTarget(target);
  renderer.clear();
  renderer.render(scene, camera);
  const shaded = read();
  // The same mesh, its interpolated world normal per pixel (the Lambert pass interpolates the
  // same vertex normals), alpha 1 on the sphere.
  sphere.material = new THREE.ShaderMaterial({
    vertexShader: `varying vec3 vN;
      void main() { vN = normalize(mat3(modelMatrix) * normal); gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
    fragmentShader: `varying vec3 vN;
      void main() { gl_FragColor = vec4(normalize(vN), 1.0); }`,
  });
  renderer.clear();
  renderer.render(scene, camera);
  const normals = read();
  renderer.setRenderTarget(null);

  let count = 0, max = 0, sum = 0, wrongMax = 0, wrongSum = 0, worst = null;
  for (let p = 0; p < S * S; p++) {
    if (normals[4 * p + 3] < 0.5) continue;
    const m = [normals[4 * p], normals[4 * p + 1], normals[4 * p + 2]];
    const len = Math.hypot(...m);
    m[0] /= len; m[1] /= len; m[2] /= len;
    if (m[0] * eye.x + m[1] * eye.y + m[2] * eye.z <= 0.2) continue;
    const n = [m[0], -m[2], m[1]]; // the z-up normal whose y-up image is m
    count++;
    for (let c = 0; c < 3; c++) {
      const want = shIrradiance(shZ, n, c) / Math.PI;
      const err = Math.abs(shaded[4 * p + c] - want) / Math.abs(want);
      sum += err;
      if (err > max) {
        max = err;
        worst = { pixel: p, channel: c, rendered: shaded[4 * p + c], expected: want };
      }
      // The control: the same coefficients read as if they were in three.js's frame already.
      const wrong = Math.abs(shaded[4 * p + c] - shIrradiance(shZ, m, c) / Math.PI) / Math.abs(want);
      wrongSum += wrong;
      wrongMax = Math.max(wrongMax, wrong);
    }
  }
  target.dispose();
  geometry.dispose();
  return {
    map: MAP, n: 256, size: S, pixels: count, maxRel: max, meanRel: sum / (3 * count),
    unrotatedMaxRel: wrongMax, unrotatedMeanRel: wrongSum / (3 * count), worst,
    ok: count > 0.4 * S * S * (Math.PI / 4) && max <= 0.01,
  };
}

// ---- 2. A dynamic probe against three.js's own -----------------------------------------------
function room() {
  const scene = new THREE.Scene();
  const basic = (r, g, b, side = THREE.FrontSide) => new THREE.MeshBasicMaterial({ color: new THREE.Color(r, g, b), side });
  // Walls +x, −x, +y (ceiling), −y (floor), +z, −z.
  const walls = [[0.6, 0.12, 0.1], [0.1, 0.45, 0.15], [0.35, 0.35, 0.38], [0.3, 0.22, 0.15], [0.15, 0.2, 0.55], [0.5, 0.48, 0.42]]
    .map(([r, g, b]) => basic(r, g, b, THREE.BackSide));
  scene.add(new THREE.Mesh(new THREE.BoxGeometry(6, 4, 6), walls));
  const panel = new THREE.Mesh(new THREE.PlaneGeometry(1.6, 1.0), basic(14, 12, 9, THREE.DoubleSide));
  panel.rotation.x = Math.PI / 2; // facing down
  panel.position.set(1.2, 1.99, -0.6);
  scene.add(panel);
  scene.userData.panel = panel;
  for (const [x, y, z, sx, sy, sz, r, g, b] of [
    [-1.6, -1.4, -1.2, 1.0, 1.2, 1.0, 0.8, 0.7, 0.1],
    [1.8, -1.5, 1.4, 0.8, 1.0, 1.4, 0.1, 0.6, 0.7],
    [-0.6, -1.7, 1.9, 1.6, 0.6, 0.8, 0.7, 0.1, 0.6],
  ]) {
    const box = new THREE.Mesh(new THREE.BoxGeometry(sx, sy, sz), basic(r, g, b));
    box.position.set(x, y, z);
    scene.add(box);
  }
  return scene;
}
const PROBE_AT = new THREE.Vector3(0.3, 0.1, -0.2);

/** The direction of texel `i` of face `face` of a w × w cube render target (LightProbeGenerator's WebGL mapping). */
function faceCoord(face, i, w, out) {
  const flip = -1, ps = 2 / w;
  const col = (1 - ((i % w) + 0.5) * ps) * flip, row = 1 - (Math.floor(i / w) + 0.5) * ps;
  switch (face) {
    case 0: out.set(-1 * flip, row, col * flip); break;
    case 1: out.set(1 * flip, row, -col * flip); break;
    case 2: out.set(col, 1, -row); break;
    case 3: out.set(col, -1, row); break;
    case 4: out.set(col, row, 1); break;
    default: out.set(-col, row, -1);
  }
  return out;
}

/** Fibonacci unit normals. */
function fibonacci(k) {
  const g = Math.PI * (3 - Math.sqrt(5));
  return Array.from({ length: k }, (_, i) => {
    const y = 1 - (2 * (i + 0.5)) / k, r = Math.sqrt(1 - y * y);
    return [Math.cos(g * i) * r, y, Math.sin(g * i) * r];
  });
}

async function dynamic() {
  const scene = room();
  const median = (xs) => xs.slice().sort((a, b) => a - b)[Math.floor(xs.length / 2)];
  // The reference: a 256² float cube render, every texel weighted by its exact solid angle.
  const RW = 256;
  const refTarget = new THREE.WebGLCubeRenderTarget(RW, { type: THREE.FloatType });
  const refCamera = new THREE.CubeCamera(0.05, 100, refTarget);
  refCamera.position.copy(PROBE_AT);
  const normals = fibonacci(64);
  const face = new Float32Array(RW * RW * 4);
  const d = new THREE.Vector3();
  const A = (x, y) => Math.atan2(x * y, Math.sqrt(x * x + y * y + 1));
  /** The brute-force irradiance of the scene at `normals`, from a fresh 256² float cube render. */
  const brute = (at = normals) => {
    refCamera.update(renderer, scene);
    const irr = at.map(() => [0, 0, 0]);
    for (let f = 0; f < 6; f++) {
      renderer.readRenderTargetPixels(refTarget, 0, 0, RW, RW, face, f);
      for (let i = 0; i < RW * RW; i++) {
        faceCoord(f, i, RW, d);
        const u0 = -1 + 2 * (i % RW) / RW, v0 = -1 + 2 * Math.floor(i / RW) / RW, h = 2 / RW;
        const omega = A(u0, v0) - A(u0, v0 + h) - A(u0 + h, v0) + A(u0 + h, v0 + h);
        d.normalize();
        for (let k = 0; k < at.length; k++) {
          const [nx, ny, nz] = at[k];
          const t = nx * d.x + ny * d.y + nz * d.z;
          if (t <= 0) continue;
          const w = omega * t, r = irr[k];
          r[0] += w * face[4 * i]; r[1] += w * face[4 * i + 1]; r[2] += w * face[4 * i + 2];
        }
      }
    }
    return irr;
  };
  let reference = brute();
  const errorOf = (irr) => {
    let num = 0, den = 0, max = 0;
    normals.forEach((n, k) => {
      const e = irr(n);
      for (let c = 0; c < 3; c++) {
        num += (e[c] - reference[k][c]) ** 2;
        den += reference[k][c] ** 2;
        max = Math.max(max, Math.abs(e[c] - reference[k][c]) / reference[k][c]);
      }
    });
    return { rms: Math.sqrt(num / den), max };
  };

  // The dynamic probe's render target: HalfFloat, mipmapped, as an engine keeps it.
  const CW = Number(params.get("cube") ?? 64);
  const cubeTarget = new THREE.WebGLCubeRenderTarget(CW, {
    type: THREE.HalfFloatType, generateMipmaps: true, minFilter: THREE.LinearMipmapLinearFilter,
  });
  const cubeCamera = new THREE.CubeCamera(0.05, 100, cubeTarget);
  cubeCamera.position.copy(PROBE_AT);
  cubeCamera.update(renderer, scene);

  const rows = [];
  const results = { cube: CW, referenceSize: RW, normals: normals.length, repeats: REPEATS, methods: [] };
  const vec = new THREE.Vector3(), col = new THREE.Vector3();

  // three.js: LightProbeGenerator.fromCubeRenderTarget (6 faces read back, projected on the CPU).
  let lpg;
  const lpgTimes = [];
  for (let r = 0; r < REPEATS + 2; r++) {
    gl.finish();
    const t0 = performance.now();
    lpg = await LightProbeGenerator.fromCubeRenderTarget(renderer, cubeTarget);
    const t1 = performance.now();
    if (r >= 2) lpgTimes.push(t1 - t0);
  }
  const lpgErr = errorOf((n) => lpg.sh.getIrradianceAt(vec.set(...n), col).toArray());
  results.methods.push({ method: "light-probe-generator", samples: 6 * CW * CW, ...lpgErr, ms: median(lpgTimes) });

  // The package's probes read the same render target through a shader: per direction one
  // bilinear texel lookup at level 0 (point samples), or the normalised spherical Gaussian
  // exp(S(t − 1)) of the footprint probe as TAPS lookups drawn from it (t by its inverse CDF,
  // azimuths on the golden angle, equal weights) at the mip level whose texels are half the
  // Gaussian's width σ = 1/√S; written to an N × 1 float target and read back.
  const quadCamera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
  const TAPS = 32;
  function gatherer(n, sharpness) {
    const dirData = new Float32Array(4 * n);
    const dirTex = new THREE.DataTexture(dirData, n, 1, THREE.RGBAFormat, THREE.FloatType);
    const taps = [];
    for (let i = 0; i < TAPS; i++) {
      const u = (i + 0.5) / TAPS;
      const t = sharpness > 0 ? 1 + Math.log(1 - u * (1 - Math.exp(-2 * sharpness))) / sharpness : 1;
      const r = Math.sqrt(Math.max(0, 1 - t * t)), phi = i * Math.PI * (3 - Math.sqrt(5));
      taps.push(new THREE.Vector3(r * Math.cos(phi), r * Math.sin(phi), t));
    }
    const lod = sharpness > 0 ? Math.max(0, Math.log2((CW * (1 / Math.sqrt(sharpness))) / Math.PI)) : 0;
    const target = new THREE.WebGLRenderTarget(n, 1, { type: THREE.FloatType, depthBuffer: false });
    const mesh = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), new THREE.ShaderMaterial({
      uniforms: { env: { value: cubeTarget.texture }, dirs: { value: dirTex }, taps: { value: taps }, lod: { value: lod } },
      defines: { TAPS: sharpness > 0 ? TAPS : 1 },
      vertexShader: "void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }",
      // CubeCamera targets are sampled unflipped (three.js's flipEnvMap is 1 for them).
      fragmentShader: `uniform samplerCube env; uniform sampler2D dirs; uniform vec3 taps[TAPS]; uniform float lod;
        void main() {
          vec3 d = texelFetch(dirs, ivec2(int(gl_FragCoord.x), 0), 0).xyz;
          vec3 t = normalize(cross(abs(d.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0), d));
          vec3 b = cross(d, t);
          vec3 sum = vec3(0.0);
          for (int i = 0; i < TAPS; i++) sum += textureLod(env, taps[i].x * t + taps[i].y * b + taps[i].z * d, lod).rgb;
          gl_FragColor = vec4(sum / float(TAPS), 1.0);
        }`,
    }));
    const scene = new THREE.Scene();
    scene.add(mesh);
    const pixels = new Float32Array(4 * n);
    return {
      lod,
      /** RGB samples (3 per direction) of the render target in `dirs` (3 per direction). */
      read(dirs, samples) {
        for (let j = 0; j < n; j++) dirData.set([dirs[3 * j], dirs[3 * j + 1], dirs[3 * j + 2], 0], 4 * j);
        dirTex.needsUpdate = true;
        renderer.setRenderTarget(target);
        renderer.render(scene, quadCamera);
        renderer.readRenderTargetPixels(target, 0, 0, n, 1, pixels);
        renderer.setRenderTarget(null);
        for (let j = 0; j < n; j++) samples.set(pixels.subarray(4 * j, 4 * j + 3), 3 * j);
        return samples;
      },
      dispose() {
        dirTex.dispose();
        target.dispose();
        mesh.geometry.dispose();
        mesh.material.dispose();
      },
    };
  }
  const sh = new THREE.SphericalHarmonics3();
  const shError = (p) => {
    sh.fromArray(p.threeJsSh("y-up"));
    return errorOf((nn) => sh.getIrradianceAt(vec.set(...nn), col).toArray()).rms;
  };

  // Probe: N point samples in three.js world directions (y-up: the export is "y-up").
  for (const n of [64, 256]) {
    const probe = await Probe.create({ n, seed: 3 });
    const g = gatherer(n, 0);
    const dirs = probe.directions();
    const samples = new Float32Array(3 * n);
    const times = [];
    for (let r = 0; r < REPEATS + 2; r++) {
      gl.finish();
      const t0 = performance.now();
      probe.update(g.read(dirs, samples));
      sh.fromArray(probe.threeJsSh("y-up"));
      const t1 = performance.now();
      if (r >= 2) times.push(t1 - t0);
    }
    const err = errorOf((nn) => Array.from(probe.irradiance(nn).value));
    results.methods.push({ method: `package-probe-${n}-point`, samples: n, ...err, shRms: shError(probe), ms: median(times) });
    probe.dispose();
    g.dispose();
  }

  // TemporalProbe with the Gaussian footprint: every update samples a freshly rotated set and
  // its sentinels; the error after the first update and after POOLED updates of the static room.
  const POOLED = 8;
  for (const n of [64, 256]) {
    const probe = await TemporalProbe.create({ n, seed: 3, footprint: "gaussian" });
    const g = gatherer(n, probe.sharpness);
    const samples = new Float32Array(3 * probe.sampleCount);
    const sentinels = new Float32Array(3 * probe.sentinelCount);
    const both = new Float32Array(3 * n);
    const times = [];
    let first = null;
    for (let r = 0; r < Math.max(POOLED, REPEATS + 2); r++) {
      gl.finish();
      const t0 = performance.now();
      const dirs = new Float32Array(3 * n);
      dirs.set(probe.directions());
      dirs.set(probe.sentinels(), 3 * probe.sampleCount);
      g.read(dirs, both);
      samples.set(both.subarray(0, 3 * probe.sampleCount));
      sentinels.set(both.subarray(3 * probe.sampleCount));
      probe.pool(samples, sentinels);
      sh.fromArray(probe.threeJsSh("y-up"));
      const t1 = performance.now();
      times.push(t1 - t0);
      if (r === 0) first = { ...errorOf((nn) => Array.from(probe.irradiance(nn).value)), shRms: shError(probe) };
      if (r === POOLED - 1) {
        const err = errorOf((nn) => Array.from(probe.irradiance(nn).value));
        results.methods.push({ method: `package-temporal-${n}-gaussian-1`, samples: n, ...first, ms: median(times.slice(2)) });
        results.methods.push({ method: `package-temporal-${n}-gaussian-${POOLED}`, samples: n, ...err, shRms: shError(probe), ms: NaN, pooled: POOLED });
      }
    }
    const last = results.methods[results.methods.length - 1];
    last.ms = median(times.slice(2));
    results.methods[results.methods.length - 2].ms = last.ms;
    results.methods[results.methods.length - 2].lod = g.lod;
    probe.dispose();
    g.dispose();
  }
  // three.js's LightProbeGridWebGL at the same point: it renders its own cubes (cubemapSize
  // as ours) and projects them on the GPU into a 3D texture, so its SH are read through
  // rendering: a white MeshLambertMaterial sphere at the probe lit by the grid alone,
  // E = π·pixel at each pixel's world normal (a second pass writes it), against the
  // brute-force irradiance at those normals, with LightProbeGenerator's and the footprint
  // TemporalProbe's (N = 64, first update) irradiance on the same normals.
  {
    // 3 × 3 × 3 probes 0.02 apart about the point (the room is 6 wide): the shader samples the
    // grid half a cell off the surface, so a single probe cannot be read alone and its close
    // neighbours blend in. Timed: the centre probe alone (start 13).
    const grid = new LightProbeGridWebGL(0.06, 0.06, 0.06, 3, 3, 3);
    grid.position.copy(PROBE_AT);
    grid.updateBoundingBox();
    const bakeOptions = { cubemapSize: CW, near: 0.05, far: 100 };
    grid.bake(renderer, scene, bakeOptions);
    const gridTimes = [];
    for (let r = 0; r < REPEATS + 2; r++) {
      gl.finish();
      const t0 = performance.now();
      grid.bake(renderer, scene, { ...bakeOptions, start: 13, count: 1 });
      gl.finish();
      const t1 = performance.now();
      if (r >= 2) gridTimes.push(t1 - t0);
    }
    const evalScene = new THREE.Scene();
    evalScene.add(grid);
    const ball = new THREE.Mesh(new THREE.SphereGeometry(0.015, 128, 64), new THREE.MeshLambertMaterial({ color: new THREE.Color(1, 1, 1) }));
    ball.position.copy(PROBE_AT);
    evalScene.add(ball);
    const GS = 96;
    const cam = new THREE.OrthographicCamera(-0.016, 0.016, 0.016, -0.016, 0.1, 10);
    const eye = new THREE.Vector3(-0.4, 0.5, 0.77).normalize();
    cam.position.copy(PROBE_AT).addScaledVector(eye, 3);
    cam.lookAt(PROBE_AT);
    const rt = new THREE.WebGLRenderTarget(GS, GS, { type: THREE.FloatType });
    const readRt = () => {
      const px = new Float32Array(GS * GS * 4);
      renderer.readRenderTargetPixels(rt, 0, 0, GS, GS, px);
      return px;
    };
    renderer.setClearColor(0x000000, 0);
    renderer.setRenderTarget(rt);
    renderer.clear();
    renderer.render(evalScene, cam);
    const shaded = readRt();
    ball.material = new THREE.ShaderMaterial({
      vertexShader: `varying vec3 vN;
        void main() { vN = normalize(mat3(modelMatrix) * normal); gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
      fragmentShader: "varying vec3 vN; void main() { gl_FragColor = vec4(normalize(vN), 1.0); }",
    });
    renderer.clear();
    renderer.render(evalScene, cam);
    const nrm = readRt();
    renderer.setRenderTarget(null);
    const at = [], gridE = [];
    for (let p = 0; p < GS * GS; p += 7) {
      if (nrm[4 * p + 3] < 0.5) continue;
      const m = [nrm[4 * p], nrm[4 * p + 1], nrm[4 * p + 2]];
      const len = Math.hypot(...m);
      if (!(len > 0)) continue;
      const u = m.map((x) => x / len);
      if (u[0] * eye.x + u[1] * eye.y + u[2] * eye.z <= 0.2) continue;
      at.push(u);
      gridE.push([0, 1, 2].map((c) => Math.PI * shaded[4 * p + c]));
    }
    const ref = brute(at);
    const errAt = (irr) => {
      let num = 0, den = 0;
      at.forEach((n, k) => {
        const e = irr(n, k);
        for (let c = 0; c < 3; c++) { num += (e[c] - ref[k][c]) ** 2; den += ref[k][c] ** 2; }
      });
      return Math.sqrt(num / den);
    };
    const tp = await TemporalProbe.create({ n: 64, seed: 3, footprint: "gaussian" });
    const tgg = gatherer(64, tp.sharpness);
    const both = new Float32Array(3 * 64), dd = new Float32Array(3 * 64);
    dd.set(tp.directions());
    dd.set(tp.sentinels(), 3 * tp.sampleCount);
    tgg.read(dd, both);
    tp.pool(both.subarray(0, 3 * tp.sampleCount), both.subarray(3 * tp.sampleCount));
    results.grid = {
      normals: at.length,
      ms: median(gridTimes),
      grid: errAt((n, k) => gridE[k]),
      lpg: errAt((n) => lpg.sh.getIrradianceAt(vec.set(...n), col).toArray()),
      temporal: errAt((n) => Array.from(tp.irradiance(n).value)),
    };
    tp.dispose();
    tgg.dispose();
    rt.dispose();
    grid.dispose?.();
  }

  // A moving light: the panel slides along the ceiling, FRAMES frames, the cube re-rendered
  // every frame. Per frame: LightProbeGenerator on that frame's target, and one pool of a
  // TemporalProbe (N = 64, Gaussian footprint) carried across the frames, at the default
  // hazard 1/64 and at 1/4; each against that frame's brute-force reference.
  const FRAMES = Number(params.get("frames") ?? 12);
  const panel = scene.userData.panel;
  const HAZARDS = [1 / 64, 1 / 4];
  const moving = { frames: FRAMES, lpg: [], temporal: HAZARDS.map((hazard) => ({ hazard, errors: [], changes: {} })) };
  const tprobes = await Promise.all(HAZARDS.map((hazard) => TemporalProbe.create({ n: 64, seed: 5, footprint: "gaussian", hazard })));
  const tg = gatherer(64, tprobes[0].sharpness);
  const tboth = new Float32Array(3 * 64);
  for (let f = 0; f < FRAMES; f++) {
    panel.position.x = -2 + (3.5 * f) / (FRAMES - 1);
    cubeCamera.update(renderer, scene);
    reference = brute();
    const probeSh = await LightProbeGenerator.fromCubeRenderTarget(renderer, cubeTarget);
    moving.lpg.push(errorOf((nn) => probeSh.sh.getIrradianceAt(vec.set(...nn), col).toArray()).rms);
    tprobes.forEach((tprobe, i) => {
      const dirs = new Float32Array(3 * 64);
      dirs.set(tprobe.directions());
      dirs.set(tprobe.sentinels(), 3 * tprobe.sampleCount);
      tg.read(dirs, tboth);
      const change = tprobe.pool(tboth.subarray(0, 3 * tprobe.sampleCount), tboth.subarray(3 * tprobe.sampleCount));
      const m = moving.temporal[i];
      m.changes[change] = (m.changes[change] ?? 0) + 1;
      m.errors.push(errorOf((nn) => Array.from(tprobe.irradiance(nn).value)).rms);
    });
  }
  for (const t of tprobes) t.dispose();
  tg.dispose();
  results.moving = moving;

  cubeTarget.dispose();
  const base = results.methods[0];
  for (const m of results.methods) {
    m.errorRatio = m.rms / base.rms;
    m.timeRatio = m.ms / base.ms;
    rows.push(`threejs,${m.method},irradiance-rel-rms,${m.rms.toPrecision(4)}`);
    rows.push(`threejs,${m.method},irradiance-rel-max,${m.max.toPrecision(4)}`);
    if (m.shRms !== undefined) rows.push(`threejs,${m.method},sh-export-irradiance-rel-rms,${m.shRms.toPrecision(4)}`);
    rows.push(`threejs,${m.method},ms-per-update,${m.ms.toPrecision(4)}`);
  }
  const gr = results.grid;
  rows.push(`threejs,light-probe-grid-webgl,hemisphere-irradiance-rel-rms,${gr.grid.toPrecision(4)}`);
  rows.push(`threejs,light-probe-generator,hemisphere-irradiance-rel-rms,${gr.lpg.toPrecision(4)}`);
  rows.push(`threejs,package-temporal-64-gaussian-1,hemisphere-irradiance-rel-rms,${gr.temporal.toPrecision(4)}`);
  rows.push(`threejs,light-probe-grid-webgl,ms-per-bake,${gr.ms.toPrecision(4)}`);
  const mean = (xs) => xs.reduce((a, b) => a + b, 0) / xs.length;
  for (const [name, xs] of [["light-probe-generator", moving.lpg],
    ...moving.temporal.map((t) => [`package-temporal-64-gaussian-hazard-${Math.round(1 / t.hazard)}`, t.errors])]) {
    rows.push(`threejs,moving-${name},irradiance-rel-rms-mean,${mean(xs).toPrecision(4)}`);
    rows.push(`threejs,moving-${name},irradiance-rel-rms-max,${Math.max(...xs).toPrecision(4)}`);
  }
  results.rows = rows;
  return results;
}

try {
  const conv = await conventions();
  const dyn = params.get("dynamic") === "0" ? null : await dynamic();
  const rows = [
    `threejs,conventions,max-rel-pixel-error,${conv.maxRel.toPrecision(4)}`,
    `threejs,conventions,mean-rel-pixel-error,${conv.meanRel.toPrecision(4)}`,
    `threejs,conventions-unrotated,max-rel-pixel-error,${conv.unrotatedMaxRel.toPrecision(4)}`,
    ...(dyn?.rows ?? []),
  ];
  out.textContent = JSON.stringify({ info, conventions: conv, dynamic: dyn, rows }, null, 1);
  out.dataset.ok = conv.ok ? "1" : "0";
} catch (e) {
  out.textContent = JSON.stringify({ info, error: `${e}\n${e?.stack ?? ""}` });
  out.dataset.ok = "0";
}
out.dataset.done = "1";
