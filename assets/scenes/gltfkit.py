"""The helpers glint's scene generators share: meshes, orientations, materials and the glTF
document with its buffer embedded (a data: URI), so each scene is one file that the build
compiles into the program.

Units are metres, +Y up. The output is deterministic: the same script writes the same bytes, so
a reference's scene hash survives regenerating a scene that did not change.
"""
import base64
import json
import math
import os
import struct

# ---- vectors --------------------------------------------------------------------------------


def add(a, b): return tuple(x + y for x, y in zip(a, b))
def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def scale(a, s): return tuple(x * s for x in a)
def dot(a, b): return sum(x * y for x, y in zip(a, b))
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def normalize(a): return scale(a, 1 / math.sqrt(dot(a, a)))


# ---- meshes: each is (positions, normals, uvs, indices) ---------------------------------------


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


def cylinder(r_bottom, r_top, height, segments=32, caps=True):
    """A cylinder or frustum standing on the origin along +Y, outward normals. Without caps it is
    an open tube (a lamp shade); glint shades both sides of a surface."""
    pos, nrm, uv, idx = [], [], [], []
    slope = (r_bottom - r_top) / height  # the side normal leans up when the top is narrower
    for i in range(segments + 1):
        phi = 2 * math.pi * i / segments
        c, s = math.cos(phi), -math.sin(phi)
        n = normalize((c, slope, s))
        pos += [(r_bottom * c, 0.0, r_bottom * s), (r_top * c, height, r_top * s)]
        nrm += [n, n]
        uv += [(i / segments, 0.0), (i / segments, 1.0)]
    for i in range(segments):
        a = 2 * i
        idx += [a, a + 2, a + 3, a, a + 3, a + 1]
    mesh = (pos, nrm, uv, idx)
    if caps:
        for y, r, up in ((0.0, r_bottom, False), (height, r_top, True)):
            append(mesh, disc(r, y, up, segments))
    return mesh


def disc(radius, y, up, segments=32):
    """A disc in the plane at height y facing +Y (up) or -Y."""
    n = (0.0, 1.0 if up else -1.0, 0.0)
    pos, uv = [(0.0, y, 0.0)], [(0.5, 0.5)]
    for i in range(segments + 1):
        phi = 2 * math.pi * i / segments
        pos.append((radius * math.cos(phi), y, -radius * math.sin(phi)))
        uv.append((0.5 + 0.5 * math.cos(phi), 0.5 + 0.5 * math.sin(phi)))
    idx = []
    for i in range(segments):
        idx += [0, i + 1, i + 2] if up else [0, i + 2, i + 1]
    return pos, [n] * len(pos), uv, idx


def append(mesh, part):
    base = len(mesh[0])
    for k in range(3):
        mesh[k].extend(part[k])
    mesh[3].extend(i + base for i in part[3])


def merge(*parts):
    mesh = ([], [], [], [])
    for p in parts:
        append(mesh, p)
    return mesh


def moved(mesh, offset):
    """The mesh translated by offset (to build one mesh from parts)."""
    pos, nrm, uv, idx = mesh
    return [add(p, offset) for p in pos], nrm, uv, idx


# ---- orientations (unit quaternions x, y, z, w) --------------------------------------------


def look_rotation(eye, target):
    """Unit quaternion (x, y, z, w) turning the node's -Z towards target with +Y kept up."""
    f = normalize(sub(target, eye))
    up = (0, 1, 0) if abs(f[1]) < 0.999 else (0, 0, -1)  # straight up or down: any roll will do
    r = normalize(cross(f, up))
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


def rotation_between(a, b):
    """Unit quaternion turning direction a onto direction b (not opposite ones) by the shortest arc."""
    a, b = normalize(a), normalize(b)
    axis = cross(a, b)
    w = 1 + dot(a, b)
    n = math.sqrt(dot(axis, axis) + w * w)
    return tuple(c / n for c in axis) + (w / n,)


def yaw(degrees):
    a = math.radians(degrees) / 2
    return (0.0, math.sin(a), 0.0, math.cos(a))


# ---- materials ------------------------------------------------------------------------------
# color is always the glTF base colour, what other viewers show; glint's own models (extras.glint,
# see the README's "Materials and extras.glint") take kd and ks instead.


def metal_rough(name, color, metallic=0.0, roughness=1.0, **extra):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0],
                                                 "metallicFactor": metallic, "roughnessFactor": roughness}}
    m.update(extra)
    return m


def phong(name, color, kd, ks, exponent):
    """The papers' glossy lobe: modified Phong over a Lambert base."""
    return metal_rough(name, color, extras={"glint": {"model": "phong", "kd": list(kd), "ks": list(ks),
                                                      "exponent": exponent}})


def ward(name, color, kd, ks, alpha_x, alpha_y, rotation=0.0, metallic=1.0, roughness=0.3):
    """Anisotropic Ward; metallic and roughness are only the fallback for other viewers."""
    return metal_rough(name, color, metallic=metallic, roughness=roughness,
                       extras={"glint": {"model": "ward", "kd": list(kd), "ks": list(ks),
                                         "alpha_x": alpha_x, "alpha_y": alpha_y, "rotation": rotation}})


def emissive(name, color, strength):
    """An area light: black and rough, radiance color x strength (W/m^2/sr in glint's units)."""
    return {"name": name, "emissiveFactor": list(color),
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}},
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1}}


def anisotropy(strength, rotation):
    """KHR_materials_anisotropy: brushed GGX along the surface tangent, turned by rotation."""
    return {"KHR_materials_anisotropy": {"anisotropyStrength": strength, "anisotropyRotation": rotation}}


# ---- lights (KHR_lights_punctual; glint takes 1 cd as 1 W/sr) ----------------------------


def spot(name, color, intensity, inner, outer):
    """A spot light; inner and outer are the cone's half angles in radians."""
    return {"name": name, "type": "spot", "color": list(color), "intensity": intensity,
            "spot": {"innerConeAngle": inner, "outerConeAngle": outer}}


def point(name, color, intensity):
    return {"name": name, "type": "point", "color": list(color), "intensity": intensity}


# ---- the document ---------------------------------------------------------------------------


class Scene:
    """Nodes in the order they are added; materials referred to by name."""

    def __init__(self, materials):
        self.materials = materials
        self.mat = {m["name"]: i for i, m in enumerate(materials)}
        self.blob = bytearray()
        self.views, self.accessors, self.meshes, self.nodes = [], [], [], []
        self.cameras, self.lights = [], []

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data), "target": target})
        self.blob.extend(data)
        return len(self.views) - 1

    def _accessor(self, values, kind):
        if kind == "SCALAR":
            view = self._view(struct.pack("<%dH" % len(values), *values), 34963)
            self.accessors.append({"bufferView": view, "componentType": 5123, "count": len(values),
                                   "type": "SCALAR"})
        else:
            flat = [c for v in values for c in v]
            view = self._view(struct.pack("<%df" % len(flat), *flat), 34962)
            acc = {"bufferView": view, "componentType": 5126, "count": len(values), "type": kind}
            if kind == "VEC3":  # POSITION needs bounds
                acc["min"] = [min(v[k] for v in values) for k in range(3)]
                acc["max"] = [max(v[k] for v in values) for k in range(3)]
            self.accessors.append(acc)
        return len(self.accessors) - 1

    def mesh(self, name, material, mesh, translation=None, rotation=None):
        """A node holding one mesh of one material."""
        pos, nrm, uv, idx = mesh
        assert len(pos) < 65536, name  # 16-bit indices
        prim = {"attributes": {"POSITION": self._accessor(pos, "VEC3"), "NORMAL": self._accessor(nrm, "VEC3"),
                               "TEXCOORD_0": self._accessor(uv, "VEC2")},
                "indices": self._accessor(idx, "SCALAR"), "material": self.mat[material]}
        self.meshes.append({"name": name, "primitives": [prim]})
        node = {"name": name, "mesh": len(self.meshes) - 1}
        if translation is not None:
            node["translation"] = list(translation)
        if rotation:
            node["rotation"] = list(rotation)
        self.nodes.append(node)

    def add_meshes(self, entries):
        """One node each: (name, material, mesh[, translation[, rotation]])."""
        for entry in entries:
            self.mesh(*entry)

    def camera(self, eye, target, yfov=1.1, name="camera"):
        """A 16:9 perspective camera at eye looking at target; yfov in radians."""
        self.cameras.append({"type": "perspective",
                             "perspective": {"yfov": yfov, "aspectRatio": 16 / 9, "znear": 0.01, "zfar": 100}})
        self.nodes.append({"name": name, "camera": len(self.cameras) - 1, "translation": list(eye),
                           "rotation": list(look_rotation(eye, target))})

    def light(self, light, position, target=None):
        """A punctual light (spot() or point()) at position; a spot points at target."""
        self.lights.append(light)
        node = {"name": light["name"], "extensions": {"KHR_lights_punctual": {"light": len(self.lights) - 1}},
                "translation": list(position)}
        if target is not None:
            node["rotation"] = list(look_rotation(position, target))
        self.nodes.append(node)

    def document(self, scene_name, generator):
        used = ["KHR_lights_punctual"] if self.lights else []
        for m in self.materials:
            used += [e for e in m.get("extensions", {}) if e not in used]
        doc = {"asset": {"version": "2.0", "generator": generator}}
        if used:
            doc["extensionsUsed"] = used
        doc.update({
            "scene": 0,
            "scenes": [{"name": scene_name, "nodes": list(range(len(self.nodes)))}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "cameras": self.cameras,
        })
        if self.lights:
            doc["extensions"] = {"KHR_lights_punctual": {"lights": self.lights}}
        doc.update({
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": len(self.blob),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode()}],
        })
        return doc


def round_floats(x):
    if isinstance(x, float):
        return round(x, 6)
    if isinstance(x, list):
        return [round_floats(v) for v in x]
    if isinstance(x, dict):
        return {k: round_floats(v) for k, v in x.items()}
    return x


def write(doc, script_file, name):
    """Writes NAME.gltf beside the generator script, atomically."""
    out = os.path.join(os.path.dirname(os.path.abspath(script_file)), name + ".gltf")
    text = json.dumps(round_floats(doc), indent=1) + "\n"
    with open(out + ".tmp", "w") as f:
        f.write(text)
    os.replace(out + ".tmp", out)
    print("wrote %s (%d bytes, %d triangles)" % (out, len(text), triangle_count(doc)))


def triangle_count(doc):
    return sum(doc["accessors"][p["indices"]]["count"] // 3 for m in doc["meshes"] for p in m["primitives"])
