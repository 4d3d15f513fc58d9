#!/usr/bin/env python3
"""Wraps an .spz file in a .glb as the Khronos SPZ drafts describe, for the glTF reader's tests and fuzzer seeds.

  python3 make_spz_glb.py SOURCE.spz OUT.glb {spz_2|spz|khr_spz_compression}

spz_2 and spz: the stream in a bufferView named by KHR_gaussian_splatting_compression_spz_2 (or the draft's earlier
name, KHR_gaussian_splatting_compression_spz) inside the primitive's KHR_gaussian_splatting extension, with the
attributes' accessors (no bufferView: they describe what the stream decodes to) as the draft's schema example has
them. khr_spz_compression: the first draft, the extension on the primitive with bufferView, numPoints, shDegree
and fractionalBits, the attributes under their old names. The SPZ bytes are copied unchanged.
"""
import gzip
import json
import struct
import sys


def spz_header(data):
    """(version, count, sh_degree, fractional_bits) of an SPZ file: gzip (versions 2, 3) or plain (4)."""
    if data[:2] == b"\x1f\x8b":
        data = gzip.decompress(data)[:16]
    magic, version, count, sh_degree, fractional_bits = struct.unpack_from("<IIIBB", data)
    if magic != 0x5053474E:
        sys.exit("not an SPZ file")
    return version, count, sh_degree, fractional_bits


def glb(gltf, binary):
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    length = 12 + 8 + len(text) + 8 + len(binary)
    return (struct.pack("<III", 0x46546C67, 2, length) + struct.pack("<II", len(text), 0x4E4F534A) + text +
            struct.pack("<II", len(binary), 0x004E4942) + binary)


def main():
    source, out, form = sys.argv[1:4]
    stream = open(source, "rb").read()
    version, count, sh_degree, fractional_bits = spz_header(stream)
    accessors = []

    def accessor(kind, component_type=5126, normalized=False):
        accessors.append({"componentType": component_type, "count": count, "type": kind})
        if normalized:
            accessors[-1]["normalized"] = True
        return len(accessors) - 1

    view = {"buffer": 0, "byteLength": len(stream)}
    if form == "khr_spz_compression":
        attributes = {"POSITION": accessor("VEC3"), "COLOR_0": accessor("VEC4", 5121, True),
                      "_SCALE": accessor("VEC3"), "_ROTATION": accessor("VEC4")}
        extension = {"bufferView": 0, "numPoints": count, "shDegree": sh_degree, "fractionalBits": fractional_bits,
                     "flagAntialiased": False}
        primitive_extensions = {"KHR_spz_compression": extension}
        used, required = ["KHR_spz_compression"], ["KHR_spz_compression"]
    else:
        name = {"spz_2": "KHR_gaussian_splatting_compression_spz_2",
                "spz": "KHR_gaussian_splatting_compression_spz"}[form]
        attributes = {"POSITION": accessor("VEC3"), "COLOR_0": accessor("VEC4", 5121, True),
                      "KHR_gaussian_splatting:SCALE": accessor("VEC3"),
                      "KHR_gaussian_splatting:ROTATION": accessor("VEC4")}
        for degree in range(1, sh_degree + 1):
            for n in range(2 * degree + 1):
                attributes[f"KHR_gaussian_splatting:SH_DEGREE_{degree}_COEF_{n}"] = accessor("VEC3")
        primitive_extensions = {"KHR_gaussian_splatting": {"extensions": {name: {"bufferView": 0}}}}
        used, required = ["KHR_gaussian_splatting", name], [name]
    gltf = {"asset": {"version": "2.0", "generator": "tilesplat tests/data/gltf_spz/make_spz_glb.py"},
            "extensionsUsed": used, "extensionsRequired": required,
            "buffers": [{"byteLength": len(stream)}], "bufferViews": [view], "accessors": accessors,
            "meshes": [{"primitives": [{"mode": 0, "attributes": attributes, "extensions": primitive_extensions}]}],
            "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
    open(out, "wb").write(glb(gltf, stream))
    print(f"{out}: SPZ version {version}, {count} Gaussians, SH {sh_degree}, {form}")


if __name__ == "__main__":
    main()
