#!/usr/bin/env python3
"""Writes default.gltf, glint's built-in scene: a closed room in miniature of the papers' kitchen
and tableau, where glossy and anisotropic metals reflect each other.

Units are metres, +Y up. The buffer is embedded (data: URI) so the scene is one file that the
build compiles into the program. Run it again after editing; the output is deterministic.

    python3 assets/default/make_default_scene.py   # rewrites assets/default/default.gltf
"""
import base64
import json
import math
import os
import struct

# ---- geometry: each mesh is (positions, normals, uvs, indices) ------------------------------


def quad(corner, edge_u, edge_v):
    """A rectangle from corner spanned by edge_u and edge_v; faces along edge_u x edge_v."""
    n = normalize(cross(edge_u, edge_v))
    p = [corner, add(corner, edge_u), add(add(corner, edge_u), edge_v), add(corner, edge_v)]
    return p, [n] * 4, [(0, 0), (1, 0), (1, 1), (0, 1)], [0, 1, 2, 0, 2, 3]


def box(size):
    """An axis-aligned box centred on the origin, outward normals, one UV square per face."""
    hx, hy, hz = (s / 2 for s in size)
    faces = [((hx, 0, 0), (0, 0, -1), (0, 1, 0)), ((-hx, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, hy, 0), (1, 0, 0), (0, 0, -1)), ((0, -hy, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, hz), (1, 0, 0), (0, 1, 0)), ((0, 0, -hz), (-1, 0, 0), (0, 1, 0))]
    mesh = ([], [], [], [])
    for c, u, v in faces:
        # scale the unit tangent directions to the half extents along them
        su = tuple(a * b for a, b in zip(u, (hx, hy, hz)))
        sv = tuple(a * b for a, b in zip(v, (hx, hy, hz)))
        corner = sub(sub(c, su), sv)
        append(mesh, quad(corner, scale(su, 2), scale(sv, 2)))
    return mesh


def sphere(radius, segments=64, rings=32):
    pos, nrm, uv, idx = [], [], [], []
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2 * math.pi * i / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            pos.append(scale(n, radius))
            nrm.append(n)
            uv.append((i / segments, j / rings))
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + segments + 1
            if j > 0:
                idx += [a, b, a + 1]
            if j < rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nrm, uv, idx


def append(mesh, part):
    base = len(mesh[0])
    for k in range(3):
        mesh[k].extend(part[k])
    mesh[3].extend(i + base for i in part[3])


def add(a, b): return tuple(x + y for x, y in zip(a, b))
def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def scale(a, s): return tuple(x * s for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def normalize(a): return scale(a, 1 / math.sqrt(dot(a, a)))


def look_rotation(eye, target):
    """Unit quaternion (x, y, z, w) turning the node's -Z towards target with +Y kept up."""
    f = normalize(sub(target, eye))
    r = normalize(cross(f, (0, 1, 0)))
    u = cross(r, f)
    m = [[r[0], u[0], -f[0]], [r[1], u[1], -f[1]], [r[2], u[2], -f[2]]]  # columns: x, y, z axes
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = math.sqrt(t + 1) * 2
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0] * 4
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return tuple(q)


def yaw(degrees):
    a = math.radians(degrees) / 2
    return (0.0, math.sin(a), 0.0, math.cos(a))


# ---- materials ----------------------------------------------------------------------------


def metal_rough(name, color, metallic=0.0, roughness=1.0, **extra):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0],
                                                 "metallicFactor": metallic, "roughnessFactor": roughness}}
    m.update(extra)
    return m


MATERIALS = [
    metal_rough("white plaster", (0.75, 0.75, 0.72)),
    metal_rough("red plaster", (0.63, 0.07, 0.05)),
    metal_rough("green plaster", (0.10, 0.45, 0.12)),
    # A varnished floor: the papers' glossy Phong lobe over a diffuse base.
    metal_rough("varnished floor", (0.4, 0.3, 0.2),
                extras={"glint": {"model": "phong", "kd": [0.32, 0.22, 0.13], "ks": [0.25, 0.25, 0.25],
                                  "exponent": 120}}),
    {"name": "ceiling light", "emissiveFactor": [1.0, 0.93, 0.82],
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}},
     "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1}},
    metal_rough("chrome", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.15),
    metal_rough("gold", (1.0, 0.78, 0.34), metallic=1.0, roughness=0.22),
    # Brushed aluminium (anisotropic Ward), as on the VSL paper's kitchen appliances.
    metal_rough("brushed aluminium", (0.8, 0.8, 0.82), metallic=1.0, roughness=0.3,
                extras={"glint": {"model": "ward", "kd": [0.02, 0.02, 0.02], "ks": [0.78, 0.78, 0.8],
                                  "alpha_x": 0.05, "alpha_y": 0.3, "rotation": 0.0}}),
    # Brushed steel through the glTF extension: anisotropic GGX along the surface tangent.
    metal_rough("brushed steel", (0.86, 0.87, 0.9), metallic=1.0, roughness=0.35,
                extensions={"KHR_materials_anisotropy": {"anisotropyStrength": 0.85, "anisotropyRotation": 1.5708}}),
    metal_rough("blue lacquer", (0.05, 0.1, 0.3),
                extras={"glint": {"model": "phong", "kd": [0.04, 0.08, 0.3], "ks": [0.5, 0.5, 0.5],
                                  "exponent": 400}}),
    metal_rough("white card", (0.8, 0.8, 0.78)),
    metal_rough("terracotta", (0.6, 0.28, 0.14), roughness=0.8),
]
MAT = {m["name"]: i for i, m in enumerate(MATERIALS)}

# ---- the room: x in [-2, 2], y in [0, 2.6], z in [-1.5, 1.5]; walls face inwards -------------

W, H, D = 2.0, 2.6, 1.5
ROOM = [
    ("floor", "varnished floor", quad((-W, 0, D), (2 * W, 0, 0), (0, 0, -2 * D))),
    ("ceiling", "white plaster", quad((-W, H, -D), (2 * W, 0, 0), (0, 0, 2 * D))),
    ("back wall", "white plaster", quad((-W, 0, -D), (2 * W, 0, 0), (0, H, 0))),
    ("front wall", "white plaster", quad((W, 0, D), (-2 * W, 0, 0), (0, H, 0))),
    ("left wall", "red plaster", quad((-W, 0, D), (0, 0, -2 * D), (0, H, 0))),
    ("right wall", "green plaster", quad((W, 0, -D), (0, 0, 2 * D), (0, H, 0))),
    # The light hangs 1 cm under the ceiling, facing down (single-sided, so it lights the room only).
    ("ceiling light", "ceiling light", quad((-0.5, H - 0.01, -0.3), (1.0, 0, 0), (0, 0, 0.6))),
    # Brushed aluminium panel on the back wall, just off it; stretched highlights of everything.
    ("brushed panel", "brushed aluminium", quad((-1.5, 0.25, -D + 0.01), (2.2, 0, 0), (0, 1.6, 0))),
    # Brushed steel panel high on the right wall, above the lacquer box.
    ("steel panel", "brushed steel", quad((W - 0.01, 0.85, -1.45), (0, 0, 1.2), (0, 1.35, 0))),
]

OBJECTS = [  # name, material, mesh, translation, rotation
    ("chrome sphere", "chrome", sphere(0.4), (-0.75, 0.4, -0.6), None),
    ("gold sphere", "gold", sphere(0.3), (0.45, 0.3, -0.15), None),
    ("lacquer box", "blue lacquer", box((0.5, 0.8, 0.5)), (1.25, 0.4, -0.85), yaw(25)),
    ("card box", "white card", box((0.45, 0.45, 0.45)), (-1.45, 0.225, 0.2), yaw(-20)),
    ("terracotta block", "terracotta", box((0.3, 0.2, 0.5)), (-0.05, 0.1, 0.45), yaw(40)),
]

CAMERA_EYE, CAMERA_TARGET = (0.35, 1.4, 1.45), (-0.1, 0.5, -0.8)
SPOT_POS, SPOT_TARGET = (-1.7, 2.4, 1.2), (0.45, 0.3, -0.15)

# ---- glTF assembly -----------------------------------------------------------------------


def build():
    blob = bytearray()
    views, accessors, meshes, nodes = [], [], [], []

    def add_view(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(views) - 1

    def add_accessor(values, kind):
        if kind == "SCALAR":
            view = add_view(struct.pack("<%dH" % len(values), *values), 34963)
            accessors.append({"bufferView": view, "componentType": 5123, "count": len(values), "type": "SCALAR"})
        else:
            flat = [c for v in values for c in v]
            view = add_view(struct.pack("<%df" % len(flat), *flat), 34962)
            acc = {"bufferView": view, "componentType": 5126, "count": len(values), "type": kind}
            if kind == "VEC3":  # POSITION needs bounds
                acc["min"] = [min(v[k] for v in values) for k in range(3)]
                acc["max"] = [max(v[k] for v in values) for k in range(3)]
            accessors.append(acc)
        return len(accessors) - 1

    def add_mesh(name, material, mesh):
        pos, nrm, uv, idx = mesh
        assert len(pos) < 65536
        prim = {"attributes": {"POSITION": add_accessor(pos, "VEC3"), "NORMAL": add_accessor(nrm, "VEC3"),
                               "TEXCOORD_0": add_accessor(uv, "VEC2")},
                "indices": add_accessor(idx, "SCALAR"), "material": MAT[material]}
        meshes.append({"name": name, "primitives": [prim]})
        return len(meshes) - 1

    for name, material, mesh in ROOM:
        nodes.append({"name": name, "mesh": add_mesh(name, material, mesh)})
    for name, material, mesh, t, r in OBJECTS:
        node = {"name": name, "mesh": add_mesh(name, material, mesh), "translation": list(t)}
        if r:
            node["rotation"] = list(r)
        nodes.append(node)
    nodes.append({"name": "camera", "camera": 0, "translation": list(CAMERA_EYE),
                  "rotation": list(look_rotation(CAMERA_EYE, CAMERA_TARGET))})
    nodes.append({"name": "spot", "extensions": {"KHR_lights_punctual": {"light": 0}},
                  "translation": list(SPOT_POS), "rotation": list(look_rotation(SPOT_POS, SPOT_TARGET))})

    return {
        "asset": {"version": "2.0", "generator": "glint assets/default/make_default_scene.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_anisotropy"],
        "scene": 0,
        "scenes": [{"name": "glint default room", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": MATERIALS,
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 1.1, "aspectRatio": 16 / 9, "znear": 0.01, "zfar": 100}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "spot", "type": "spot", "color": [1.0, 0.95, 0.88], "intensity": 15.0,
             "spot": {"innerConeAngle": 0.22, "outerConeAngle": 0.32}}]}},
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }


def round_floats(x):
    if isinstance(x, float):
        return round(x, 6)
    if isinstance(x, list):
        return [round_floats(v) for v in x]
    if isinstance(x, dict):
        return {k: round_floats(v) for k, v in x.items()}
    return x


if __name__ == "__main__":
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "default.gltf")
    text = json.dumps(round_floats(build()), indent=1) + "\n"
    with open(out + ".tmp", "w") as f:
        f.write(text)
    os.replace(out + ".tmp", out)
    print("wrote %s (%d bytes)" % (out, len(text)))
