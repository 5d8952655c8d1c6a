#!/usr/bin/env python3
"""glint against an independent renderer, Blender Cycles (Debian 12: Blender 3.4), on the shared
scenes: the same scene, camera, size, environment and path depth, rendered by both, compared per
block of pixels (docs/benchmarks.md, "glint against Blender Cycles").

    blender_twin.py run GLINT OUTDIR [--size WxH] [--spp N] [--env MAP] [--block PX] [--scenes A,B]
            [--scenes-dir DIR]
        Renders each scene with both (glint's path tracer, Cycles through scripts/blender_render.py)
        and prints, per scene, glint's luminance over Cycles' per block of PX pixels (40) and a
        summary, and for the sphere grid per grey sphere (metallic by roughness). The scenes: metal-rough-spheres as it is and as Lambert of its base colours (the
        control: the same BRDF in both), the damaged helmet, the water bottle, from the shared
        scenes' folder (not in the repository): --scenes-dir, else GLINT_SHARED_SCENES.
    blender_twin.py compare A.exr B.exr [--block PX]
        The same comparison of two EXRs (glint's or Blender's).

Scenes are rewritten beside the output (their files linked) with glTF's default material spelt
out where a primitive has none, which Blender's importer would leave without a material.
    blender_twin.py test GLINT
        The opt-in ctest (label blender): exits 77, ctest's skip, unless GLINT_BLENDER=1 and
        `blender` is installed (scripts/deps.sh: GLINT_BLENDER=1 installs it). Renders the
        Lambert control small and fails unless the two agree (whole image within 1.5%, nine in ten
        40-pixel blocks within 4%).

Standard library only (an EXR reader for the scanline files both renderers write: no, ZIP or ZIPS
compression, half or float channels).
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
BLENDER_SCRIPT = os.path.join(ROOT, "scripts", "blender_render.py")


def fail(msg):
    sys.exit("blender_twin: error: " + msg)


# ---- EXR ------------------------------------------------------------------------------------------

def read_exr(path):
    """(width, height, {channel: [float] row-major}) of a scanline EXR."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        fail(path + ": not an OpenEXR file")
    if data[5] & 0x1a:  # tiled (bit 9), deep (11), multi-part (12); long names (10) are fine
        fail(path + ": tiled, deep or multi-part EXRs are not read here")
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        name, kind = data[pos:name_end].decode(), data[name_end + 1:type_end].decode()
        size = struct.unpack_from("<i", data, type_end + 1)[0]
        attrs[name] = (kind, data[type_end + 5:type_end + 5 + size])
        pos = type_end + 5 + size
    pos += 1
    chans, raw = [], attrs["channels"][1]
    p = 0
    while raw[p] != 0:
        end = raw.index(b"\0", p)
        ptype = struct.unpack_from("<i", raw, end + 1)[0]
        chans.append((raw[p:end].decode(), ptype))
        p = end + 17
    comp = attrs["compression"][1][0]
    if comp not in (0, 2, 3):
        fail("%s: compression %d is not read here (none, ZIPS or ZIP only)" % (path, comp))
    x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines_per_chunk = {0: 1, 2: 1, 3: 16}[comp]
    nchunks = (h + lines_per_chunk - 1) // lines_per_chunk
    offsets = struct.unpack_from("<%dQ" % nchunks, data, pos)
    out = {name: [0.0] * (w * h) for name, _ in chans}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        block = data[off + 8:off + 8 + size]
        lines = min(lines_per_chunk, y1 + 1 - y)
        expect = lines * w * sum(2 if t == 1 else 4 for _, t in chans)
        if comp != 0 and size < expect:
            t = bytearray(zlib.decompress(block))
            for i in range(1, len(t)):  # the predictor
                t[i] = (t[i - 1] + t[i] - 128) & 0xff
            half = (len(t) + 1) // 2
            block = bytearray(len(t))
            block[0::2], block[1::2] = t[:half], t[half:]
        p = 0
        for line in range(lines):
            row = (y - y0 + line) * w
            for name, ptype in chans:
                fmt, n = ("<%de" % w, 2) if ptype == 1 else ("<%df" % w, 4)
                out[name][row:row + w] = struct.unpack_from(fmt, block, p)
                p += n * w
    return w, h, out


def luminance(img):
    w, h, ch = img
    r, g, b = ch["R"], ch["G"], ch["B"]
    return w, h, [0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i] for i in range(w * h)]


# ---- comparison -----------------------------------------------------------------------------------

def compare(a_path, b_path, block):
    """Per-block mean luminance of A over B's: the grid of ratios and a summary dict."""
    aw, ah, a = luminance(read_exr(a_path))
    bw, bh, b = luminance(read_exr(b_path))
    if (aw, ah) != (bw, bh):
        fail("%s is %dx%d, %s %dx%d" % (a_path, aw, ah, b_path, bw, bh))
    grid, ratios = [], []
    for by in range(0, ah, block):
        row = []
        for bx in range(0, aw, block):
            sa = sb = 0.0
            for y in range(by, min(by + block, ah)):
                for x in range(bx, min(bx + block, aw)):
                    sa += a[y * aw + x]
                    sb += b[y * aw + x]
            r = sa / sb if sb > 0 else float("nan")
            row.append(r)
            if sb > 0:
                ratios.append(r)
        grid.append(row)
    ratios.sort()
    n = len(ratios)
    dev = sorted(abs(r - 1.0) for r in ratios)
    summary = {
        "image": sum(a) / sum(b) if sum(b) > 0 else float("nan"),
        "median": ratios[n // 2] if n else float("nan"),
        "min": ratios[0] if n else float("nan"),
        "max": ratios[-1] if n else float("nan"),
        "within_2pc": sum(d <= 0.02 for d in dev) / max(n, 1),
        "within_5pc": sum(d <= 0.05 for d in dev) / max(n, 1),
        "p90_dev": dev[min(n - 1, int(0.9 * n))] if n else float("nan"),
    }
    return grid, summary


def print_comparison(title, grid, s, block):
    print("### %s\n" % title)
    print("glint / Cycles, mean luminance per %d-pixel block (rows top to bottom):\n" % block)
    print("```")
    for row in grid:
        print(" ".join("%5.3f" % r for r in row))
    print("```\n")
    print("whole image %.4f; blocks: median %.4f, range %.3f to %.3f, %.0f%% within 2%%, %.0f%% within 5%%, "
          "nine in ten within %.1f%%\n" % (s["image"], s["median"], s["min"], s["max"], 100 * s["within_2pc"],
                                          100 * s["within_5pc"], 100 * s["p90_dev"]))


def sphere_grid(scene_path, stats_path, size):
    """The grey spheres of the sphere grid (MetalRoughSpheres), in front of the gold ones: per
    sphere its metallic and roughness (from the node's name, mM%_rR%) and the disk of pixels of its
    inner half radius, projected with glint's camera (--stats)."""
    with open(scene_path) as f:
        g = json.load(f)
    with open(stats_path) as f:
        cam = json.load(f)["camera"]
    w, h = (int(x) for x in size.split("x"))
    p, fw, up = cam["position"], cam["forward"], cam["up"]
    right = [fw[1] * up[2] - fw[2] * up[1], fw[2] * up[0] - fw[0] * up[2], fw[0] * up[1] - fw[1] * up[0]]
    th = math.tan(math.radians(cam["yfov_degrees"]) / 2)
    nodes, out = g["nodes"], []

    def visit(i, t):
        n = nodes[i]
        if "rotation" in n or "scale" in n or "matrix" in n:
            return  # the grid's sphere nodes are translated only
        t = [a + b for a, b in zip(t, n.get("translation", [0, 0, 0]))]
        name = n.get("name", "")
        if "mesh" in n and name.startswith("m") and "_r" in name:
            acc = g["accessors"][g["meshes"][n["mesh"]]["primitives"][0]["attributes"]["POSITION"]]
            radius = 0.5 * (acc["max"][0] - acc["min"][0])
            d = [a - b for a, b in zip(t, p)]
            z = sum(a * b for a, b in zip(d, fw))
            x, y = sum(a * b for a, b in zip(d, right)), sum(a * b for a, b in zip(d, up))
            px, py = (0.5 + 0.5 * x / (z * th * w / h)) * w, (0.5 - 0.5 * y / (z * th)) * h
            metal, rough = (int(v.rstrip("%")) for v in name[1:].split("_r"))
            out.append((metal, rough, px, py, 0.5 * radius / (z * th) * h / 2))
        for c in n.get("children", []):
            visit(c, t)

    for root in [i for i, n in enumerate(nodes) if n.get("name") == "Gray Spheres"]:
        visit(root, [0, 0, 0])
    return out


def compare_spheres(a_path, b_path, spheres):
    """Mean luminance of A over B's within each sphere's disk: {(metallic, roughness): ratio}."""
    aw, ah, a = luminance(read_exr(a_path))
    _, _, b = luminance(read_exr(b_path))
    ratios = {}
    for metal, rough, px, py, r in spheres:
        sa = sb = 0.0
        for y in range(max(0, int(py - r)), min(ah, int(py + r) + 1)):
            for x in range(max(0, int(px - r)), min(aw, int(px + r) + 1)):
                if (x + 0.5 - px) ** 2 + (y + 0.5 - py) ** 2 <= r * r:
                    sa += a[y * aw + x]
                    sb += b[y * aw + x]
        if sb > 0:
            ratios[(metal, rough)] = sa / sb
    return ratios


def print_spheres(ratios):
    metals, roughs = sorted({m for m, _ in ratios}, reverse=True), sorted({r for _, r in ratios})
    print("glint / Cycles per grey sphere (the inner half of its disk), metallic down, roughness across:\n")
    print("| metallic \\ roughness | " + " | ".join("%d%%" % r for r in roughs) + " |")
    print("|---" * (len(roughs) + 1) + "|")
    for m in metals:
        print("| %d%% | " % m + " | ".join("%.3f" % ratios.get((m, r), float("nan")) for r in roughs) + " |")
    print()


# ---- scenes and renders ---------------------------------------------------------------------------

def link_beside(scene_path, out_dir):
    """The scene's buffers and images, linked into out_dir so a rewritten .gltf there finds them."""
    src = os.path.dirname(os.path.abspath(scene_path))
    for name in os.listdir(src):
        if not name.endswith(".gltf"):
            target = os.path.join(out_dir, name)
            if not os.path.exists(target):
                os.symlink(os.path.join(src, name), target)


def explicit_default(g):
    """Primitives without a material get glTF's default material (white, metallic 1, roughness 1)
    spelt out: glint renders the default as the spec defines it, Blender's importer gives such
    primitives no material at all (Blender's grey diffuse). The sphere grid's labels are such."""
    default = None
    for mesh in g.get("meshes", []):
        for prim in mesh.get("primitives", []):
            if "material" not in prim:
                if default is None:
                    g.setdefault("materials", []).append({"name": "glTF default"})
                    default = len(g["materials"]) - 1
                prim["material"] = default


def rewritten_scene(scene_path, out_dir, lambert):
    """scene_path with the default material explicit, written into out_dir (its files linked
    beside); with lambert, every material Lambert of its base colour (glint's Phong with ks 0,
    which the base colour texture tints as it tints Cycles' Diffuse BSDF) and no emission."""
    with open(scene_path) as f:
        g = json.load(f)
    explicit_default(g)
    for m in g.get("materials", []) if lambert else []:
        pbr = m.setdefault("pbrMetallicRoughness", {})
        kd = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
        pbr["metallicFactor"] = 0.0
        m.pop("emissiveFactor", None)
        m.pop("emissiveTexture", None)
        m.setdefault("extras", {})["glint"] = {"model": "phong", "kd": kd, "ks": [0, 0, 0], "exponent": 1}
    os.makedirs(out_dir, exist_ok=True)
    link_beside(scene_path, out_dir)
    out = os.path.join(out_dir, "lambert.gltf" if lambert else os.path.basename(scene_path))
    with open(out, "w") as f:
        json.dump(g, f)
    return out


def run_cmd(cmd, log):
    # Blender's embedded Python takes its prefix from the first python3 on PATH: this script run
    # by another interpreter (a pyenv one) would hide Debian's, and its numpy, from Blender.
    env = dict(os.environ)
    if sys.prefix != "/usr":
        env["PATH"] = ":".join(d for d in env.get("PATH", "").split(":") if not d.startswith(sys.prefix))
    with open(log, "w") as f:
        rc = subprocess.call(cmd, stdout=f, stderr=subprocess.STDOUT, env=env)
    if rc != 0:
        fail("%s failed (exit %d); see %s" % (os.path.basename(cmd[0]), rc, log))


def render_pair(glint, scene, env, size, spp, out_dir, name, lambert):
    """glint and Cycles renders of scene: (glint.exr, cycles.exr)."""
    g_exr, stats = os.path.join(out_dir, name + "-glint.exr"), os.path.join(out_dir, name + "-glint.json")
    c_exr = os.path.join(out_dir, name + "-cycles.exr")
    run_cmd([glint, "render", scene, "--env", env, "--method", "pt", "--spp", str(spp), "--size", size, "--out",
             g_exr, "--stats", stats, "--quiet"], os.path.join(out_dir, name + "-glint.log"))
    cmd = ["blender", "-b", "--factory-startup", "-P", BLENDER_SCRIPT, "--", scene, c_exr, "--size", size,
           "--samples", str(spp), "--camera", stats, "--env", env]
    run_cmd(cmd + (["--lambert"] if lambert else []), os.path.join(out_dir, name + "-cycles.log"))
    return g_exr, c_exr


def scenes_dir(given=None):
    """The shared scenes (glTF samples by others, not in the repository): --scenes-dir, else
    GLINT_SHARED_SCENES (the test sets it from CMake's GLINT_SHARED_SCENES); no guess beside it."""
    d = given or os.environ.get("GLINT_SHARED_SCENES")
    if not d:
        fail("the shared scenes' folder: give --scenes-dir DIR or set GLINT_SHARED_SCENES")
    if not os.path.isdir(d):
        fail(d + ": not a folder (the shared scenes')")
    return d


def options(args, defaults):
    opts = dict(defaults)
    i = 0
    while i < len(args):
        key = args[i].lstrip("-").replace("-", "_")
        if key not in opts or i + 1 >= len(args):
            fail("unknown option or missing value: " + args[i])
        opts[key] = args[i + 1]
        i += 2
    return opts


def cmd_run(glint, out_dir, args):
    o = options(args, {"size": "320x320", "spp": "256", "env": "", "block": "40",
                       "scenes": "mrs-lambert,mrs,helmet,bottle", "scenes_dir": ""})
    sc = scenes_dir(o["scenes_dir"])
    o["env"] = o["env"] or os.path.join(sc, "envmaps", "blender_studio.exr")
    os.makedirs(out_dir, exist_ok=True)
    mrs = os.path.join(sc, "metal-rough-spheres-notextures", "glTF", "MetalRoughSpheresNoTextures.gltf")
    runs = [("mrs-lambert", rewritten_scene(mrs, os.path.join(out_dir, "mrs-lambert"), True), True),
            ("mrs", rewritten_scene(mrs, os.path.join(out_dir, "mrs"), False), False),
            ("helmet", os.path.join(sc, "damaged-helmet", "glTF", "DamagedHelmet.gltf"), False),
            ("bottle", os.path.join(sc, "water-bottle", "glTF", "WaterBottle.gltf"), False)]
    print("## glint (%s) against Blender Cycles, %s, %s spp, environment %s\n" %
          (subprocess.run([glint, "--version"], capture_output=True, text=True).stdout.strip(), o["size"], o["spp"],
           os.path.basename(o["env"])))
    for name, scene, lambert in runs:
        if name not in o["scenes"].split(","):
            continue
        if not os.path.exists(scene):
            print("skipping %s: %s not found\n" % (name, scene))
            continue
        g, c = render_pair(glint, scene, o["env"], o["size"], o["spp"], out_dir, name, lambert)
        grid, s = compare(g, c, int(o["block"]))
        print_comparison(name + (" (Lambert control)" if lambert else ""), grid, s, int(o["block"]))
        if name.startswith("mrs"):
            print_spheres(compare_spheres(g, c, sphere_grid(scene, g[:-4] + ".json", o["size"])))


def skip_without_blender(name):
    """An opt-in Blender test's start: exits 77, ctest's skip, unless GLINT_BLENDER=1 and blender is there."""
    if os.environ.get("GLINT_BLENDER") != "1":
        print("%s: skipped (opt-in: set GLINT_BLENDER=1; it needs Blender, a large install)" % name)
        sys.exit(77)
    if shutil.which("blender") is None:
        print("%s: skipped: blender is not installed (GLINT_BLENDER=1 scripts/test.sh installs it)" % name)
        sys.exit(77)


def cmd_test(glint):
    skip_without_blender("blender_twin")
    sc = os.environ.get("GLINT_SHARED_SCENES", "")  # the test's: without the shared scenes it skips
    mrs = os.path.join(sc, "metal-rough-spheres-notextures", "glTF", "MetalRoughSpheresNoTextures.gltf")
    if not sc or not os.path.exists(mrs):
        print("blender_twin: skipped: %s not found" % mrs)
        sys.exit(77)
    with tempfile.TemporaryDirectory() as tmp:
        scene = rewritten_scene(mrs, os.path.join(tmp, "lambert"), True)
        env = os.path.join(sc, "envmaps", "blender_studio.exr")
        g, c = render_pair(glint, scene, env, "160x160", 128, tmp, "control", True)
        grid, s = compare(g, c, 40)
        print_comparison("Lambert control", grid, s, 40)
    ok = abs(s["image"] - 1.0) <= 0.015 and s["p90_dev"] <= 0.04
    print("blender_twin: %s" % ("the Lambert control agrees" if ok else "FAILED: the Lambert control differs"))
    sys.exit(0 if ok else 1)


def main():
    a = sys.argv[1:]
    if len(a) >= 3 and a[0] == "run":
        cmd_run(a[1], a[2], a[3:])
    elif len(a) >= 3 and a[0] == "compare":
        o = options(a[3:], {"block": "40"})
        grid, s = compare(a[1], a[2], int(o["block"]))
        print_comparison("%s / %s" % (a[1], a[2]), grid, s, int(o["block"]))
    elif len(a) == 2 and a[0] == "test":
        cmd_test(a[1])
    else:
        fail("usage: blender_twin.py run GLINT OUTDIR [options] | compare A.exr B.exr | test GLINT")


if __name__ == "__main__":
    main()
