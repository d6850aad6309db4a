#!/usr/bin/env python3
"""Read a clothbake EXR table with the OpenEXR Python package and print it as JSON.

Usage: python3 tests/python/read_exr.py FILE.exr [--no-values]

Prints one JSON object:
  openexr_version  version of the OpenEXR package, api: "File" (>= 3.3) or "InputFile" (older)
  width, height    image size in pixels (width = n_phi_i * n_phi_o, height = n_theta_i * n_theta_o)
  channels         {"R": "half" | "float" | "uint", ...}
  attributes       every clothbake.* header attribute, as text
  metadata         the clothbake.metadata attribute, parsed as JSON
  values           {"R": [...], "G": [...], "B": [...]}: samples in row-major order (pixel (x, y)
                   at index y * width + x), as exact decimal floats; left out with --no-values
  crc32            {"stored": clothbake.crc32, "computed": ..., "ok": bool}: CRC-32 of the
                   clothbake.metadata text followed by the samples as float32 little-endian,
                   pixels in row-major order, R, G, B per pixel
  sums             {"R": sum, ...} in float64

Used by the Rust test crates/clothbake-loader/tests/openexr_interop.rs to cross-check the exr
crate's output with the reference OpenEXR library. Needs: pip install OpenEXR numpy
"""

import json
import sys
import zlib

import numpy as np
import OpenEXR


def package_version():
    try:
        from importlib.metadata import version

        return version("OpenEXR")
    except Exception:
        return getattr(OpenEXR, "__version__", "unknown")


def text(value):
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def read_new_api(path):
    """OpenEXR >= 3.3: OpenEXR.File."""
    f = OpenEXR.File(path, separate_channels=True)
    if len(f.parts) != 1:
        raise SystemExit(f"{path}: {len(f.parts)} parts, expected 1")
    header = f.header()
    (x0, y0), (x1, y1) = header["dataWindow"]
    width, height = int(x1 - x0 + 1), int(y1 - y0 + 1)
    types, planes = {}, {}
    for name, channel in f.channels().items():
        types[name] = {"HALF": "half", "FLOAT": "float", "UINT": "uint"}[channel.type().name]
        planes[name] = np.asarray(channel.pixels)
    attributes = {k: text(v) for k, v in header.items() if k.startswith("clothbake.")}
    return width, height, types, planes, attributes


def read_old_api(path):
    """OpenEXR < 3.3: OpenEXR.InputFile and Imath."""
    import Imath

    f = OpenEXR.InputFile(path)
    header = f.header()
    dw = header["dataWindow"]
    width, height = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    names = {Imath.PixelType.HALF: "half", Imath.PixelType.FLOAT: "float", Imath.PixelType.UINT: "uint"}
    dtypes = {"half": np.float16, "float": np.float32, "uint": np.uint32}
    types, planes = {}, {}
    for name, channel in header["channels"].items():
        kind = names[channel.type.v]
        types[name] = kind
        raw = f.channel(name, channel.type)
        planes[name] = np.frombuffer(raw, dtype=dtypes[kind]).reshape(height, width)
    attributes = {k: text(v) for k, v in header.items() if k.startswith("clothbake.")}
    return width, height, types, planes, attributes


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    if len(args) != 1:
        raise SystemExit(__doc__)
    path = args[0]
    if hasattr(OpenEXR, "File"):
        api, (width, height, types, planes, attributes) = "File", read_new_api(path)
    else:
        api, (width, height, types, planes, attributes) = "InputFile", read_old_api(path)

    out = {
        "openexr_version": package_version(),
        "api": api,
        "width": width,
        "height": height,
        "channels": types,
        "attributes": attributes,
        "metadata": json.loads(attributes["clothbake.metadata"]) if "clothbake.metadata" in attributes else None,
    }
    rgb = [planes[c].astype(np.float32) for c in "RGB" if c in planes]
    if len(rgb) == 3:
        interleaved = np.stack(rgb, axis=-1).astype("<f4")
        meta = attributes.get("clothbake.metadata", "").encode("utf-8")
        computed = f"{zlib.crc32(meta + interleaved.tobytes()):08x}"
        stored = attributes.get("clothbake.crc32")
        out["crc32"] = {"stored": stored, "computed": computed, "ok": stored == computed}
    out["sums"] = {c: float(planes[c].astype(np.float64).sum()) for c in "RGB" if c in planes}
    if "--no-values" not in sys.argv:
        # float() of a float16/float32 is exact, and json writes the shortest exact decimal.
        out["values"] = {c: [float(v) for v in planes[c].ravel()] for c in "RGB" if c in planes}
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
