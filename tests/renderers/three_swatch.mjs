// Renders an exported .glb swatch with three.js (the version package-lock.json pins) in Debian's
// headless Chromium (driven by playwright-core; no browser download, no network: every request
// of the page is answered from disk) and writes the mean linear RGB of each view.
//
//   node three_swatch.mjs IN.glb CONFIGS.json OUT.json [--png DIR]
//   node three_swatch.mjs --selftest [--png DIR]
//
// CONFIGS.json: {"width": W, "configs": [{"light": [x, y, z], "view_theta_deg": t,
// "view_phi_deg": p}, ...]}.
//
// Conventions (shared with cycles_swatch.py; the exporter writes the .glb to match):
// * Frame: the swatch is the glb's scene, the unit square [0,1]^2 of the glTF XY plane at z = 0,
//   normal +Z, UV = (x, 1 - y) (glTF's v points down the image, so an image lies upright on the
//   plane: its top row at y = 1), TANGENT (1, 0, 0, 1): the tangent is +X (dP/du), three.js's
//   bitangent cross(N, T) w = +Y.
// * Light: one DirectionalLight, white, intensity 1, shining along -`light` (`light` is the unit
//   vector from the surface toward the light; normalised here). Since r155 three.js lights are
//   physical: a surface facing the light receives irradiance 1. No other light, no environment,
//   black background.
// * Camera: orthographic, looking from `view` = (sin t cos p, sin t sin p, cos t), t =
//   view_theta_deg (< 80), p = view_phi_deg (a multiple of 90). Its image covers exactly the
//   square [0.25, 0.75]^2 of the plane: W pixels across the side perpendicular to the tilt (the
//   image's horizontal axis, along (sin p, -cos p, 0)), round(W cos t) pixels along the tilt
//   (the image's vertical axis, up = the horizontal direction of `view`), the frustum's height
//   exactly 0.5 cos t (so W cos t should be whole for square pixels; it is not required).
// * Rendering: toneMapping = NoToneMapping, into a WebGLRenderTarget of FloatType (three.js
//   writes a render target in its linear working space: no output colour-space conversion),
//   read back with readRenderTargetPixels; no antialiasing, nearest filtering.
//
// OUT.json: {"renderer": "three.js 0.187.0", "results": [{"rgb": [r, g, b], "pixels": n,
// "quadrants": [[r, g, b] x 4]}, ...]} in config order. rgb is the mean over every pixel of the
// image: the swatch's exitant radiance for unit irradiance, i.e. the mean over the square of
// f_r(light, view) cos(theta_light) (in three.js terms, irradiance * BRDF with irradiance =
// dotNL). `quadrants` are the means over the pixels whose centres fall in each quarter of the
// square, in the order (x < 0.5, y < 0.5), (x > 0.5, y < 0.5), (x < 0.5, y > 0.5),
// (x > 0.5, y > 0.5). --png DIR writes each view as an 8-bit sRGB preview DIR/view<k>.png of
// pi * rgb clamped to 1 (a white Lambert surface lit head-on shows white), top row first.
//
// Any failure (no WebGL2 or EXT_color_buffer_float, a .glb that does not load, a pixel that is
// not finite) exits 1 with one line on stderr.
//
// --selftest builds small .glb files itself and checks this harness's conventions (see
// `selftest` at the end): a Lambert material (metallic 0, roughness 1, KHR_materials_specular
// with specularFactor 0, so F0 = F90 = 0) gives c / pi * cos(theta_light) within 1% (measured:
// to the float's precision); a 4x4 texture lands in the quadrants the UV convention says, with
// nothing of its border in the image; an anisotropic metal's off-specular highlight follows the
// tangent +X, by the ratio three.js's own GGX formulas predict. Each of its .glb files passes
// the Khronos validator with no error or warning.

import { chromium } from "playwright-core";
import { readFileSync, writeFileSync, existsSync, mkdirSync } from "node:fs";
import { dirname, join, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { deflateSync } from "node:zlib";
import { createRequire } from "node:module";

const here = dirname(fileURLToPath(import.meta.url));
const die = (msg) => {
  console.error(`three_swatch: ${String(msg).split("\n")[0]}`);
  process.exit(1);
};
const threeDir = join(here, "node_modules", "three");
const chromiumPath = process.env.CHROMIUM || "/usr/bin/chromium";

// The page: three.js from node_modules through an import map, one function that renders a
// .glb in several views. Served from the made-up origin http://clothbake.test, which
// page.route answers; any other request is aborted.
const PAGE = `<!doctype html><html><head>
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
"three/addons/": "/three/examples/jsm/"}}</script></head><body>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
window.renderSwatch = async (url, job, wantPng) => {
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.toneMapping = THREE.NoToneMapping;
  const gl = renderer.getContext();
  if (!(gl instanceof WebGL2RenderingContext)) throw new Error("no WebGL2 context");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  const gltf = await new GLTFLoader().loadAsync(url).catch((e) => {
    throw new Error("the .glb does not load in three.js's GLTFLoader: " + e.message);
  });
  let meshes = 0;
  gltf.scene.traverse((o) => { if (o.isMesh) meshes++; });
  if (meshes !== 1) throw new Error(url + " has " + meshes + " meshes, not one");
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0, 0, 0);
  scene.add(gltf.scene);
  const light = new THREE.DirectionalLight(0xffffff, 1.0);
  scene.add(light);
  scene.add(light.target);
  const results = [];
  for (const c of job.configs) {
    const t = c.view_theta_deg * Math.PI / 180, p = c.view_phi_deg * Math.PI / 180;
    const w = job.width, h = Math.round(job.width * Math.cos(t));
    // Frustum: 0.5 across, 0.5 cos(t) along the tilt: the square [0.25, 0.75]^2 exactly.
    const hw = 0.25, hh = 0.25 * Math.cos(t);
    const cam = new THREE.OrthographicCamera(-hw, hw, hh, -hh, 0.01, 10);
    const v = new THREE.Vector3(Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t));
    const centre = new THREE.Vector3(0.5, 0.5, 0);
    cam.position.copy(centre).addScaledVector(v, 2);
    cam.up.set(Math.cos(p), Math.sin(p), 0);
    cam.lookAt(centre);
    cam.updateMatrixWorld();
    const l = new THREE.Vector3(...c.light).normalize();
    light.position.copy(centre).add(l);
    light.target.position.copy(centre);
    light.updateMatrixWorld();
    light.target.updateMatrixWorld();
    const rt = new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: true });
    renderer.setRenderTarget(rt);
    renderer.render(scene, cam);
    const buf = new Float32Array(w * h * 4);
    renderer.readRenderTargetPixels(rt, 0, 0, w, h, buf);
    renderer.setRenderTarget(null);
    rt.dispose();
    // Each pixel centre's point on the plane: along the camera's right and up axes from the
    // square's centre, then along -view down to z = 0. Rows come bottom row first.
    const right = new THREE.Vector3().setFromMatrixColumn(cam.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(cam.matrixWorld, 1);
    const sum = [0, 0, 0];
    const quad = [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]];
    const count = [0, 0, 0, 0];
    const q = new THREE.Vector3();
    for (let j = 0; j < h; j++) {
      for (let i = 0; i < w; i++) {
        const sx = ((i + 0.5) / w * 2 - 1) * hw, sy = ((j + 0.5) / h * 2 - 1) * hh;
        q.copy(centre).addScaledVector(right, sx).addScaledVector(up, sy);
        q.addScaledVector(v, -q.z / v.z);
        const k = (q.x > 0.5 ? 1 : 0) + (q.y > 0.5 ? 2 : 0);
        count[k]++;
        for (let ch = 0; ch < 3; ch++) {
          const x = buf[4 * (j * w + i) + ch];
          if (!Number.isFinite(x)) throw new Error("pixel (" + i + ", " + j + ") is " + x);
          sum[ch] += x;
          quad[k][ch] += x;
        }
      }
    }
    const r = { rgb: sum.map((s) => s / (w * h)), pixels: w * h,
      quadrants: quad.map((s, k) => s.map((x) => x / Math.max(count[k], 1))) };
    if (wantPng) {
      const enc = (x) => {
        x = Math.min(Math.max(x * Math.PI, 0), 1);
        x = x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055;
        return Math.round(255 * x);
      };
      const rows = [];
      for (let j = h - 1; j >= 0; j--) {
        const row = [];
        for (let i = 0; i < w; i++) for (let ch = 0; ch < 3; ch++) row.push(enc(buf[4 * (j * w + i) + ch]));
        rows.push(row);
      }
      r.png = { w, h, rows };
    }
    results.push(r);
  }
  gltf.scene.traverse((o) => { if (o.isMesh) { o.geometry.dispose(); o.material.dispose(); } });
  renderer.dispose();
  renderer.forceContextLoss();
  return results;
};
window.ready = true;
</script></body></html>`;

// A PNG of 8-bit RGB rows (for the previews and the self-test's texture).
function crc32(bytes) {
  let c = ~0;
  for (const b of bytes) {
    c ^= b;
    for (let k = 0; k < 8; k++) c = (c >>> 1) ^ (0xedb88320 & -(c & 1));
  }
  return ~c >>> 0;
}
function png(w, h, rows) {
  const chunk = (type, data) => {
    const len = Buffer.alloc(4);
    len.writeUInt32BE(data.length);
    const td = Buffer.concat([Buffer.from(type, "ascii"), data]);
    const crc = Buffer.alloc(4);
    crc.writeUInt32BE(crc32(td));
    return Buffer.concat([len, td, crc]);
  };
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(w, 0);
  ihdr.writeUInt32BE(h, 4);
  ihdr.set([8, 2, 0, 0, 0], 8);
  const raw = Buffer.concat(rows.map((r) => Buffer.from([0, ...r])));
  return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk("IHDR", ihdr),
    chunk("IDAT", deflateSync(raw)), chunk("IEND", Buffer.alloc(0))]);
}

// Starts Chromium, opens the page, runs `body(render)` where render(glbBytes, job, pngDir)
// gives the results of one .glb; closes the browser.
async function withRenderer(body) {
  if (!existsSync(chromiumPath)) die(`no Chromium at ${chromiumPath} (apt-get install chromium, or set CHROMIUM)`);
  if (!existsSync(join(threeDir, "package.json"))) die(`no three.js in ${threeDir} (npm ci in tests/renderers)`);
  const browser = await chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
      "--no-sandbox", "--disable-dev-shm-usage"],
  }).catch((e) => die(`cannot start Chromium at ${chromiumPath}: ${e.message}`));
  try {
    const page = await browser.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(e.message));
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
    const glbs = new Map();
    await page.route("**/*", async (route) => {
      const url = new URL(route.request().url());
      if (url.hostname !== "clothbake.test") return route.abort();
      if (url.pathname === "/") return route.fulfill({ contentType: "text/html", body: PAGE });
      if (glbs.has(url.pathname)) {
        return route.fulfill({ contentType: "model/gltf-binary", body: glbs.get(url.pathname) });
      }
      if (url.pathname.startsWith("/three/")) {
        const file = resolve(threeDir, decodeURIComponent(url.pathname.slice("/three/".length)));
        if (!file.startsWith(threeDir + sep) || !existsSync(file)) return route.fulfill({ status: 404 });
        return route.fulfill({ contentType: "text/javascript", body: readFileSync(file) });
      }
      return route.fulfill({ status: 404 });
    });
    await page.goto("http://clothbake.test/");
    await page.waitForFunction(() => window.ready === true, null, { timeout: 60000 })
      .catch(() => die(`the page did not load three.js: ${errors.join("; ") || "timeout"}`));
    let n = 0;
    const render = async (bytes, job, pngDir, name = "the self-test's .glb") => {
      if (selftesting) await mustValidate(bytes);
      const path = `/swatch${n++}.glb`;
      glbs.set(path, bytes);
      const results = await page.evaluate(([u, j, p]) => window.renderSwatch(u, j, p),
        [path, job, Boolean(pngDir)])
        .catch((e) => die(`${name}: ${e.message.replace(/^.*Error: /, "")}` +
          (errors.length ? ` (${errors.join("; ")})` : "")));
      glbs.delete(path);
      results.forEach((r, k) => {
        if (r.png) {
          mkdirSync(pngDir, { recursive: true });
          writeFileSync(join(pngDir, `view${k}.png`), png(r.png.w, r.png.h, r.png.rows));
          delete r.png;
        }
      });
      return results;
    };
    return await body(render);
  } finally {
    await browser.close();
  }
}

const threeVersion = () =>
  JSON.parse(readFileSync(join(threeDir, "package.json"), "utf8")).version;

// ---- The self-test's .glb files ----

// A .glb of the swatch (the conventions above) with `material` (a glTF material object) and,
// optionally, one PNG image used as texture 0 (nearest filtering, clamped).
function swatchGlb(material, image) {
  const f32 = (a) => Buffer.from(new Float32Array(a).buffer);
  const parts = [
    f32([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]), // POSITION
    f32([0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1]), // NORMAL
    f32([1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1]), // TANGENT
    f32([0, 1, 1, 1, 1, 0, 0, 0]), // TEXCOORD_0 = (x, 1 - y)
    Buffer.from(new Uint16Array([0, 1, 2, 0, 2, 3]).buffer), // counter-clockwise seen from +Z
  ];
  if (image) parts.push(image);
  const views = [];
  let offset = 0;
  const chunks = [];
  for (const p of parts) {
    views.push({ buffer: 0, byteOffset: offset, byteLength: p.length });
    const pad = (4 - (p.length % 4)) % 4;
    chunks.push(p, Buffer.alloc(pad));
    offset += p.length + pad;
  }
  const bin = Buffer.concat(chunks);
  const json = {
    asset: { version: "2.0", generator: "clothbake three_swatch.mjs self-test" },
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [{ mesh: 0 }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0, NORMAL: 1, TANGENT: 2, TEXCOORD_0: 3 },
      indices: 4, material: 0 }] }],
    materials: [material],
    buffers: [{ byteLength: bin.length }],
    bufferViews: views.map((v, k) => (k < 4 ? { ...v, target: 34962 } : k === 4 ? { ...v, target: 34963 } : v)),
    accessors: [
      { bufferView: 0, componentType: 5126, count: 4, type: "VEC3", min: [0, 0, 0], max: [1, 1, 0] },
      { bufferView: 1, componentType: 5126, count: 4, type: "VEC3" },
      { bufferView: 2, componentType: 5126, count: 4, type: "VEC4" },
      { bufferView: 3, componentType: 5126, count: 4, type: "VEC2" },
      { bufferView: 4, componentType: 5123, count: 6, type: "SCALAR" },
    ],
  };
  const used = new Set(Object.keys(material.extensions || {}));
  if (used.size) json.extensionsUsed = [...used];
  if (image) {
    json.images = [{ bufferView: 5, mimeType: "image/png" }];
    json.samplers = [{ magFilter: 9728, minFilter: 9728, wrapS: 33071, wrapT: 33071 }];
    json.textures = [{ source: 0, sampler: 0 }];
  }
  let js = Buffer.from(JSON.stringify(json));
  js = Buffer.concat([js, Buffer.alloc((4 - (js.length % 4)) % 4, 0x20)]);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + js.length + 8 + bin.length, 8);
  const ch = (len, type) => {
    const b = Buffer.alloc(8);
    b.writeUInt32LE(len, 0);
    b.writeUInt32LE(type, 4);
    return b;
  };
  return Buffer.concat([header, ch(js.length, 0x4e4f534a), js, ch(bin.length, 0x004e4942), bin]);
}

// three.js's direct specular for a white metal (F = 1) without its multiple-scattering factor,
// which depends on roughness and the view only: V * D of BRDF_GGX with USE_ANISOTROPY
// (lights_physical_pars_fragment: alphaT = mix(roughness^2, 1, anisotropy^2) along T,
// alpha = roughness^2 along B), times cos(theta_light).
function ggxAnisoVD(l, v, roughness, anisotropy) {
  const norm = (a) => { const n = Math.hypot(...a); return a.map((x) => x / n); };
  const [L, V] = [norm(l), norm(v)];
  const H = norm([L[0] + V[0], L[1] + V[1], L[2] + V[2]]);
  const a = roughness * roughness;
  const at = Math.max(a + (1 - a) * anisotropy * anisotropy, a);
  const gv = L[2] * Math.hypot(at * V[0], a * V[1], V[2]);
  const gl = V[2] * Math.hypot(at * L[0], a * L[1], L[2]);
  const Vis = 0.5 / (gv + gl);
  const a2 = at * a;
  const w = [a * H[0], at * H[1], a2 * H[2]];
  const w2 = a2 / (w[0] ** 2 + w[1] ** 2 + w[2] ** 2);
  const D = a2 * w2 * w2 / Math.PI;
  return Vis * D * L[2];
}

const dir = (thetaDeg, phiDeg) => {
  const t = thetaDeg * Math.PI / 180, p = phiDeg * Math.PI / 180;
  return [Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t)];
};

// The self-test's files pass the Khronos validator (as validate_gltf.mjs runs it).
let selftesting = false;
async function mustValidate(bytes) {
  const validator = createRequire(import.meta.url)("gltf-validator");
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    externalResourceFunction: () => Promise.reject(new Error("no external resources")),
  });
  if (report.issues.numErrors > 0 || report.issues.numWarnings > 0) {
    die(`the self-test's .glb does not validate: ${JSON.stringify(report.issues.messages)}`);
  }
}

async function selftest(pngDir) {
  selftesting = true;
  const failures = [];
  const check = (ok, what) => {
    console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
    if (!ok) failures.push(what);
  };
  const rel = (a, b) => Math.abs(a - b) / Math.max(Math.abs(b), 1e-9);
  const width = 64;
  // W cos(theta) whole for W = 64 (cos 0, 0.75 (41.41 deg), 0.5 (60 deg)), but the last.
  const t41 = Math.acos(0.75) * 180 / Math.PI;
  const views = [
    { light: dir(0, 0), view_theta_deg: 0, view_phi_deg: 0 },
    { light: dir(40, 180), view_theta_deg: t41, view_phi_deg: 0 },
    { light: dir(60, 270), view_theta_deg: t41, view_phi_deg: 90 },
    { light: dir(30, 45), view_theta_deg: 60, view_phi_deg: 180 },
    { light: dir(70, 90), view_theta_deg: 60, view_phi_deg: 270 },
    // W cos t = 52.43 is not whole: the frustum keeps the coverage exact (oblong pixels).
    { light: dir(20, 0), view_theta_deg: 35, view_phi_deg: 90 },
  ];
  const job = { width, configs: views };
  const c = [0.8, 0.5, 0.2];
  const t0 = Date.now();
  await withRenderer(async (render) => {
    // 1. Lambert: metallic 0, roughness 1 and KHR_materials_specular's specularFactor 0, so
    // that F0 = F90 = 0: no specular lobe, and the diffuse lobe's (1 - F) factor is 1. Then
    // rgb = c / pi * cos(theta_light) exactly (the DirectionalLight gives irradiance
    // dotNL * intensity, BRDF_Lambert is c / pi).
    const lambert = {
      pbrMetallicRoughness: { baseColorFactor: [...c, 1], metallicFactor: 0, roughnessFactor: 1 },
      extensions: { KHR_materials_specular: { specularFactor: 0 } },
    };
    const r1 = await render(swatchGlb(lambert), job, pngDir && join(pngDir, "lambert"));
    r1.forEach((r, k) => {
      const want = c.map((x) => x / Math.PI * views[k].light[2]);
      const e = Math.max(...r.rgb.map((x, ch) => rel(x, want[ch])));
      check(e < 0.01, `Lambert view ${k}: rgb ${fmt(r.rgb)} = c/pi cos(theta_l) ${fmt(want)} within 1% (${pct(e)})`);
    });
    // 2. The default dielectric (F0 = 0.04, no KHR_materials_specular) at roughness 1: what
    // three.js adds to Lambert. RE_Direct_Physical gives irradiance * (BRDF_GGX *
    // multiScatteringCompensation + c / pi * (1 - F_Schlick(0.04, 1, dot(V, H)))): the diffuse
    // loses F (4% and more at grazing half-angles) and a rough GGX lobe with the Turquin
    // multiple-scattering factor 1 + F0 (1 / E_ss - 1) adds back. Printed, not asserted.
    const plain = {
      pbrMetallicRoughness: { baseColorFactor: [...c, 1], metallicFactor: 0, roughnessFactor: 1 },
    };
    const r2 = await render(swatchGlb(plain), job);
    r2.forEach((r, k) => {
      const lam = c.map((x) => x / Math.PI * views[k].light[2]);
      console.log(`     default dielectric (F0 0.04) view ${k}: rgb / Lambert = ${fmt(r.rgb.map((x, ch) => x / lam[ch]))}`);
    });
    // 3. A 4x4 base colour texture (sRGB 0 or 255, so linear 0 or 1, nearest texel) on the
    // Lambert material: a black border, and inside, the quarters of [0.25, 0.75]^2 in red
    // (the image's top-left: x < 0.5, y > 0.5 on the plane), green (top-right: x > 0.5,
    // y > 0.5), blue (bottom-left: x < 0.5, y < 0.5), yellow (bottom-right: x > 0.5,
    // y < 0.5). Each quadrant of the image must hold its colour / pi cos(theta_light) in
    // every view: checks UV = (x, 1 - y) and the framing (a frame one pixel too wide would
    // bring in the black border).
    const K = [0, 0, 0], R = [255, 0, 0], G = [0, 255, 0], B = [0, 0, 255], Y = [255, 255, 0];
    const tex = png(4, 4, [[K, K, K, K], [K, R, G, K], [K, B, Y, K], [K, K, K, K]].map((r) => r.flat()));
    const textured = {
      pbrMetallicRoughness: { baseColorTexture: { index: 0 }, metallicFactor: 0, roughnessFactor: 1 },
      extensions: { KHR_materials_specular: { specularFactor: 0 } },
    };
    const r3 = await render(swatchGlb(textured, tex), job, pngDir && join(pngDir, "quadrants"));
    const texel = [[0, 0, 1], [1, 1, 0], [1, 0, 0], [0, 1, 0]]; // the quadrant order
    r3.forEach((r, k) => {
      const cl = views[k].light[2] / Math.PI;
      const e = Math.max(...r.quadrants.flatMap((q, i) => q.map((x, ch) => Math.abs(x - texel[i][ch] * cl) / cl)));
      check(e < 0.01, `texture view ${k}: each quadrant its texel / pi cos(theta_l) (largest error ${pct(e)})`);
    });
    // 4. Anisotropy: a white metal (F = 1), roughness 0.3, KHR_materials_anisotropy strength
    // 0.8, rotation 0 (along the tangent, +X). Two configurations that are the same up to a
    // rotation by 90 degrees about the normal: A (light at theta 30 from phi 180, eye at
    // theta 60 from phi 0: the half vector tilts 15 degrees toward +X) and B (the same turned
    // to phi 270 / 90: the half vector tilts toward +Y). The isotropic control gives A = B;
    // the anisotropic material is brighter in A (the highlight stretches along the tangent,
    // alpha_T = mix(0.09, 1, 0.64) = 0.67 > alpha_B = 0.09) by the ratio of three.js's
    // V * D (its multiple-scattering factor is the same in A and B: same view angle and
    // roughness).
    const pair = { width, configs: [
      { light: dir(30, 180), view_theta_deg: 60, view_phi_deg: 0 },
      { light: dir(30, 270), view_theta_deg: 60, view_phi_deg: 90 },
    ] };
    const metal = (ext) => ({
      pbrMetallicRoughness: { baseColorFactor: [1, 1, 1, 1], metallicFactor: 1, roughnessFactor: 0.3 },
      ...(ext ? { extensions: { KHR_materials_anisotropy: { anisotropyStrength: 0.8, anisotropyRotation: 0 } } } : {}),
    });
    const [iA, iB] = await render(swatchGlb(metal(false)), pair);
    check(rel(iA.rgb[0], iB.rgb[0]) < 0.01, `isotropic metal: A ${iA.rgb[0].toFixed(5)} = B ${iB.rgb[0].toFixed(5)} within 1%`);
    const [aA, aB] = await render(swatchGlb(metal(true)), pair, pngDir && join(pngDir, "anisotropic"));
    const want = ggxAnisoVD(pair.configs[0].light, dir(60, 0), 0.3, 0.8) /
      ggxAnisoVD(pair.configs[1].light, dir(60, 90), 0.3, 0.8);
    const got = aA.rgb[0] / aB.rgb[0];
    check(rel(got, want) < 0.02, `anisotropic metal: A ${aA.rgb[0].toFixed(5)} / B ${aB.rgb[0].toFixed(5)} = ${got.toFixed(4)}, three.js's GGX says ${want.toFixed(4)} (tangent +X, rougher along it)`);
  });
  console.log(`three.js ${threeVersion()} self-test: ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  if (failures.length) die(`self-test failed: ${failures[0]}`);
}

const fmt = (a) => `[${a.map((x) => x.toFixed(5)).join(", ")}]`;
const pct = (e) => `${(100 * e).toFixed(3)}%`;

// ---- Command line ----

const args = process.argv.slice(2);
let pngDir = null;
const pi = args.indexOf("--png");
if (pi >= 0) {
  pngDir = args[pi + 1];
  if (!pngDir) die("--png needs a folder");
  args.splice(pi, 2);
}
if (args[0] === "--selftest" && args.length === 1) {
  await selftest(pngDir);
} else {
  if (args.length !== 3) die("usage: node three_swatch.mjs IN.glb CONFIGS.json OUT.json [--png DIR] | --selftest [--png DIR]");
  const [glbPath, configPath, outPath] = args;
  let glb, job;
  try {
    glb = readFileSync(glbPath);
    job = JSON.parse(readFileSync(configPath, "utf8"));
  } catch (e) {
    die(e.message);
  }
  if (!Number.isInteger(job.width) || job.width < 1 || !Array.isArray(job.configs)) {
    die(`${configPath}: needs {"width": W, "configs": [...]}`);
  }
  for (const c of job.configs) {
    if (!(c.view_theta_deg >= 0 && c.view_theta_deg < 80) || c.view_phi_deg % 90 !== 0 ||
        !Array.isArray(c.light) || c.light.length !== 3 || !(c.light[2] > 0)) {
      die(`${configPath}: a config needs light [x, y, z] above the swatch, view_theta_deg in [0, 80) and view_phi_deg a multiple of 90: ${JSON.stringify(c)}`);
    }
  }
  const results = await withRenderer((render) => render(glb, job, pngDir, glbPath));
  writeFileSync(outPath, JSON.stringify({ renderer: `three.js ${threeVersion()}`, results }, null, 1));
}
