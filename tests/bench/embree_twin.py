#!/usr/bin/env python3
"""The same work for glint and for Embree's own `pathtracer` (embree-tools), for the throughput
comparison in tests/bench/run.sh:

    embree_twin.py scene SCENE.gltf GEOMETRY.obj OUT.gltf
        Writes OUT.gltf: SCENE with every material Lambert of its base colour (glint's Phong with
        ks 0), no emission and one point light above the centre of the bounds of GEOMETRY.obj
        (`glint info SCENE --obj`), bright enough at the scene's scale. Buffers are linked beside
        OUT.gltf. Prints the light's pathtracer arguments: --pointlight X Y Z I I I.
    embree_twin.py camera STATS.json
        Prints the pathtracer arguments of the camera `glint render --stats` rendered from:
        --vp ... --vi ... --vu ... --fov ...

Standard library only.
"""
import json
import math
import os
import sys


def bounds_of_obj(path):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                p = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, p)]
                hi = [max(a, b) for a, b in zip(hi, p)]
    if lo[0] > hi[0]:
        sys.exit(f"embree_twin: error: {path}: no vertices")
    return lo, hi


def link_beside(uri, src_dir, out_dir):
    """Makes the relative file uri of the source scene readable from out_dir."""
    if uri.startswith("data:"):
        return
    target = os.path.join(out_dir, uri)
    os.makedirs(os.path.dirname(target), exist_ok=True)
    if not os.path.lexists(target):
        os.symlink(os.path.abspath(os.path.join(src_dir, uri)), target)


def scene(src, geometry, out):
    if not src.endswith(".gltf"):
        sys.exit(f"embree_twin: error: {src}: only .gltf scenes (JSON with separate buffers)")
    with open(src) as f:
        g = json.load(f)
    lo, hi = bounds_of_obj(geometry)
    diag = math.dist(lo, hi)
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    light = [centre[0], lo[1] + 0.9 * (hi[1] - lo[1]), centre[2]]
    intensity = 0.5 * diag * diag
    materials = []
    for m in g.get("materials", []):
        kd = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])[:3]
        materials.append({"name": m.get("name", ""), "extras": {"glint": {"model": "phong", "kd": kd, "ks": [0, 0, 0]}}})
    g["materials"] = materials
    for key in ("textures", "images", "samplers"):
        g.pop(key, None)
    for node in g.get("nodes", []):
        node.get("extensions", {}).pop("KHR_lights_punctual", None)
    g.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": [{"type": "point", "intensity": intensity}]}
    used = g.setdefault("extensionsUsed", [])
    if "KHR_lights_punctual" not in used:
        used.append("KHR_lights_punctual")
    g.setdefault("nodes", []).append({"name": "benchmark light", "translation": light,
                                      "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g["scenes"][g.get("scene", 0)]["nodes"].append(len(g["nodes"]) - 1)
    out_dir = os.path.dirname(os.path.abspath(out))
    for b in g.get("buffers", []):
        if "uri" in b:
            link_beside(b["uri"], os.path.dirname(os.path.abspath(src)), out_dir)
    with open(out, "w") as f:
        json.dump(g, f)
    print("--pointlight %.9g %.9g %.9g %.9g %.9g %.9g" % (*light, intensity, intensity, intensity))


def camera(stats):
    with open(stats) as f:
        c = json.load(f)["camera"]
    at = [p + d for p, d in zip(c["position"], c["forward"])]
    print("--vp %.9g %.9g %.9g --vi %.9g %.9g %.9g --vu %.9g %.9g %.9g --fov %.9g"
          % (*c["position"], *at, *c["up"], c["yfov_degrees"]))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "scene":
        scene(*sys.argv[2:])
    elif len(sys.argv) == 3 and sys.argv[1] == "camera":
        camera(sys.argv[2])
    else:
        sys.exit(__doc__)
