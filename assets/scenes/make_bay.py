#!/usr/bin/env python3
"""Writes bay.gltf, the built-in scene `bay`: one room, both regimes. A ceiling panel lights the
left half directly; a full-height partition walls off a bay on the right, open only towards the
front of the room, so that nothing in the bay sees the panel: it is lit by what the lit half
and the front of the room send into it. One polished floor runs through both; the lit half
has a table and a chrome sphere under the panel, the bay a red lacquer cabinet, a brass sphere
and a copper block. A method that wins in one half and loses in the other shows it here
(issue 46: an estimator that chooses per pixel).

    python3 assets/scenes/make_bay.py   # rewrites assets/scenes/bay.gltf
"""
from gltfkit import Scene, box, cylinder, emissive, merge, metal_rough, moved, phong, quad, sphere, write, yaw

MATERIALS = [
    metal_rough("white plaster", (0.78, 0.77, 0.74)),
    metal_rough("warm plaster", (0.78, 0.62, 0.45)),
    phong("polished stone", (0.6, 0.57, 0.52), kd=(0.5, 0.47, 0.42), ks=(0.3, 0.3, 0.3), exponent=200),
    emissive("ceiling panel", (1.0, 0.94, 0.86), 60.0),
    metal_rough("chrome", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.12),
    metal_rough("oak", (0.45, 0.3, 0.17), roughness=0.7),
    phong("red lacquer", (0.5, 0.06, 0.04), kd=(0.42, 0.04, 0.03), ks=(0.4, 0.4, 0.4), exponent=300),
    metal_rough("polished brass", (1.0, 0.82, 0.5), metallic=1.0, roughness=0.3),
    metal_rough("copper", (0.95, 0.64, 0.54), metallic=1.0, roughness=0.5),
]

# ---- the room: x in [-W, W], y in [0, H], z in [0, D]; walls face inwards ----------------------
# The partition stands at x in [0, T] from the back wall to z = ZP; the bay is x > T, z < ZP.

W, H, D = 3.0, 2.8, 5.0
T, ZP = 0.15, 3.0
PANEL = (-1.6, 1.4)  # the ceiling panel's centre (x, z), over the lit half
CAMERA_EYE, CAMERA_TARGET = (0.35, 1.5, 4.85), (0.15, 0.9, 0.6)

ROOM = [
    ("floor", "polished stone", quad((-W, 0, D), (2 * W, 0, 0), (0, 0, -D))),
    ("ceiling", "white plaster", quad((-W, H, 0), (2 * W, 0, 0), (0, 0, D))),
    ("back wall", "white plaster", quad((-W, 0, 0), (W, 0, 0), (0, H, 0))),
    ("bay's back wall", "warm plaster", quad((0, 0, 0), (W, 0, 0), (0, H, 0))),
    ("front wall", "white plaster", quad((W, 0, D), (-2 * W, 0, 0), (0, H, 0))),
    ("left wall", "white plaster", quad((-W, 0, D), (0, 0, -D), (0, H, 0))),
    ("right wall", "warm plaster", quad((W, 0, 0), (0, 0, D), (0, H, 0))),
    ("partition", "white plaster", moved(box((T, H, ZP)), (T / 2, H / 2, ZP / 2))),
    # 1.2 x 1.0 m, 1 cm under the ceiling, facing down.
    ("ceiling panel", "ceiling panel", quad((PANEL[0] - 0.6, H - 0.01, PANEL[1] - 0.5), (1.2, 0, 0), (0, 0, 1.0))),
]


def table():
    """A small table: a top on four legs."""
    return merge(moved(box((1.0, 0.05, 0.6)), (0, 0.73, 0)),
                 *[moved(box((0.05, 0.7, 0.05)), (x, 0.35, z)) for x in (-0.45, 0.45) for z in (-0.25, 0.25)])


OBJECTS = [  # name, material, mesh, translation, rotation
    ("table", "oak", table(), (-1.9, 0.0, 1.2), yaw(10)),
    ("chrome sphere", "chrome", sphere(0.3), (-0.8, 0.3, 2.4), None),
    ("cabinet", "red lacquer", box((1.2, 0.8, 0.45)), (1.6, 0.4, 0.3), None),
    ("brass sphere", "polished brass", sphere(0.28), (1.0, 0.28, 1.7), None),
    ("copper block", "copper", box((0.35, 0.5, 0.35)), (2.3, 0.25, 1.6), yaw(30)),
    ("stool", "oak", cylinder(0.2, 0.18, 0.45, 24), (-2.3, 0.0, 3.4), None),
]


def build():
    s = Scene(MATERIALS)
    s.add_meshes(ROOM)
    s.add_meshes(OBJECTS)
    s.camera(CAMERA_EYE, CAMERA_TARGET, yfov=0.95)
    return s.document("glint bay", "glint assets/scenes/make_bay.py")


if __name__ == "__main__":
    write(build(), __file__, "bay")
