"""Renders an exported Blender module's material on a swatch with Cycles (Blender as the `bpy`
module, CPU) and writes the mean linear RGB of each view.

    python cycles_swatch.py MODULE.py CONFIGS.json OUT.json [--samples N]

MODULE.py is a module `clothbake export --blender` writes: `build_material(name)` builds the
material (maps made in memory, read from the UV map "UVMap") and returns it. CONFIGS.json and
OUT.json as tests/renderers/three_swatch.mjs documents them: the swatch is the unit square of
the XY plane, normal +Z, UV (x, y) (u along the weft, v along the warp); one Sun lamp of
strength 1 (irradiance 1 W/m^2 on a surface facing it) and angle 0 toward `light`; a black
world; an orthographic camera whose image covers exactly the square [0.25, 0.75]^2 (W pixels
across the side perpendicular to the tilt, W cos(theta) along it); a box pixel filter of one
pixel; the Standard view transform, no look, exposure 0, gamma 1; no denoising. The image is
saved as a 32-bit OpenEXR (scene-linear) and read back. rgb = the mean over the image =
the mean of f_r cos(theta_light) over the square. Failures exit 1 with one line.
"""

import importlib.util
import json
import math
import os
import sys
import tempfile

import bpy
import numpy as np
from mathutils import Matrix, Vector


def fail(msg):
    print(f"cycles_swatch: {msg}", file=sys.stderr)
    sys.exit(1)


def load_module(path):
    spec = importlib.util.spec_from_file_location("clothbake_material", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def scene_for(material, samples):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.cycles.seed = 1
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    mesh = bpy.data.meshes.new("swatch")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop in mesh.loops:
        co = mesh.vertices[loop.vertex_index].co
        uv.data[loop.index].uv = (co.x, co.y)
    mesh.materials.append(material)
    obj = bpy.data.objects.new("swatch", mesh)
    scene.collection.objects.link(obj)

    sun_data = bpy.data.lights.new("sun", "SUN")
    sun_data.energy = 1.0
    sun_data.angle = 0.0
    sun = bpy.data.objects.new("sun", sun_data)
    scene.collection.objects.link(sun)

    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 0.5
    cam_data.sensor_fit = "HORIZONTAL"
    cam_data.clip_start = 0.01
    cam_data.clip_end = 10.0
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene, sun, cam


def frame(scene, sun, cam, c, width):
    t, p = math.radians(c["view_theta_deg"]), math.radians(c["view_phi_deg"])
    h = round(width * math.cos(t))
    scene.render.resolution_x = width
    scene.render.resolution_y = h
    v = Vector((math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)))
    up = Vector((math.cos(p), math.sin(p), 0.0))
    y = (up - up.dot(v) * v).normalized()
    x = y.cross(v)
    cam.matrix_world = Matrix.Translation(Vector((0.5, 0.5, 0.0)) + 2.0 * v) @ Matrix(
        (x, y, v)).transposed().to_4x4()
    # The sun shines along its local -Z: point +Z at the light.
    l = Vector(c["light"]).normalized()
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = l.to_track_quat("Z", "Y")
    return width * h


def main():
    args = sys.argv[1:]
    samples = 16
    if "--samples" in args:
        i = args.index("--samples")
        samples = int(args[i + 1])
        del args[i:i + 2]
    if len(args) != 3:
        fail("usage: cycles_swatch.py MODULE.py CONFIGS.json OUT.json [--samples N]")
    module_path, config_path, out_path = args
    with open(config_path) as f:
        job = json.load(f)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, c in enumerate(job["configs"]):
            # A fresh scene per view: the module builds its material into it.
            bpy.ops.wm.read_factory_settings(use_empty=True)
            material = load_module(module_path).build_material("clothbake")
            scene, sun, cam = scene_for(material, samples)
            n = frame(scene, sun, cam, c, job["width"])
            path = os.path.join(tmp, f"view{k}.exr")
            scene.render.filepath = path
            bpy.ops.render.render(write_still=True)
            img = bpy.data.images.load(path)
            px = np.empty(len(img.pixels), dtype=np.float32)
            img.pixels.foreach_get(px)
            rgba = px.reshape(-1, 4)
            if rgba.shape[0] != n or not np.all(np.isfinite(rgba)):
                fail(f"view {k}: {rgba.shape[0]} pixels (expected {n}) or a pixel not finite")
            results.append({"rgb": [float(x) for x in rgba[:, :3].mean(axis=0)], "pixels": n})
    with open(out_path, "w") as f:
        json.dump({"renderer": f"Blender {bpy.app.version_string} Cycles", "results": results},
                  f, indent=1)


if __name__ == "__main__":
    main()
