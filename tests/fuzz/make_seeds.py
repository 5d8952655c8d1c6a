#!/usr/bin/env python3
"""Writes the glTF fuzzer's seed corpus (corpus/) and the files its seeds refer to (files/):
small scenes that together reach every part of the importer. Run from anywhere; stdlib only."""
import base64, json, os, struct, zlib

here = os.path.dirname(os.path.abspath(__file__))


def png(w, h, rgba):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    rows = b"".join(b"\0" + bytes(rgba[y * w * 4:(y + 1) * w * 4]) for y in range(h))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


# A quad: positions, normals, uvs, uint16 indices; then a sparse index/value pair.
pos = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]
nrm = [0, 0, 1] * 4
uv = [0, 0, 1, 0, 1, 1, 0, 1]
idx = [0, 1, 2, 0, 2, 3]
BIN = (struct.pack("<12f", *pos) + struct.pack("<12f", *nrm) + struct.pack("<8f", *uv) +
       struct.pack("<6H", *idx) + struct.pack("<H", 2) + struct.pack("<3f", 0.5, 0.5, 0.25))
BIN += b"\0" * (-len(BIN) % 4)
TEX = png(2, 2, [255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255])


def base(buffer_uri):
    views = [(0, 48), (48, 48), (96, 32), (128, 12), (140, 2), (144, 12)]
    b = {"byteLength": len(BIN)}
    if buffer_uri is not None:
        b["uri"] = buffer_uri
    return {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}]}],
        "buffers": [b],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    }


def embedded():
    return base("data:application/octet-stream;base64," + base64.b64encode(BIN).decode())


def glb(doc, extra=b""):
    j = json.dumps(doc, separators=(",", ":")).encode()
    j += b" " * (-len(j) % 4)
    b = BIN + extra
    b += b"\0" * (-len(b) % 4)
    total = 12 + 8 + len(j) + 8 + len(b)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(j), 0x4E4F534A) + j +
            struct.pack("<II", len(b), 0x004E4942) + b)


seeds = {}
seeds["quad.gltf"] = embedded()
d = base(None)
seeds["quad.glb"] = d
d = embedded()
d["materials"] = [
    {"name": "tex", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0},
                                             "baseColorFactor": [0.8, 0.5, 0.2, 1], "metallicFactor": 0.3},
     "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1],
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
                    "KHR_materials_anisotropy": {"anisotropyStrength": 0.5, "anisotropyRotation": 1,
                                                 "anisotropyTexture": {"index": 0}}}}]
d["meshes"][0]["primitives"][0]["material"] = 0
d["textures"] = [{"source": 0, "sampler": 0}]
d["samplers"] = [{"wrapS": 33071, "wrapT": 33648}]
d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(TEX).decode()}]
d["extensionsUsed"] = ["KHR_materials_emissive_strength", "KHR_materials_anisotropy"]
seeds["textured.gltf"] = d
d = base("quad.bin")
d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
d["meshes"][0]["primitives"][0]["material"] = 0
d["textures"] = [{"source": 0}]
d["images"] = [{"uri": "tex.png"}]
seeds["external.gltf"] = d
d = base(None)
d["images"] = [{"bufferView": 6, "mimeType": "image/png"}]
d["bufferViews"].append({"buffer": 0, "byteOffset": len(BIN), "byteLength": len(TEX)})
d["buffers"][0]["byteLength"] = len(BIN) + len(TEX) + (-len(TEX) % 4)
d["textures"] = [{"source": 0}]
d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
d["meshes"][0]["primitives"][0]["material"] = 0
seeds["image-view.glb"] = (d, TEX)
d = embedded()
d["nodes"] = [{"mesh": 0, "children": [1, 2, 3, 4]},
              {"translation": [0, 5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
              {"rotation": [-0.7071, 0, 0, 0.7071], "extensions": {"KHR_lights_punctual": {"light": 1}}},
              {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1],
               "extensions": {"KHR_lights_punctual": {"light": 2}}},
              {"translation": [0, 1, 5], "scale": [2, 2, 2], "camera": 0}]
d["extensionsUsed"] = ["KHR_lights_punctual"]
d["extensions"] = {"KHR_lights_punctual": {"lights": [
    {"type": "point", "intensity": 10, "color": [1, 0.5, 0.25], "range": 4},
    {"type": "spot", "intensity": 20, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
    {"type": "directional", "intensity": 3}]}}
d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}]
seeds["lights-camera.gltf"] = d
d = embedded()
d["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                       "sparse": {"count": 1, "indices": {"bufferView": 4, "componentType": 5123},
                                  "values": {"bufferView": 5}}})
d["meshes"] = [{"primitives": [{"attributes": {"POSITION": 4}, "indices": 3, "mode": 5},
                               {"attributes": {"POSITION": 0}, "mode": 6},
                               {"attributes": {"POSITION": 0}, "mode": 1}]}]
seeds["sparse-modes.gltf"] = d
d = embedded()
d["materials"] = [{"name": "phong", "extras": {"glint": {"model": "phong", "kd": [0.1, 0.2, 0.3], "ks": [0.5] * 3,
                                                         "exponent": 250}}},
                  {"name": "ward", "alphaMode": "BLEND", "normalTexture": {"index": 0},
                   "extras": {"glint": {"model": "ward", "ks": [0.9, 0.8, 0.7], "alpha_x": 0.05, "alpha_y": 0.3,
                                        "rotation": 0.5}}}]
d["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "material": 0},
                               {"attributes": {"POSITION": 0, "TEXCOORD_1": 2}, "indices": 3, "material": 1}]}]
d["nodes"] = [{"children": [1, 2]}, {"mesh": 0, "children": [2]}, {"mesh": 0, "scale": [1, 1, -1]}]
d["textures"] = [{"source": 0}]
d["images"] = [{"uri": "tex.png"}]
d["buffers"][0]["uri"] = "quad.bin"
seeds["papers-materials.gltf"] = d
# Glass: a transmission texture, a volume with absorption, a thin-walled pane (issue 21).
d = embedded()
d["meshes"][0]["primitives"][0]["material"] = 0
d["materials"] = [{"name": "glass", "pbrMetallicRoughness": {"roughnessFactor": 0.2},
                   "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1,
                                                                 "transmissionTexture": {"index": 0}},
                                  "KHR_materials_volume": {"thicknessFactor": 0.5, "attenuationDistance": 0.3,
                                                           "attenuationColor": [0.9, 0.5, 0.1]},
                                  "KHR_materials_ior": {"ior": 1.45}}}]
d["textures"] = [{"source": 0}]
d["images"] = [{"uri": "tex.png"}]
d["buffers"][0]["uri"] = "quad.bin"
d["extensionsUsed"] = ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"]
seeds["glass.gltf"] = d
# Normal maps, texture transforms, alpha, emissive textures and material variants, instanced twice.
tt = {"KHR_texture_transform": {"offset": [0.5, 0.25], "rotation": 0.7, "scale": [2, -1], "texCoord": 1}}
d = embedded()
d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = 2
d["meshes"][0]["primitives"][0]["material"] = 0
d["meshes"][0]["primitives"][0]["extensions"] = {"KHR_materials_variants": {"mappings": [
    {"material": 1, "variants": [0, 2]}, {"material": 2, "variants": [1]}]}}
d["materials"] = [
    {"normalTexture": {"index": 0, "scale": 0.5, "texCoord": 1, "extensions": tt}, "occlusionTexture": {"index": 0},
     "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": tt}}},
    {"alphaMode": "MASK", "alphaCutoff": 0.3,
     "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 1, 1, 0.8]}},
    {"alphaMode": "BLEND", "emissiveTexture": {"index": 0, "extensions": tt}, "emissiveFactor": [1, 1, 1],
     "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}}]
d["nodes"] = [{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [2, 0, 0]}]
d["textures"] = [{"source": 0, "sampler": 0}]
d["samplers"] = [{"wrapS": 33648, "wrapT": 10497}]
d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(TEX).decode()}]
d["extensionsUsed"] = ["KHR_texture_transform", "KHR_materials_variants"]
d["extensions"] = {"KHR_materials_variants": {"variants": [{"name": "masked"}, {"name": "blend"}, {"name": "c"}]}}
seeds["surfaces-variants.gltf"] = d

os.makedirs(os.path.join(here, "corpus"), exist_ok=True)
os.makedirs(os.path.join(here, "files"), exist_ok=True)
for name, doc in seeds.items():
    if name.endswith(".glb"):
        data = glb(*doc) if isinstance(doc, tuple) else glb(doc)
    else:
        data = json.dumps(doc, separators=(",", ":")).encode()
    with open(os.path.join(here, "corpus", name), "wb") as f:
        f.write(data)
with open(os.path.join(here, "files", "quad.bin"), "wb") as f:
    f.write(BIN)
with open(os.path.join(here, "files", "tex.png"), "wb") as f:
    f.write(TEX)
