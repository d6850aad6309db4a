"""Renders an exported Blender module's material on a swatch with Cycles (Blender as the `bpy`
module from PyPI, on the CPU) and writes the mean linear RGB of each view.

    python cycles_swatch.py MODULE.py CONFIGS.json OUT.json [--samples N] [--png DIR]
    python cycles_swatch.py --selftest [--png DIR]

Run it with the python that has bpy (the repository's .venv: `cargo xtask test` puts it first on
PATH). MODULE.py is what `clothbake export --blender` writes: `build_material(name="clothbake")`
builds the material (its images made in memory, read through the UV map "UVMap", its tangent
from a Tangent node on that UV map) and returns it. It is loaded once, into an empty scene.

CONFIGS.json and OUT.json are those of tests/renderers/three_swatch.mjs, and so are the
conventions, in Blender's terms:
* Frame: the swatch is a mesh of one quad, the unit square [0,1]^2 of the XY plane at z = 0,
  normal +Z, UV map "UVMap" = (x, y) (Blender's v points up the image, so an image lies upright
  on the plane, as in the glTF harness); a Tangent node on "UVMap" gives +X.
* Light: one Sun lamp of strength 1 (irradiance 1 W/m^2 on a surface facing it), angle 0 (a
  parallel light), white, shining along -`light` (`light`, toward the lamp, is normalised
  here). The world is black (Background strength 0); nothing else is in the scene.
* Camera: orthographic, looking from `view` = (sin t cos p, sin t sin p, cos t), its image's
  vertical axis along the horizontal direction of `view` (p a multiple of 90, t < 80): width W
  pixels, height round(W cos t), sensor fit horizontal with ortho_scale 0.5, so that the image
  covers exactly the square [0.25, 0.75]^2 of the plane. When W cos t is not whole, the pixel
  aspect (otherwise 1) makes up the difference, so the coverage stays exact.
* Rendering: Cycles on the CPU, `samples` per pixel (default 16; no adaptive sampling, no
  denoising, fixed seed), a box pixel filter one pixel wide (each pixel the exact mean over
  its own area, so the image's mean is the mean over the square; the default 1.5-pixel
  Blackman-Harris would reach outside the square at the image's border), default light paths;
  view transform Standard, look None, exposure 0, gamma 1 (none of which touches the 32-bit
  OpenEXR the image is saved as, scene-linear, and read back with bpy).

OUT.json: {"renderer": "Blender 5.0.1 Cycles", "results": [{"rgb": [r, g, b], "pixels": n,
"quadrants": [[r, g, b] x 4]}, ...]}: rgb is the mean over the image, the swatch's exitant
radiance for unit irradiance, i.e. the mean over the square of f_r(light, view)
cos(theta_light); quadrants as three_swatch.mjs says. --png DIR writes 8-bit sRGB previews of
pi * rgb as DIR/view<k>.png. Failures exit 1 with one line on stderr.

Noise: with a parallel light (a delta light, sampled exactly), Cycles evaluates every closure
of the material toward the lamp at each sample, and the continuation ray only finds the black
world, so a uniform material renders without noise at any sample count; the only noise is the
pixel footprint's sampling of the textures (see --selftest, which measures it).

--selftest checks the conventions on materials it builds itself (see `selftest`).
"""

import contextlib
import importlib.util
import json
import math
import os
import sys
import tempfile
import time

import bpy
import numpy as np
from mathutils import Matrix, Vector


def fail(msg):
    print(f"cycles_swatch: {str(msg).splitlines()[0] if str(msg) else msg}", file=sys.stderr)
    sys.exit(1)


def load_module(path):
    spec = importlib.util.spec_from_file_location("clothbake_material", path)
    if spec is None:
        fail(f"{path} is not a Python module")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@contextlib.contextmanager
def quiet():
    """Blender's own progress lines (file loading, "Fra:1 ...", "Saved: ...") off stdout."""
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(null)
        os.close(saved)


def empty_scene():
    """A factory-empty file: no objects, no materials, no images."""
    with quiet():
        bpy.ops.wm.read_factory_settings(use_empty=True)


def swatch_scene(material, samples, seed=1):
    """The scene of the module documentation around `material`: (scene, sun, camera)."""
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = samples
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.seed = seed
    cy.use_animated_seed = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.use_persistent_data = True
    world = bpy.data.worlds.new("black")  # Blender 5 gives it nodes (use_nodes is deprecated)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world

    mesh = bpy.data.meshes.new("swatch")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop in mesh.loops:
        co = mesh.vertices[loop.vertex_index].co
        uv.data[loop.index].uv = (co.x, co.y)
    mesh.materials.append(material)
    mesh.update()
    obj = bpy.data.objects.new("swatch", mesh)
    scene.collection.objects.link(obj)

    sun_data = bpy.data.lights.new("sun", "SUN")
    sun_data.energy = 1.0
    sun_data.angle = 0.0
    sun_data.color = (1, 1, 1)
    sun = bpy.data.objects.new("sun", sun_data)
    scene.collection.objects.link(sun)

    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 0.5
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.shift_x = cam_data.shift_y = 0.0
    cam_data.clip_start = 0.01
    cam_data.clip_end = 10.0
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene, sun, cam


def view_dir(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return Vector((math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)))


def frame(scene, sun, cam, c, width):
    """Points the camera and the sun for config `c`; returns (w, h, right, up, view)."""
    t, p = math.radians(c["view_theta_deg"]), math.radians(c["view_phi_deg"])
    exact = width * math.cos(t)
    h = max(1, round(exact))
    scene.render.resolution_x = width
    scene.render.resolution_y = h
    # The vertical extent is ortho_scale * (h aspect_y) / (w aspect_x): 0.5 cos t exactly.
    # Blender's pixel aspects are at least 1.
    scene.render.pixel_aspect_x = max(1.0, h / exact)
    scene.render.pixel_aspect_y = max(1.0, exact / h)
    v = view_dir(c["view_theta_deg"], c["view_phi_deg"])
    up = Vector((math.cos(p), math.sin(p), 0.0))
    y = (up - up.dot(v) * v).normalized()
    x = y.cross(v)
    # The camera looks along its local -Z, with local +Y up the image: columns (x, y, v).
    rot = Matrix((x, y, v)).transposed().to_4x4()
    cam.matrix_world = Matrix.Translation(Vector((0.5, 0.5, 0.0)) + 2.0 * v) @ rot
    # The sun shines along its local -Z: point +Z at the light.
    light = Vector(c["light"])
    if light.length == 0 or light.z <= 0:
        fail(f"light {list(c['light'])} is not above the swatch")
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = light.normalized().to_track_quat("Z", "Y")
    return width, h, x, y, v, math.cos(t)


def render_views(build, job, samples, png_dir=None, seed=1):
    """Renders the material that `build()` makes in an empty file on the swatch, in each
    config of `job`: the OUT.json results."""
    empty_scene()
    material = build()
    if not isinstance(material, bpy.types.Material):
        fail(f"the material builder returned {type(material).__name__}, not a Material")
    scene, sun, cam = swatch_scene(material, samples, seed)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, c in enumerate(job["configs"]):
            w, h, right, up, v, cos_t = frame(scene, sun, cam, c, job["width"])
            path = os.path.join(tmp, f"view{k}.exr")
            scene.render.filepath = path
            with quiet():
                bpy.ops.render.render(write_still=True)
            img = bpy.data.images.load(path)
            if tuple(img.size) != (w, h):
                fail(f"view {k}: the image is {tuple(img.size)}, not {(w, h)}")
            px = np.empty(w * h * img.channels, dtype=np.float32)
            img.pixels.foreach_get(px)
            bpy.data.images.remove(img)
            rgb = px.reshape(h, w, -1)[:, :, :3].astype(np.float64)  # bottom row first
            bad = ~np.isfinite(rgb)
            if bad.any():
                j, i, _ = np.argwhere(bad)[0]
                fail(f"view {k}: pixel ({i}, {j}) is {rgb[j, i]}")
            # Each pixel centre's point on the plane (as three_swatch.mjs computes it).
            sx = ((np.arange(w) + 0.5) / w * 2 - 1) * 0.25
            sy = ((np.arange(h) + 0.5) / h * 2 - 1) * 0.25 * cos_t
            X, Y = np.meshgrid(sx, sy)
            q = [np.array((0.5, 0.5, 0.0)) + X[..., None] * np.array(right)
                 + Y[..., None] * np.array(up)][0]
            q = q - (q[..., 2:3] / v.z) * np.array(v)
            quad = (q[..., 0] > 0.5).astype(int) + 2 * (q[..., 1] > 0.5).astype(int)
            quadrants = [rgb[quad == i].mean(axis=0).tolist() if (quad == i).any() else [0, 0, 0]
                         for i in range(4)]
            results.append({"rgb": rgb.reshape(-1, 3).mean(axis=0).tolist(), "pixels": w * h,
                             "quadrants": quadrants})
            if png_dir:
                write_png(os.path.join(png_dir, f"view{k}.png"), rgb[::-1])
    return results


def write_png(path, rgb):
    """An 8-bit sRGB preview of pi * rgb (rows top first)."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    x = np.clip(rgb * math.pi, 0, 1)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    h, w, _ = x.shape
    img = bpy.data.images.new("preview", w, h)
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :3] = x[::-1]  # bpy wants the bottom row first
    img.pixels.foreach_set(rgba.ravel())
    img.filepath_raw = path
    img.file_format = "PNG"
    img.colorspace_settings.name = "Non-Color"
    img.save()
    bpy.data.images.remove(img)


def check_job(job, where):
    if not isinstance(job.get("width"), int) or job["width"] < 1 or not isinstance(
            job.get("configs"), list):
        fail(f'{where}: needs {{"width": W, "configs": [...]}}')
    for c in job["configs"]:
        ok = (isinstance(c.get("light"), list) and len(c["light"]) == 3 and c["light"][2] > 0
              and 0 <= c.get("view_theta_deg", -1) < 80 and c.get("view_phi_deg", 1) % 90 == 0)
        if not ok:
            fail(f"{where}: a config needs light [x, y, z] above the swatch, view_theta_deg in "
                 f"[0, 80) and view_phi_deg a multiple of 90: {c}")


def renderer_name():
    return f"Blender {bpy.app.version_string} Cycles"


# ---- Self-test ----

def principled(name, **inputs):
    """A material of one Principled BSDF with `inputs` (socket name -> value); returns
    (material, node tree, the BSDF node)."""
    m = bpy.data.materials.new(name)  # with a Principled BSDF (Blender 5 always uses nodes)
    nt = m.node_tree
    p = nt.nodes["Principled BSDF"]
    for k, val in inputs.items():
        p.inputs[k].default_value = val
    return m, nt, p


def texture(nt, p, socket, px, closest=False, scale=1.0):
    """Connects an in-memory float image of `px` ([row from the bottom, column, RGBA],
    linear) to `p`'s input `socket`, read through "UVMap" scaled by `scale`."""
    h, w, _ = px.shape
    img = bpy.data.images.new(f"tex{len(bpy.data.images)}", w, h, float_buffer=True)
    # The colour space is set before the pixels: changing it afterwards reloads a generated
    # image, which then renders black.
    img.colorspace_settings.name = "Non-Color"
    img.pixels.foreach_set(px.astype(np.float32).ravel())
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Closest" if closest else "Linear"
    tex.extension = "EXTEND" if closest else "REPEAT"
    uvn = nt.nodes.new("ShaderNodeUVMap")
    uvn.uv_map = "UVMap"
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (scale, scale, 1)
    nt.links.new(uvn.outputs["UV"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], p.inputs[socket])


def uv_tangent(nt, p):
    """The Principled BSDF's tangent from a Tangent node on "UVMap" (dP/du = +X here)."""
    tan = nt.nodes.new("ShaderNodeTangent")
    tan.direction_type = "UV_MAP"
    tan.uv_map = "UVMap"
    nt.links.new(tan.outputs["Tangent"], p.inputs["Tangent"])


def ggx_aniso(l, v, ax, ay):
    """Cycles' GGX reflection toward a white conductor (F = 1), without its multiple-
    scattering energy factor (which depends on the view and roughness only): D G2 / (4 cos_l
    cos_v) cos_l with the anisotropic GGX D and the height-correlated Smith G2 = 1 / (1 +
    Lambda_l + Lambda_v); alpha_x along the tangent (+X here)."""
    l, v = Vector(l).normalized(), Vector(v).normalized()
    h = (l + v).normalized()
    d = 1 / (math.pi * ax * ay * ((h.x / ax) ** 2 + (h.y / ay) ** 2 + h.z ** 2) ** 2)

    def lam(w):
        return (math.sqrt(1 + ((ax * w.x) ** 2 + (ay * w.y) ** 2) / w.z ** 2) - 1) / 2

    g = 1 / (1 + lam(l) + lam(v))
    return d * g / (4 * v.z)


def selftest(png_dir):
    failures = []

    def check(ok, what):
        print(f"{'ok  ' if ok else 'FAIL'} {what}", flush=True)
        if not ok:
            failures.append(what)

    def rel(a, b):
        return abs(a - b) / max(abs(b), 1e-9)

    def fmt(a):
        return "[" + ", ".join(f"{x:.5f}" for x in a) + "]"

    width = 64
    t41 = math.degrees(math.acos(0.75))
    views = [
        {"light": list(view_dir(0, 0)), "view_theta_deg": 0, "view_phi_deg": 0},
        {"light": list(view_dir(40, 180)), "view_theta_deg": t41, "view_phi_deg": 0},
        {"light": list(view_dir(60, 270)), "view_theta_deg": t41, "view_phi_deg": 90},
        {"light": list(view_dir(30, 45)), "view_theta_deg": 60, "view_phi_deg": 180},
        {"light": list(view_dir(70, 90)), "view_theta_deg": 60, "view_phi_deg": 270},
        # W cos t = 52.43 is not whole: the pixel aspect keeps the coverage exact.
        {"light": list(view_dir(20, 0)), "view_theta_deg": 35, "view_phi_deg": 90},
    ]
    job = {"width": width, "configs": views}
    c = (0.8, 0.5, 0.2)
    t0 = time.time()
    sub = (lambda n: os.path.join(png_dir, n)) if png_dir else (lambda n: None)

    # 1. Lambert: Principled BSDF with Specular IOR Level 0, so that F0 = 0 and eta = 1: Cycles
    # then makes no specular closure at all, and the diffuse closure (Lambert, Diffuse
    # Roughness 0) keeps the whole base colour: rgb = c / pi * cos(theta_light) exactly (a Sun
    # of strength 1 gives irradiance cos(theta_light)).
    def lambert():
        return principled("lambert", **{"Base Color": (*c, 1), "Roughness": 1.0,
                                        "Specular IOR Level": 0.0})[0]

    for k, r in enumerate(render_views(lambert, job, 4, sub("lambert"))):
        want = [x / math.pi * views[k]["light"][2] for x in c]
        e = max(rel(x, w) for x, w in zip(r["rgb"], want))
        check(e < 0.01, f"Lambert view {k}: rgb {fmt(r['rgb'])} = c/pi cos(theta_l) "
                        f"{fmt(want)} within 1% ({100 * e:.3f}%)")

    # 2. The default dielectric (IOR 1.5, Specular IOR Level 0.5: F0 = 0.04) at roughness 1:
    # Cycles layers the multiple-scattering GGX specular (energy-preserving albedo scaling)
    # over the diffuse, whose weight is scaled by 1 - (the specular's directional albedo
    # toward the eye) (closure_layering_weight). Printed, not asserted.
    def dielectric():
        return principled("dielectric", **{"Base Color": (*c, 1), "Roughness": 1.0})[0]

    for k, r in enumerate(render_views(dielectric, job, 4)):
        lam = [x / math.pi * views[k]["light"][2] for x in c]
        print(f"     default dielectric (F0 0.04) view {k}: rgb / Lambert = "
              f"{fmt([x / y for x, y in zip(r['rgb'], lam)])}")

    # 3. A 4x4 texture on the Lambert material (linear, closest texel): a black border, and
    # inside, the quarters of [0.25, 0.75]^2 in red (x < 0.5, y > 0.5: the image's top-left,
    # as in three_swatch.mjs), green (top-right), blue (bottom-left), yellow (bottom-right).
    # Each quadrant of the image must hold its colour / pi cos(theta_light): checks UV (x, y)
    # and the framing (a frame one pixel too wide would bring in the black border).
    inner = {(1, 2): (1, 0, 0), (2, 2): (0, 1, 0), (1, 1): (0, 0, 1), (2, 1): (1, 1, 0)}

    def quadrants():
        m, nt, p = principled("quadrants", **{"Roughness": 1.0, "Specular IOR Level": 0.0})
        px = np.zeros((4, 4, 4))
        px[..., 3] = 1
        for (col, row), rgb in inner.items():
            px[row, col, :3] = rgb
        texture(nt, p, "Base Color", px, closest=True)
        return m

    want_q = [inner[(1, 1)], inner[(2, 1)], inner[(1, 2)], inner[(2, 2)]]
    for k, r in enumerate(render_views(quadrants, job, 4, sub("quadrants"))):
        cl = views[k]["light"][2] / math.pi
        e = max(abs(x - w * cl) / cl for q, wq in zip(r["quadrants"], want_q)
                for x, w in zip(q, wq))
        check(e < 0.01, f"texture view {k}: each quadrant its texel / pi cos(theta_l) "
                        f"(largest error {100 * e:.3f}%)")

    # 4. Anisotropy: a white metal (Metallic 1, F82 tint white: F = 1), Roughness 0.3,
    # Anisotropic 0.8, the tangent from a Tangent node on "UVMap" (+X). Cycles' Principled:
    # alpha_x = r^2 / sqrt(1 - 0.9 a) along the tangent, alpha_y = r^2 sqrt(1 - 0.9 a). The
    # configurations A and B of three_swatch.mjs (the same up to a rotation by 90 degrees about
    # the normal; the half vector tilts toward +X in A, +Y in B): the isotropic control gives
    # A = B, the anisotropic metal is brighter in A, by the ratio of Cycles' GGX.
    pair = {"width": width, "configs": [
        {"light": list(view_dir(30, 180)), "view_theta_deg": 60, "view_phi_deg": 0},
        {"light": list(view_dir(30, 270)), "view_theta_deg": 60, "view_phi_deg": 90},
    ]}

    def metal(aniso):
        def build():
            m, nt, p = principled("metal", **{"Base Color": (1, 1, 1, 1), "Metallic": 1.0,
                                              "Roughness": 0.3, "Anisotropic": aniso})
            uv_tangent(nt, p)
            return m
        return build

    iA, iB = render_views(metal(0.0), pair, 4)
    aA, aB = render_views(metal(0.8), pair, 4, sub("anisotropic"))
    check(rel(iA["rgb"][0], iB["rgb"][0]) < 0.01,
          f"isotropic metal: A {iA['rgb'][0]:.5f} = B {iB['rgb'][0]:.5f} within 1%")
    a = 0.09
    s = math.sqrt(1 - 0.9 * 0.8)
    want = (ggx_aniso(pair["configs"][0]["light"], view_dir(60, 0), a / s, a * s)
            / ggx_aniso(pair["configs"][1]["light"], view_dir(60, 90), a / s, a * s))
    got = aA["rgb"][0] / aB["rgb"][0]
    check(rel(got, want) < 0.02,
          f"anisotropic metal: A {aA['rgb'][0]:.5f} / B {aB['rgb'][0]:.5f} = {got:.4f}, "
          f"Cycles' GGX says {want:.4f} (tangent +X, rougher along it)")

    # 5. Noise: a material with every lobe the exporter uses (a base colour map of 16x16
    # texels tiled 8 times, bilinear; sheen; an anisotropic dielectric specular), rendered
    # with two seeds at the width the tests use. Printed.
    def busy():
        m, nt, p = principled("busy", **{"Roughness": 0.5, "Anisotropic": 0.5,
                                         "Sheen Weight": 0.5, "Sheen Roughness": 0.4})
        n = 16
        u, v = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
        px = np.stack([0.1 + 0.8 * u, 0.1 + 0.8 * (v > 0.5), 0.5 + 0.4 * np.sin(8 * u),
                       np.ones_like(u)], -1)
        texture(nt, p, "Base Color", px, scale=8.0)
        uv_tangent(nt, p)
        return m

    for spp in (4, 16):
        t1 = time.time()
        r1 = render_views(busy, {"width": 128, "configs": views[:3]}, spp, seed=1)
        r2 = render_views(busy, {"width": 128, "configs": views[:3]}, spp, seed=2)
        d = max(rel(x, y) for a_, b_ in zip(r1, r2) for x, y in zip(a_["rgb"], b_["rgb"]))
        print(f"     noise: textured sheen + anisotropic material, {spp} samples, width 128: "
              f"the means of two seeds differ by at most {100 * d:.4f}% "
              f"({(time.time() - t1) / 2:.2f} s for 3 views)", flush=True)

    print(f"{renderer_name()} self-test: {time.time() - t0:.1f} s")
    if failures:
        fail(f"self-test failed: {failures[0]}")


def main():
    args = sys.argv[1:]
    samples = 16
    png_dir = None
    for flag in ("--samples", "--png"):
        if flag in args:
            i = args.index(flag)
            if i + 1 >= len(args):
                fail(f"{flag} needs a value")
            if flag == "--samples":
                try:
                    samples = int(args[i + 1])
                except ValueError:
                    fail(f"--samples {args[i + 1]}: not a whole number")
                if samples < 1:
                    fail("--samples must be at least 1")
            else:
                png_dir = args[i + 1]
            del args[i:i + 2]
    if args == ["--selftest"]:
        selftest(png_dir)
        return
    if len(args) != 3:
        fail("usage: cycles_swatch.py MODULE.py CONFIGS.json OUT.json [--samples N] "
             "[--png DIR] | --selftest [--png DIR]")
    module_path, config_path, out_path = args
    try:
        with open(config_path) as f:
            job = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{config_path}: {e}")
    check_job(job, config_path)

    def build():
        try:
            return load_module(module_path).build_material("clothbake")
        except SystemExit:
            raise
        except Exception as e:  # the module's own error, in one line
            fail(f"{module_path}: build_material failed: {type(e).__name__}: {e}")

    results = render_views(build, job, samples, png_dir)
    with open(out_path, "w") as f:
        json.dump({"renderer": renderer_name(), "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
