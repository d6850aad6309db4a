// One of the gallery's views in three.js (python/gallery/mainstream.py): the draped cloth with the
// fitted glTF material of CLOTH.glb, the ball and the floor (Lambertian), a DirectionalLight and
// a constant environment (also the background), rendered by the three.js of
// tests/renderers/node_modules in Debian's headless Chromium into a float target (no tone
// mapping), 3 x 3 supersampled, and written as raw little-endian f32 RGB rows from the top.
//
//   node three_scene.mjs CLOTH.glb DRAPE.bin CONFIG.json OUT.f32

import { readFileSync, writeFileSync, existsSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const renderers = resolve(here, "../../tests/renderers");
const three = resolve(renderers, "node_modules/three");
const { chromium } = createRequire(resolve(renderers, "package.json"))("playwright-core");
const die = (m) => { console.error(`three_scene: ${m}`); process.exit(1); };
const [glbPath, meshPath, cfgPath, outPath] = process.argv.slice(2);
if (!outPath) die("usage: node three_scene.mjs CLOTH.glb DRAPE.bin CONFIG.json OUT.f32");
if (!existsSync(three)) die("tests/renderers/node_modules is missing (npm ci there)");
const files = { "/cloth.glb": readFileSync(glbPath), "/drape.bin": readFileSync(meshPath) };
const cfg = JSON.parse(readFileSync(cfgPath, "utf8"));
const SS = 3;

const html = `<!doctype html><html><head>
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
"three/addons/": "/three/examples/jsm/"}}</script></head><body>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
window.renderScene = async (cfg, ss) => {
  const lin = (c) => new THREE.Color().setRGB(c[0], c[1], c[2], THREE.LinearSRGBColorSpace);
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFSoftShadowMap;
  const gltf = await new GLTFLoader().loadAsync("/cloth.glb");
  let material = null;
  gltf.scene.traverse((o) => { if (o.isMesh) material = o.material; });
  const buf = await (await fetch("/drape.bin")).arrayBuffer();
  const bytes = new Uint8Array(buf);
  const nl = bytes.indexOf(10);
  const head = JSON.parse(new TextDecoder().decode(bytes.slice(0, nl)));
  let off = nl + 1;
  const take = (Type, n) => { const a = new Type(buf.slice(off, off + n * 4)); off += n * 4; return a; };
  const pos = take(Float32Array, 3 * head.vertices);
  const uv = take(Float32Array, 2 * head.vertices);
  const idx = take(Uint32Array, 3 * head.triangles);
  const geo = new THREE.BufferGeometry();
  geo.setAttribute("position", new THREE.BufferAttribute(pos, 3));
  geo.setAttribute("uv", new THREE.BufferAttribute(uv, 2));
  geo.setIndex(new THREE.BufferAttribute(idx, 1));
  geo.computeVertexNormals();
  geo.computeTangents();
  const scene = new THREE.Scene();
  const cloth = new THREE.Mesh(geo, material);
  cloth.castShadow = cloth.receiveShadow = true;
  scene.add(cloth);
  const ball = new THREE.Mesh(new THREE.SphereGeometry(cfg.ball.radius, 128, 64),
    new THREE.MeshLambertMaterial({ color: lin(cfg.ball.albedo) }));
  ball.position.set(...cfg.ball.center);
  ball.rotation.x = Math.PI / 2;
  ball.castShadow = ball.receiveShadow = true;
  scene.add(ball);
  const side = 2 * cfg.floor.half_side;
  const floor = new THREE.Mesh(new THREE.PlaneGeometry(side, side),
    new THREE.MeshLambertMaterial({ color: lin(cfg.floor.albedo) }));
  floor.receiveShadow = true;
  scene.add(floor);
  const sun = new THREE.DirectionalLight(0xffffff, cfg.sun_irradiance);
  sun.position.set(...cfg.sun.map((x) => 10 * x));
  sun.castShadow = true;
  sun.shadow.mapSize.set(4096, 4096);
  Object.assign(sun.shadow.camera, { left: -6, right: 6, top: 6, bottom: -6, near: 0.1, far: 30 });
  sun.shadow.bias = -0.0005;
  sun.target.position.set(0, 0, 0);
  scene.add(sun, sun.target);
  const L = cfg.sky_radiance;
  const env = new THREE.DataTexture(new Float32Array(Array(8 * 4 * 4).fill(0).map((_, i) =>
    i % 4 === 3 ? 1 : L)), 8, 4, THREE.RGBAFormat, THREE.FloatType);
  env.mapping = THREE.EquirectangularReflectionMapping;
  env.colorSpace = THREE.LinearSRGBColorSpace;
  env.needsUpdate = true;
  const pmrem = new THREE.PMREMGenerator(renderer);
  scene.environment = pmrem.fromEquirectangular(env).texture;
  scene.background = new THREE.Color().setRGB(L, L, L, THREE.LinearSRGBColorSpace);
  const w = cfg.width * ss, h = cfg.height * ss;
  const vfov = 2 * Math.atan(Math.tan(cfg.hfov_deg * Math.PI / 360) * h / w) * 180 / Math.PI;
  const cam = new THREE.PerspectiveCamera(vfov, w / h, 0.01, 1000);
  cam.up.set(0, 0, 1);
  cam.position.set(...cfg.origin);
  cam.lookAt(...cfg.target);
  const rt = new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType });
  renderer.setRenderTarget(rt);
  renderer.render(scene, cam);
  const px = new Float32Array(w * h * 4);
  renderer.readRenderTargetPixels(rt, 0, 0, w, h, px);
  // Box-filter ss x ss down, rows from the top (GL rows run from the bottom).
  const out = new Array(cfg.width * cfg.height * 3).fill(0);
  for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
    const o = ((cfg.height - 1 - Math.floor(y / ss)) * cfg.width + Math.floor(x / ss)) * 3;
    for (let k = 0; k < 3; k++) out[o + k] += px[(y * w + x) * 4 + k] / (ss * ss);
  }
  return out;
};
window.ready = true;
</script></body></html>`;

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium", headless: true,
  args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
    "--no-sandbox"],
}).catch((e) => die(`cannot start Chromium: ${e.message.split("\n")[0]}`));
try {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  await page.route("**/*", async (route) => {
    const url = new URL(route.request().url());
    if (url.hostname !== "clothbake.test") return route.abort();
    if (url.pathname === "/") return route.fulfill({ contentType: "text/html", body: html });
    if (files[url.pathname]) return route.fulfill({ body: files[url.pathname] });
    if (url.pathname.startsWith("/three/")) {
      const f = resolve(three, url.pathname.slice("/three/".length));
      if (!f.startsWith(three) || !existsSync(f)) return route.fulfill({ status: 404 });
      return route.fulfill({ contentType: "text/javascript", body: readFileSync(f) });
    }
    return route.fulfill({ status: 404 });
  });
  await page.goto("http://clothbake.test/");
  await page.waitForFunction(() => window.ready === true, null, { timeout: 60000 })
    .catch(() => die(`the page did not load: ${errors.join("; ")}`));
  const rgb = await page.evaluate(([c, s]) => window.renderScene(c, s), [cfg, SS])
    .catch((e) => die(`rendering failed: ${e.message.split("\n")[0]}`));
  writeFileSync(outPath, Buffer.from(new Float32Array(rgb).buffer));
} finally {
  await browser.close();
}
