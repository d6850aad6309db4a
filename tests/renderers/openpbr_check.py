"""Checks an exported OpenPBR material with the reference libraries (PyPI `materialx`, `usd-core`).

    python openpbr_check.py FILE.mtlx FILE.usda EXPECTED.json OUT.json

MaterialX: the document, with the standard libraries imported, validates, and GLSL and OSL
shader generation for its material succeed. USD: the stage opens, the swatch mesh's bound
material is the exported one, its `mtlx:surface` output reaches the `open_pbr_surface` shader
and its `surface` output a UsdPreviewSurface, and every input named in EXPECTED.json
(`{"inputs": {"name": value or [values], ...}, "connected": ["name", ...]}`) reads back with
that value (to 1e-6) or is connected. Writes what it found to OUT.json; exits 1 with one line on
the first failure.
"""

import json
import sys

import MaterialX as mx
from MaterialX import PyMaterialXGenGlsl as mx_glsl
from MaterialX import PyMaterialXGenOsl as mx_osl
from MaterialX import PyMaterialXGenShader as mx_gen
from pxr import Usd, UsdShade


def fail(msg):
    print(f"openpbr_check: {msg}", file=sys.stderr)
    sys.exit(1)


def check_mtlx(path):
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, path)
    lib = mx.createDocument()
    search = mx.getDefaultDataSearchPath()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search, lib)
    doc.importLibrary(lib)
    ok, msg = doc.validate()
    if not ok:
        fail(f"{path} does not validate: {msg}")
    materials = doc.getMaterialNodes()
    if len(materials) != 1:
        fail(f"{path}: expected one material, found {len(materials)}")
    shaders = [n for n in doc.getNodes() if n.getCategory() == "open_pbr_surface"]
    if len(shaders) != 1:
        fail(f"{path}: expected one open_pbr_surface, found {len(shaders)}")
    out = {"valid": True, "material": materials[0].getName()}
    for name, gen in (("glsl", mx_glsl.GlslShaderGenerator.create()),
                      ("osl", mx_osl.OslShaderGenerator.create())):
        ctx = mx_gen.GenContext(gen)
        ctx.registerSourceCodeSearchPath(search)
        shader = gen.generate("clothbake", materials[0], ctx)
        code = shader.getSourceCode(mx_gen.PIXEL_STAGE)
        if not code:
            fail(f"{path}: {name} generation produced no code")
        out[f"{name}_chars"] = len(code)
    inputs = {}
    for i in shaders[0].getInputs():
        inputs[i.getName()] = i.getValueString() if i.getValueString() else "connected"
    out["inputs"] = inputs
    return out


def check_usd(path, expected):
    stage = Usd.Stage.Open(path)
    if stage is None:
        fail(f"{path} does not open")
    mesh = stage.GetPrimAtPath("/Cloth/Swatch")
    if not mesh:
        fail(f"{path}: no /Cloth/Swatch")
    material, _ = UsdShade.MaterialBindingAPI(mesh).ComputeBoundMaterial()
    if not material:
        fail(f"{path}: the swatch has no bound material")
    src = material.ComputeSurfaceSource("mtlx")[0]
    if not src or src.GetIdAttr().Get() != "ND_open_pbr_surface_surfaceshader":
        fail(f"{path}: mtlx:surface does not reach open_pbr_surface")
    preview = material.ComputeSurfaceSource("")[0]
    if not preview or preview.GetIdAttr().Get() != "UsdPreviewSurface":
        fail(f"{path}: surface does not reach a UsdPreviewSurface")
    read = {}
    for name, want in expected.get("inputs", {}).items():
        inp = src.GetInput(name)
        if not inp:
            fail(f"{path}: the shader has no input {name}")
        got = inp.Get()
        got = list(got) if hasattr(got, "__len__") and not isinstance(got, str) else got
        read[name] = got
        w = want if isinstance(want, list) else [want]
        g = got if isinstance(got, list) else [got]
        if len(w) != len(g) or any(abs(float(a) - float(b)) > 1e-6 for a, b in zip(w, g)):
            fail(f"{path}: input {name} reads back {got}, exported {want}")
    for name in expected.get("connected", []):
        inp = src.GetInput(name)
        if not inp or not inp.HasConnectedSource():
            fail(f"{path}: input {name} is not connected")
        read[name] = "connected"
    return {"material": str(material.GetPath()), "inputs": read}


def main():
    if len(sys.argv) != 5:
        fail("usage: openpbr_check.py FILE.mtlx FILE.usda EXPECTED.json OUT.json")
    mtlx_path, usd_path, expected_path, out_path = sys.argv[1:]
    with open(expected_path) as f:
        expected = json.load(f)
    report = {"mtlx": check_mtlx(mtlx_path), "usd": check_usd(usd_path, expected),
              "materialx": mx.getVersionString(), "usd_version": ".".join(map(str, Usd.GetVersion()))}
    with open(out_path, "w") as f:
        json.dump(report, f, indent=1)


if __name__ == "__main__":
    main()
