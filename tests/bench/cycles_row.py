#!/usr/bin/env python3
"""The headline benchmark's Blender Cycles row (opt-in, where Blender is installed): the scene and
camera glint's bench renders, Cycles on the CPU with unbiased settings (scripts/blender_render.py:
no clamping, no glossy filter, no denoising, no adaptive sampling) for the same time budgets on the
same threads, each budget with several seeds; its error against the bench's reference split into
noise and bias as `glint bench` splits it (docs/benchmarks.md).

    cycles_row.py GLINT SCENE REF.exr OUTDIR [--size WxH] [--times 10,60] [--seeds 2]
                  [--threads N] [--env MAP] [--max-depth D]
    cycles_row.py test GLINT
        The opt-in ctest (label blender): exits 77, ctest's skip, unless GLINT_BLENDER=1 and
        `blender` is installed. A small row of builtin:bay (64x48, 0.5 and 2 s, 2 seeds) against a
        quick glint reference: every figure finite, and the longer budget more samples and less noise.

SCENE is a glTF file or builtin:NAME (assets/scenes/NAME.gltf). Prints a Markdown table and writes
OUTDIR/cycles.csv beside the renders. Cycles' time limit leaves out its scene set-up, as glint's
budgets leave out loading. Read the noise as Cycles' own (and, where its picture is brighter or
darker than glint's, the noise against its own mean image); the error and bias also hold where
Cycles' materials differ from glint's: a few per cent for the glTF model (docs/benchmarks.md,
"the glTF material model against Blender Cycles"), more for glint's own Phong and Ward lobes,
which Cycles renders as their nearest lobes of its own (blender_render.py says how).

Standard library only; the EXR reader and the way Blender is run are blender_twin.py's.
"""
import math
import os
import re
import subprocess
import sys
import tempfile

from blender_twin import BLENDER_SCRIPT, ROOT, fail, read_exr, run_cmd, skip_without_blender

RELMSE_EPS = 1e-2  # renderer/metrics.h's METRIC_RELMSE_EPS


def options(argv):
    if len(argv) < 4:
        fail("usage: cycles_row.py GLINT SCENE REF.exr OUTDIR [--size WxH] [--times 10,60] [--seeds 2] "
             "[--threads N] [--env MAP] [--max-depth D]")
    o = {"glint": argv[0], "scene": argv[1], "ref": argv[2], "out": argv[3], "size": "320x240",
         "times": "10,60", "seeds": "2", "threads": str(os.cpu_count() or 1), "env": None, "max_depth": "16"}
    rest = argv[4:]
    for i in range(0, len(rest), 2):
        key = rest[i].lstrip("-").replace("-", "_")
        if key not in o or i + 1 >= len(rest):
            fail("unknown option or missing value: " + rest[i])
        o[key] = rest[i + 1]
    return o


def scene_file(scene):
    if scene.startswith("builtin:"):
        path = os.path.join(ROOT, "assets", "scenes", scene[len("builtin:"):] + ".gltf")
        if not os.path.isfile(path):
            fail(scene + ": no such built-in scene file " + path)
        return path
    return scene


def rgb(path):
    w, h, ch = read_exr(path)
    if not all(c in ch for c in "RGB"):
        fail(path + ": no R, G, B channels")
    out = []
    for r, g, b in zip(ch["R"], ch["G"], ch["B"]):
        out += (r, g, b)
    return (w, h), out


def ref_noise(glint, image, ref):
    """The reference's own relative noise, from its description (glint compare prints it)."""
    line = subprocess.run([glint, "compare", image, ref], capture_output=True, text=True).stdout
    m = re.search(r"ref_noise=([0-9.eE+-]+)", line)
    return float(m.group(1)) if m else 0.0


def samples_of(log):
    """The samples Cycles reached (its last progress line's)."""
    done = 0
    with open(log) as f:
        for m in re.finditer(r"Sample (\d+)/", f.read()):
            done = max(done, int(m.group(1)))
    return done


def measure(o):
    """The row: (budget, rel. L2, rel. MSE, noise, bias, own noise, samples) per budget."""
    os.makedirs(o["out"], exist_ok=True)
    scene, times, seeds = scene_file(o["scene"]), [float(t) for t in o["times"].split(",")], int(o["seeds"])
    env = ["--env", o["env"]] if o["env"] else []
    cam = os.path.join(o["out"], "camera.json")
    run_cmd([o["glint"], "render", o["scene"], "--size", o["size"], "--spp", "1", "--max-depth", o["max_depth"],
             "--stats", cam, "--out", os.path.join(o["out"], "camera.exr"), "--quiet"] + env,
            os.path.join(o["out"], "camera.log"))
    size, ref = rgb(o["ref"])
    norm2 = sum(v * v for v in ref)
    rows = []
    for t in times:
        images, samples = [], []
        for seed in range(1, seeds + 1):
            name = os.path.join(o["out"], "cycles-%gs-seed%d" % (t, seed))
            run_cmd(["blender", "-b", "-t", o["threads"], "--factory-startup", "-P", BLENDER_SCRIPT, "--", scene,
                     name + ".exr", "--size", o["size"], "--camera", cam, "--time-limit", "%g" % t, "--seed",
                     str(seed), "--max-depth", o["max_depth"]] + env, name + ".log")
            got, img = rgb(name + ".exr")
            if got != size:
                fail("%s.exr is %dx%d, the reference %dx%d" % (name, got[0], got[1], size[0], size[1]))
            images.append(img)
            samples.append(samples_of(name + ".log"))
        r = ref_noise(o["glint"], name + ".exr", o["ref"])
        err2 = [sum((a - b) ** 2 for a, b in zip(img, ref)) for img in images]
        relmse = [sum((a - b) ** 2 / (b * b + RELMSE_EPS) for a, b in zip(img, ref)) / len(ref) for img in images]
        mean = [sum(v) / seeds for v in zip(*images)]
        mean_err2 = sum((a - b) ** 2 for a, b in zip(mean, ref))
        # as metric_noise_bias: the runs' spread about their mean, and what the mean's error keeps
        noise = bias = float("nan")
        if seeds >= 2:
            noise2 = max(sum(err2) - seeds * mean_err2, 0.0) / (seeds - 1)
            bias2 = max(mean_err2 - noise2 / seeds - r * r * norm2, 0.0)
            noise, bias = math.sqrt(noise2 / norm2), math.sqrt(bias2 / norm2)
        rms = math.sqrt(sum(err2) / seeds / norm2)
        # the noise against Cycles' own picture (its mean image): where its materials make the
        # scene brighter or darker than glint's, this is the figure to set beside glint's noise
        own = noise * math.sqrt(norm2 / max(sum(v * v for v in mean), 1e-30)) if seeds >= 2 else float("nan")
        rows.append((t, rms, sum(relmse) / seeds, noise, bias, own, sum(samples) / seeds))
    return rows


def report(o, rows):
    with open(os.path.join(o["out"], "cycles.csv"), "w") as f:
        f.write("budget,rel_l2,relmse,noise,bias,own_noise,samples\n")
        for row in rows:
            f.write("%g,%.6g,%.6g,%.6g,%.6g,%.6g,%.1f\n" % row)
    version = subprocess.run(["blender", "--version"], capture_output=True, text=True).stdout.split("\n")[0]
    print("\n### %s, Cycles (%s, CPU, %s threads, %s seeds)\n" % (o["scene"], version, o["threads"], o["seeds"]))
    print("| budget | rel. L2 | rel. MSE | noise | bias | noise of its own picture | samples |\n"
          "|---|---|---|---|---|---|---|")
    for t, rms, mse, noise, bias, own, spp in rows:
        print("| %g s | %.4f | %.4g | %.4f | %.4f | %.4f | %.0f |" % (t, rms, mse, noise, bias, own, spp))


def test(glint):
    skip_without_blender("cycles_row")
    with tempfile.TemporaryDirectory() as tmp:
        ref = os.path.join(tmp, "ref.exr")
        run_cmd([glint, "render", "builtin:bay", "--method", "pt", "--size", "64x48", "--spp", "256", "--out", ref,
                 "--quiet"], os.path.join(tmp, "ref.log"))
        o = options([glint, "builtin:bay", ref, tmp, "--size", "64x48", "--times", "0.5,2", "--seeds", "2"])
        rows = measure(o)
        report(o, rows)
    ok = len(rows) == 2 and all(math.isfinite(v) for row in rows for v in row)
    ok = ok and rows[1][6] > rows[0][6] and rows[1][3] < rows[0][3]
    print("cycles_row: %s" % ("a row measured" if ok else "FAILED: the row is not finite, or longer is not better"))
    sys.exit(0 if ok else 1)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "test":
        test(sys.argv[2])
    o = options(sys.argv[1:])
    report(o, measure(o))


if __name__ == "__main__":
    main()
