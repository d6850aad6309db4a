"""One of the gallery's views in Blender's Cycles (python/gallery/mainstream.py): the draped cloth
with the material the exported Blender module builds, the ball and the floor (Diffuse BSDF), a
Sun lamp and a world of constant colour, rendered on the CPU with no denoising and the Standard
view transform, and written as raw little-endian f32 RGB rows from the top.

    python cycles_scene.py CLOTH.py DRAPE.bin CONFIG.json OUT.f32
"""

import importlib.util
import json
import math
import os
import sys
import tempfile

import bpy
import numpy as np
from mathutils import Vector


def diffuse(name, albedo):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    d = nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*albedo, 1.0)
    m.node_tree.links.new(d.outputs["BSDF"], out.inputs["Surface"])
    return m


def main():
    module_path, mesh_path, cfg_path, out_path = sys.argv[1:5]
    cfg = json.load(open(cfg_path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    spec = importlib.util.spec_from_file_location("clothbake_material", module_path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cloth_mat = mod.build_material("cloth")

    raw = open(mesh_path, "rb").read()
    nl = raw.index(b"\n")
    head = json.loads(raw[:nl])
    nv, nt = head["vertices"], head["triangles"]
    off = nl + 1
    pos = np.frombuffer(raw, "<f4", 3 * nv, off).reshape(-1, 3)
    off += 12 * nv
    uv = np.frombuffer(raw, "<f4", 2 * nv, off).reshape(-1, 2)
    off += 8 * nv
    tri = np.frombuffer(raw, "<u4", 3 * nt, off).reshape(-1, 3)

    scene = bpy.context.scene
    mesh = bpy.data.meshes.new("cloth")
    mesh.from_pydata(pos.tolist(), [], tri.tolist())
    layer = mesh.uv_layers.new(name="UVMap")
    loops = np.empty(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", loops)
    layer.data.foreach_set("uv", uv[loops].ravel())
    mesh.shade_smooth()
    mesh.materials.append(cloth_mat)
    scene.collection.objects.link(bpy.data.objects.new("cloth", mesh))

    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64,
                                         radius=cfg["ball"]["radius"],
                                         location=cfg["ball"]["center"])
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ball.data.materials.append(diffuse("ball", cfg["ball"]["albedo"]))
    bpy.ops.mesh.primitive_plane_add(size=2 * cfg["floor"]["half_side"])
    bpy.context.active_object.data.materials.append(diffuse("floor", cfg["floor"]["albedo"]))

    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = cfg["sun_irradiance"]
    sun.data.angle = 0.0
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = Vector(cfg["sun"]).normalized().to_track_quat("Z", "Y")
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = cfg["sky_radiance"]
    scene.world = world

    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.angle = math.radians(cfg["hfov_deg"])
    cam.data.clip_start = 0.01
    cam.data.clip_end = 1000.0
    cam.location = cfg["origin"]
    d = Vector(cfg["target"]) - Vector(cfg["origin"])
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = d.to_track_quat("-Z", "Y")
    scene.collection.objects.link(cam)
    scene.camera = cam

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = cfg["spp"]
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 5
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.resolution_x, scene.render.resolution_y = cfg["width"], cfg["height"]
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cycles.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path)
        px = np.empty(len(img.pixels), dtype=np.float32)
        img.pixels.foreach_get(px)
    rgb = px.reshape(cfg["height"], cfg["width"], 4)[::-1, :, :3]
    np.ascontiguousarray(rgb, dtype="<f4").tofile(out_path)


if __name__ == "__main__":
    main()
