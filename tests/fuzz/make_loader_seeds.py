#!/usr/bin/env python3
"""Writes the seeds of the image fuzzer (corpus-image/) and of the reference fuzzer
(corpus-reference/). Usage: make_loader_seeds.py BUILD, BUILD being a test build (it holds
tests/make_exr_seeds and app/glint). EXRs come from make_exr_seeds (the tests' writer and glint's
own), a multi-part EXR from OpenEXR's exrmultipart when installed; Radiance HDRs are written here;
the reference descriptions are read from a render by glint, then broken in several ways."""
import json, os, shutil, struct, subprocess, sys, tempfile

here = os.path.dirname(os.path.abspath(__file__))
build = os.path.abspath(sys.argv[1]) if len(sys.argv) == 2 else sys.exit(__doc__)
img_dir, ref_dir = os.path.join(here, "corpus-image"), os.path.join(here, "corpus-reference")
for d in (img_dir, ref_dir):
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)


def put(d, name, data):
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


# ---- EXR ----------------------------------------------------------------------------------------
subprocess.run([os.path.join(build, "tests", "make_exr_seeds"), img_dir], check=True)
if shutil.which("exrmultipart"):
    a, b = os.path.join(img_dir, "scanline-zip-half.exr"), os.path.join(img_dir, "tiled-piz-windows.exr")
    subprocess.run(["exrmultipart", "-combine", "-i", a, b, "-o", os.path.join(img_dir, "multipart.exr")],
                   check=True, stdout=subprocess.DEVNULL)


# ---- Radiance HDR: flat and run-length encoded scanlines ----------------------------------------
def rgbe(r, g, b):
    m = max(r, g, b)
    if m < 1e-32:
        return bytes(4)
    e = 0
    while m >= 1.0:
        m, e = m / 2, e + 1
    while m < 0.5:
        m, e = m * 2, e - 1
    s = 256.0 / 2 ** e
    return bytes([int(r * s) & 255, int(g * s) & 255, int(b * s) & 255, e + 128])


def hdr(w, h, rle, magic=b"#?RADIANCE", extra=b""):
    head = magic + b"\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n" + extra + b"\n-Y %d +X %d\n" % (h, w)
    body = b""
    for y in range(h):
        px = [rgbe(0.1 * x + 0.05, 0.3 + 0.01 * y, 2.0 if x < w // 2 else 0.0) for x in range(w)]
        if not rle:
            body += b"".join(px)
            continue
        body += bytes([2, 2, w >> 8, w & 255])
        for c in range(4):  # each component: a run of the first half, literals for the rest
            vals = [p[c] for p in px]
            half = w // 2
            if len(set(vals[:half])) == 1:
                body += bytes([128 + half, vals[0]])
            else:
                body += bytes([half]) + bytes(vals[:half])
            body += bytes([w - half]) + bytes(vals[half:])
    return head + body


put(img_dir, "flat.hdr", hdr(4, 3, False))
put(img_dir, "rle.hdr", hdr(16, 4, True))
put(img_dir, "rgbe-magic.hdr", hdr(8, 2, True, b"#?RGBE", b"GAMMA=1\n"))
put(img_dir, "truncated.hdr", hdr(16, 4, True)[:-20])


# ---- reference descriptions ---------------------------------------------------------------------
def exr_string_attr(data, want):
    """The value of a string attribute in a single-part EXR's header."""
    i = 8
    while data[i] != 0:
        name_end = data.index(b"\0", i)
        type_end = data.index(b"\0", name_end + 1)
        (n,) = struct.unpack_from("<i", data, type_end + 1)
        if data[i:name_end] == want:
            return data[type_end + 5:type_end + 5 + n]
        i = type_end + 5 + n
    return None


with tempfile.TemporaryDirectory() as tmp:
    descriptions = []
    for i, extra in enumerate([[], ["--method", "vsl", "--env", "corpus-image/rle.hdr"]]):
        out = os.path.join(tmp, "r%d.exr" % i)
        subprocess.run([os.path.join(build, "app", "glint"), "render", "builtin:showcase", "--spp", "2", "--size",
                        "8x8", "--out", out] + extra, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       cwd=here)
        with open(out, "rb") as f:
            descriptions.append(exr_string_attr(f.read(), b"glint.reference"))
good = descriptions[0]
put(ref_dir, "render.json", good)
put(ref_dir, "render-env.json", descriptions[1])
doc = json.loads(good)


def variant(name, **changes):
    d = json.loads(good)
    for k, v in changes.items():
        if v is None:
            d.pop(k, None)
        else:
            d[k] = v
    put(ref_dir, name, json.dumps(d, indent=1).encode())


variant("big-seed.json", seed=18446744073709551615)
variant("seed-2p53.json", seed=9007199254740993)
variant("legacy-builtin.json", scene_hash="builtin:default:fnv1a64:0123456789abcdef")
variant("noise.json", variance={"mean_pixel_variance": 1e-4, "rel_l2_noise": 0.01, "estimate": "x"})
variant("escaped.json", scene="a \"quoted\"\\path\n\u00e9\u2603", env="tab\there")
variant("missing-camera.json", camera=None)
variant("bad-width.json", width=0)
variant("float-index.json", camera=dict(doc["camera"], index=0.5))
variant("wrong-types.json", spp="2", highlights_layer=1, method=["pt"])
put(ref_dir, "huge-number.json", good.replace(b'"seconds": ', b'"seconds": 1e999, "x": '))
put(ref_dir, "truncated.json", good[: len(good) // 2])
put(ref_dir, "nul.json", good[:20] + b"\0" + good[20:])
put(ref_dir, "nested.json", b"[" * 1200 + b"]" * 1200)
put(ref_dir, "not-object.json", b'["glint_reference", 1]')
put(ref_dir, "empty.json", b"")
