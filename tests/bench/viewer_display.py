#!/usr/bin/env python3
"""The bookkeeping of tests/bench/viewer_display.sh (standard library only): which poses its
captures need references for, and the table of their errors. A pose is a scene, a camera and
light edits, read from each capture's description (the glint.reference EXR header attribute).

  viewer_display.py poses CAPTURES REFS SPP_REST SPP_MOTION
      assigns each capture a pose in REFS/poses.json (a pose within the viewer's tolerance of a
      known one is that one: camera_same_view's test, renderer/camera.c; lights within float
      noise), writes REFS/poses.md (the list of poses), and prints one line per reference still
      missing: REF SPP CAPTURE SCENE WxH [--move-light G,DX,DY,DZ | --light-gain G,X]...
      (tab-separated). Captures during motion (during-*.exr) need SPP_MOTION, the others SPP_REST;
      a pose needed at both gets the larger.
  viewer_display.py table CAPTURES REFS GLINT OUT
      compares every capture with its pose's reference (glint compare, which checks the pose
      again) and writes OUT.md and OUT.csv.

The lookup here only finds the file: glint compare is what refuses a reference of another pose.
"""
import csv
import json
import math
import os
import re
import struct
import subprocess
import sys


def exr_description(path):
    """The glint.reference string attribute of an EXR header, parsed; None without one."""
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(path + ": not an OpenEXR file")
    pos = 8
    while pos < len(data) and data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode("latin-1")
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1:tend].decode("latin-1")
        (size,) = struct.unpack("<i", data[tend + 1:tend + 5])
        value = data[tend + 5:tend + 5 + size]
        if name == "glint.reference" and kind == "string":
            return json.loads(value.decode("utf-8"))
        pos = tend + 5 + size
    return None


def captures(root):
    """(path, scene, method, scenario, name) of every capture under root/SCENE/METHOD/SCENARIO/:
    opened-T, during-N and after-T.exr."""
    found = []
    for dirpath, _, files in os.walk(root):
        rel = os.path.relpath(dirpath, root).split(os.sep)
        if len(rel) != 3:
            continue
        for name in sorted(files):
            if name.endswith(".exr") and name.split("-")[0] in ("opened", "during", "after"):
                found.append((os.path.join(dirpath, name), rel[0], rel[1], rel[2], name[:-4]))
    return sorted(found)


def parse_lights(text):
    edits = {}
    for item in filter(None, text.split(";")):
        m = re.fullmatch(r"(\d+):([^,]+),([^,]+),([^*]+)\*(.+)", item)
        if not m:
            raise ValueError("bad light edit " + item)
        edits[int(m.group(1))] = tuple(float(m.group(k)) for k in range(2, 6))
    return edits


def near(a, b):
    return abs(a - b) <= 1e-5 * (1.0 + max(abs(a), abs(b)))


def lights_same(a, b):
    ea, eb = parse_lights(a), parse_lights(b)
    for g in set(ea) | set(eb):
        x, y = ea.get(g, (0, 0, 0, 1)), eb.get(g, (0, 0, 0, 1))
        if not all(near(p, q) for p, q in zip(x, y)):
            return False
    return True


def dot(a, b):
    return sum(p * q for p, q in zip(a, b))


def same_view(a, b, scale):
    """renderer/camera.c's camera_same_view, on descriptions' cameras."""
    d = math.sqrt(sum((p - q) ** 2 for p, q in zip(a["position"], b["position"])))
    return (d <= 1e-4 * scale and dot(a["forward"], b["forward"]) >= 1 - 1e-5 and dot(a["up"], b["up"]) >= 1 - 1e-5
            and abs(a["yfov"] - b["yfov"]) <= 1e-4)


def pose_of(desc):
    return {"scene": desc["scene"], "scene_hash": desc["scene_hash"], "camera": desc["camera"],
            "lights": desc.get("lights", ""), "diag": desc.get("scene_diagonal", 0.0),
            "size": "%dx%d" % (desc["width"], desc["height"])}


def find_pose(poses, p):
    for i, q in enumerate(poses):
        if (q["scene_hash"] == p["scene_hash"] and q["size"] == p["size"] and lights_same(q["lights"], p["lights"])
                and same_view(q["camera"], p["camera"], max(q["diag"], p["diag"]))):
            return i
    return -1


def load_poses(refs):
    path = os.path.join(refs, "poses.json")
    return json.load(open(path)) if os.path.exists(path) else []


def save_poses(refs, poses):
    path = os.path.join(refs, "poses.json")
    with open(path + ".tmp", "w") as f:
        json.dump(poses, f, indent=1)
    os.replace(path + ".tmp", path)


def ref_path(refs, i, pose):
    name = pose["scene"].replace("builtin:", "").replace("/", "_")
    return os.path.join(refs, "%s-pose%03d-pt%d.exr" % (name, i, pose["spp"]))


def light_args(text):
    args = []
    for g, (dx, dy, dz, gain) in sorted(parse_lights(text).items()):
        if (dx, dy, dz) != (0, 0, 0):
            args += ["--move-light", "%d,%.9g,%.9g,%.9g" % (g, dx, dy, dz)]
        if gain != 1:
            args += ["--light-gain", "%d,%.9g" % (g, gain)]
    return args


def cmd_poses(root, refs, spp_rest, spp_motion):
    os.makedirs(refs, exist_ok=True)
    poses = load_poses(refs)
    for path, scene, method, scenario, name in captures(root):
        desc = exr_description(path)
        if desc is None:
            sys.exit(path + ": no glint description")
        p = pose_of(desc)
        need = spp_motion if name.startswith("during-") else spp_rest
        i = find_pose(poses, p)
        if i < 0:
            p.update(spp=need, source=path, uses=[])
            poses.append(p)
            i = len(poses) - 1
        elif poses[i]["spp"] < need and not os.path.exists(ref_path(refs, i, poses[i])):
            poses[i]["spp"] = need
        use = "%s %s %s %s" % (scene, method, scenario, name)
        if use not in poses[i]["uses"]:
            poses[i]["uses"].append(use)
        if not os.path.exists(poses[i]["source"]):
            poses[i]["source"] = path  # a capture of this pose that is still there
    save_poses(refs, poses)
    with open(os.path.join(refs, "poses.md"), "w") as f:
        f.write("| pose | scene | camera position | forward | lights | spp | captures |\n|---|---|---|---|---|---|---|\n")
        for i, p in enumerate(poses):
            c = p["camera"]
            f.write("| %d | %s | %s | %s | %s | %d | %d |\n" % (
                i, p["scene"], " ".join("%.4f" % v for v in c["position"]),
                " ".join("%.4f" % v for v in c["forward"]), p["lights"] or "as loaded", p["spp"], len(p["uses"])))
    for i, p in enumerate(poses):
        ref = ref_path(refs, i, p)
        if not os.path.exists(ref):
            print("\t".join([ref, str(p["spp"]), p["source"], p["scene"], p["size"]] + light_args(p["lights"])))


def stats_lines(path):
    out = []
    for line in open(path) if os.path.exists(path) else []:
        if line.startswith("stats "):
            out.append(dict(kv.split("=", 1) for kv in line.split()[1:] if "=" in kv))
    return out


def orbit_rates(scenario_dir):
    """Updates a second during the orbit, from the stats lines before and after it."""
    s = stats_lines(os.path.join(scenario_dir, "stdout.txt"))
    if len(s) < 2 or "images" not in s[0]:
        return None
    a, b = s[0], s[1]
    dt = float(b["time"]) - float(a["time"])
    n = int(b["images"]) - int(a["images"])
    full = int(b["images_full"]) - int(a["images_full"])
    px = int(b["image_pixels"]) - int(a["image_pixels"])
    w, h = (int(v) for v in b["render_size"].split("x"))
    return {"seconds": dt, "updates_per_s": n / dt, "full_per_s": full / dt,
            "pixel_share": px / n / (w * h) if n else 0.0, "last_image": "%sx%s" % (b.get("width"), b.get("height"))}


def cmd_table(root, refs, glint, out):
    poses = load_poses(refs)
    rows = []
    for path, scene, method, scenario, name in captures(root):
        desc = exr_description(path)
        i = find_pose(poses, pose_of(desc))
        ref = ref_path(refs, i, poses[i]) if i >= 0 else None
        row = {"scene": scene, "method": method, "scenario": scenario,
               "when": name[len("after-"):] if name.startswith("after-") else name,
               "capture": name, "since_change": desc["capture"]["since_change"],
               "preview": desc["capture"]["preview"], "image": "%dx%d" % tuple(desc["capture"]["image_size"]),
               "latest": desc["capture"]["latest"], "frames": desc["spp"], "pose": i,
               "ref_spp": poses[i]["spp"] if i >= 0 else "", "rel_l2": "", "ref_noise": "", "net": "",
               "peak_share": ""}
        if ref and os.path.exists(ref):
            r = subprocess.run([glint, "compare", path, ref], capture_output=True, text=True)
            if r.returncode == 0:
                row.update(dict(kv.split("=") for kv in r.stdout.split()))
            else:
                row["net"] = "refused: " + r.stderr.strip()
        else:
            row["net"] = "no reference"
        if scenario == "orbit":
            rates = orbit_rates(os.path.dirname(path))
            if rates:
                row.update({"updates_per_s": "%.2f" % rates["updates_per_s"], "full_per_s": "%.2f" % rates["full_per_s"],
                            "pixel_share": "%.3f" % rates["pixel_share"], "orbit_s": "%.2f" % rates["seconds"],
                            "last_image": rates["last_image"]})
            free = orbit_rates(os.path.join(os.path.dirname(os.path.dirname(path)), "rate"))
            if free:  # the same orbit in a session without captures
                row.update({"free_per_s": "%.2f" % free["updates_per_s"], "free_full_per_s": "%.2f" % free["full_per_s"]})
        rows.append(row)
    def when_key(w):  # at rest after opening, the orbit's steps, then seconds after the stop
        if w.startswith("opened-"):
            return (0, float(w[len("opened-"):]))
        return (1, int(w[len("during-"):])) if w.startswith("during-") else (2, float(w))

    rows.sort(key=lambda r: (r["scene"], r["method"], r["scenario"], when_key(r["when"])))
    fields = ["scene", "method", "scenario", "when", "capture", "since_change", "preview", "image", "latest", "frames",
              "pose", "ref_spp", "rel_l2", "ref_noise", "net", "peak_share", "updates_per_s", "full_per_s", "pixel_share", "orbit_s",
              "last_image", "free_per_s", "free_full_per_s"]
    with open(out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    with open(out + ".md", "w") as f:
        f.write("Displayed error (relative L2 against path-traced references, the references' noise taken out) "
                "by scene, method and scenario; `when`: seconds after the stop, during-N: at the end of the orbit's step N of 10 (0.1 s after it), opened-10: 10 s after "
                "opening, before the orbit (plain accumulation at rest); "
                "`s after change`: when the capture was taken, after the last change (a step); `stale`: the image shown "
                "was not yet of the last change (its own pose is the one measured); `peak`: the share of the squared "
                "error in the 0.1% of the pixels where it is largest (near 1: a light's speck in a mirror decides "
                "the figure).\n\n")
        f.write("| scene | method | scenario | when | s after change | shown | net error | ref noise | peak |\n"
                "|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            shown = ("preview " + r["image"] if r["preview"] else "full, %s frames" % r["frames"]) + \
                    ("" if r["latest"] else ", stale")
            net = r["net"] if isinstance(r["net"], str) and not r["net"][:1].isdigit() else "%.4f" % float(r["net"])
            f.write("| %s | %s | %s | %s | %.2f | %s | %s | %s | %s |\n" % (
                r["scene"], r["method"], r["scenario"], r["when"], r["since_change"], shown, net,
                "%.4f" % float(r["ref_noise"]) if r["ref_noise"] != "" else "-",
                "%.2f" % float(r["peak_share"]) if r["peak_share"] != "" else "-"))
        f.write("\nDuring the orbit (15 degrees at 15 degrees a second), from the stats lines before and after it; "
                "`no captures`: the same orbit in a session of its own without captures (scenario rate), what a "
                "person gets:\n\n"
                "| scene | method | updates/s | full-resolution updates/s | full-resolution updates/s, no captures | "
                "mean pixels an update (of full) | orbit seconds | last image |\n|---|---|---|---|---|---|---|---|\n")
        seen = set()
        for r in rows:
            key = (r["scene"], r["method"])
            if r["scenario"] == "orbit" and "updates_per_s" in r and key not in seen:
                seen.add(key)
                f.write("| %s | %s | %s | %s | %s | %s | %s | %s |\n" % (
                    r["scene"], r["method"], r["updates_per_s"], r["full_per_s"], r.get("free_full_per_s", "-"),
                    r["pixel_share"], r["orbit_s"], r["last_image"]))


if __name__ == "__main__":
    if len(sys.argv) == 6 and sys.argv[1] == "poses":
        cmd_poses(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]))
    elif len(sys.argv) == 6 and sys.argv[1] == "table":
        cmd_table(*sys.argv[2:])
    else:
        sys.exit(__doc__)
