# share_map.py [--half] OUT.png RENDER.exr ...: each render's image (tone-mapped to its log-average) beside
# --method auto's map of the share of each pixel's samples the virtual lights gave (the EXR's
# vsl_share layer; blue the path tracer, orange the virtual lights, as the viewer's `show
# estimator`, over a quarter of the image's brightness), two renders a row (--half: at half their size, each 2x2 pixels' mean). Made docs/auto-share.png
# (docs/benchmarks.md, 2026-12-08). Needs numpy.
import os, struct, sys, zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_twin import read_exr
def load(p, layer=''):
    w, h, ch = read_exr(p)
    pre = layer + '.' if layer else ''
    return np.stack([np.array(ch[pre + c], dtype=np.float64).reshape(h, w) for c in 'RGB'], -1)
def tonemap(x):
    lum = x.mean(-1)
    key = 0.18 / np.exp(np.mean(np.log(lum + 1e-4)))
    y = x * key
    y = y / (1 + y.mean(-1, keepdims=True))
    return np.clip(np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(np.maximum(y, 0), 1 / 2.4) - 0.055), 0, 1)
def share_colour(s, img):
    s = np.clip(s, 0, 1)[..., None]
    c = np.concatenate([0.15 + 0.8 * s, 0.35 + 0.2 * s, 0.9 - 0.8 * s], -1)
    return np.clip(0.75 * c + 0.25 * img.mean(-1, keepdims=True), 0, 1)
def write_png(path, rgb):
    h, w, _ = rgb.shape
    raw = b''.join(b'\x00' + (rgb[y] * 255 + 0.5).astype(np.uint8).tobytes() for y in range(h))
    def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) + chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))
args = sys.argv[1:]
half = args[0] == '--half'
if half:
    args = args[1:]
pairs = []
for path in args[1:]:
    img = tonemap(load(path))
    pair = np.concatenate([img, share_colour(load(path, 'vsl_share')[..., 0], img)], 1)
    if half:
        h, w = pair.shape[0] // 2 * 2, pair.shape[1] // 2 * 2
        pair = pair[:h, :w].reshape(h // 2, 2, w // 2, 2, 3).mean((1, 3))
    pairs.append(np.concatenate([pair[:, :pair.shape[1] // 2], np.ones((pair.shape[0], 4, 3)), pair[:, pair.shape[1] // 2:]], 1))
rows = []
for i in range(0, len(pairs), 2):
    a = pairs[i]; b = pairs[i + 1] if i + 1 < len(pairs) else np.ones_like(a)
    rows.append(np.concatenate([a, np.ones((a.shape[0], 12, 3)), b], 1))
out = np.concatenate([np.concatenate([r, np.ones((12, r.shape[1], 3))], 0) for r in rows], 0)[:-12]
write_png(args[0], out)
