// Renders an exported .glb swatch with three.js (the pinned version in package.json) in
// Debian's headless Chromium (driven by playwright-core; no browser download) and writes the
// mean linear RGB of each view.
//
//   node three_swatch.mjs IN.glb CONFIGS.json OUT.json
//
// CONFIGS.json: {"width": W, "configs": [{"light": [x, y, z], "view_theta_deg": t,
// "view_phi_deg": p}, ...]} with view_phi_deg a multiple of 90.
//
// Conventions (the glTF file's, docs/export.md): the swatch is the unit square of the XY plane,
// normal +Z, u along +X (the weft), v along +Y (the warp). `light` is the unit direction toward
// a DirectionalLight of intensity 1 (irradiance 1 on a surface facing it), white; no other
// light, no environment, black background. The orthographic camera looks from the direction
// (theta, phi) and its image covers exactly the square [0.25, 0.75]^2 of the swatch: W pixels
// across the side perpendicular to the tilt, W cos(theta) along it (so the configs use angles
// whose W cos(theta) is whole). No tone mapping; the scene is rendered into a float render
// target, which three.js leaves linear. OUT.json: {"renderer": "three.js rNNN", "results":
// [{"rgb": [r, g, b], "pixels": n}, ...]}: rgb is the mean over the image, the swatch's
// radiance for unit irradiance, i.e. the mean of f_r cos(theta_light) over the square.
// Failures exit 1 with one line.

import { chromium } from "playwright-core";
import { readFileSync, writeFileSync, existsSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const die = (msg) => {
  console.error(`three_swatch: ${msg}`);
  process.exit(1);
};

const [glbPath, configPath, outPath] = process.argv.slice(2);
if (!outPath) die("usage: node three_swatch.mjs IN.glb CONFIGS.json OUT.json");
const glb = readFileSync(glbPath);
const configs = JSON.parse(readFileSync(configPath, "utf8"));
const chromiumPath = process.env.CHROMIUM || "/usr/bin/chromium";
if (!existsSync(chromiumPath)) die(`no Chromium at ${chromiumPath} (apt-get install chromium)`);
const three = join(here, "node_modules", "three");
const threeVersion = JSON.parse(readFileSync(join(three, "package.json"), "utf8")).version;

const page_html = `<!doctype html><html><head>
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
"three/addons/": "/three/examples/jsm/"}}</script></head><body>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
window.renderSwatch = async (job) => {
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.toneMapping = THREE.NoToneMapping;
  const gl = renderer.getContext();
  if (!(gl instanceof WebGL2RenderingContext)) throw new Error("no WebGL2");
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  const gltf = await new GLTFLoader().loadAsync("/swatch.glb");
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
    const half = 0.25;
    const cam = new THREE.OrthographicCamera(-half, half, half * h / w, -half * h / w, 0.01, 10);
    const v = new THREE.Vector3(Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t));
    cam.position.set(0.5 + 2 * v.x, 0.5 + 2 * v.y, 2 * v.z);
    cam.up.set(Math.cos(p), Math.sin(p), 0);
    cam.lookAt(0.5, 0.5, 0);
    cam.updateMatrixWorld();
    const l = new THREE.Vector3(...c.light).normalize();
    light.position.set(0.5 + l.x, 0.5 + l.y, l.z);
    light.target.position.set(0.5, 0.5, 0);
    light.target.updateMatrixWorld();
    const rt = new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType,
      minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter });
    renderer.setRenderTarget(rt);
    renderer.render(scene, cam);
    const buf = new Float32Array(w * h * 4);
    renderer.readRenderTargetPixels(rt, 0, 0, w, h, buf);
    renderer.setRenderTarget(null);
    rt.dispose();
    const sum = [0, 0, 0];
    for (let i = 0; i < w * h; i++) {
      for (let k = 0; k < 3; k++) {
        const x = buf[4 * i + k];
        if (!Number.isFinite(x)) throw new Error("a pixel is not finite");
        sum[k] += x;
      }
    }
    results.push({ rgb: sum.map((s) => s / (w * h)), pixels: w * h });
  }
  renderer.dispose();
  return results;
};
window.ready = true;
</script></body></html>`;

const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
    "--no-sandbox"],
}).catch((e) => die(`cannot start Chromium: ${e.message.split("\n")[0]}`));
try {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(e.message));
  // Every request is answered from disk: the page, three.js from node_modules, the .glb.
  await page.route("**/*", async (route) => {
    const url = new URL(route.request().url());
    if (url.hostname !== "clothbake.test") return route.abort();
    if (url.pathname === "/") return route.fulfill({ contentType: "text/html", body: page_html });
    if (url.pathname === "/swatch.glb") {
      return route.fulfill({ contentType: "model/gltf-binary", body: glb });
    }
    if (url.pathname.startsWith("/three/")) {
      const file = resolve(three, url.pathname.slice("/three/".length));
      if (!file.startsWith(three) || !existsSync(file)) return route.fulfill({ status: 404 });
      return route.fulfill({ contentType: "text/javascript", body: readFileSync(file) });
    }
    return route.fulfill({ status: 404 });
  });
  await page.goto("http://clothbake.test/");
  await page.waitForFunction(() => window.ready === true, null, { timeout: 60000 })
    .catch(() => die(`the page did not load: ${errors.join("; ")}`));
  const results = await page.evaluate((job) => window.renderSwatch(job), configs)
    .catch((e) => die(`rendering failed: ${e.message.split("\n")[0]}`));
  writeFileSync(outPath, JSON.stringify({ renderer: `three.js r${threeVersion.split(".")[1]}`,
    results }, null, 1));
} finally {
  await browser.close();
}
