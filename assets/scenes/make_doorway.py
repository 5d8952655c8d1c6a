#!/usr/bin/env python3
"""Writes doorway.gltf, the built-in scene `doorway`: two rooms joined by an open doorway. Both
lights are in the back room, a ceiling panel and a spot shining through the doorway; the camera
stands in the front room, which is lit only by what comes through the door: a pool of light on a
polished stone floor, seen again in a polished steel panel, a chrome sphere and a brushed steel
cabinet.

    python3 assets/scenes/make_doorway.py   # rewrites assets/scenes/doorway.gltf
"""
from gltfkit import (Scene, append, box, cylinder, emissive, merge, metal_rough, moved, phong, quad, sphere, spot,
                     ward, write, yaw)

MATERIALS = [
    metal_rough("white plaster", (0.78, 0.77, 0.74)),
    metal_rough("warm plaster", (0.78, 0.58, 0.36)),
    metal_rough("sage plaster", (0.55, 0.6, 0.5)),
    # Polished limestone: a sharp Phong lobe over a pale diffuse base.
    phong("polished stone", (0.6, 0.57, 0.52), kd=(0.5, 0.47, 0.42), ks=(0.35, 0.35, 0.35), exponent=300),
    emissive("ceiling panel", (1.0, 0.94, 0.86), 200.0),
    metal_rough("chrome", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.12),
    # Brushed stainless steel, anisotropic Ward: sharp along the brushing, rough across it.
    ward("brushed steel", (0.75, 0.75, 0.77), kd=(0.03, 0.03, 0.03), ks=(0.72, 0.72, 0.74),
         alpha_x=0.04, alpha_y=0.25),
    # The wall panel: polished steel, GGX alpha 0.06.
    metal_rough("polished steel", (0.9, 0.9, 0.92), metallic=1.0, roughness=0.25),
    metal_rough("oak", (0.45, 0.3, 0.17), roughness=0.7),
    metal_rough("dark bronze", (0.25, 0.18, 0.12), metallic=1.0, roughness=0.6),
    metal_rough("blue linen", (0.12, 0.2, 0.42)),
    metal_rough("terracotta", (0.6, 0.28, 0.14), roughness=0.8),
]

# ---- two rooms side by side along z; walls face inwards ----------------------------------
# front room z in [0, ZF], back room z in [ZB, -T]; the shared wall is T thick, its doorway spans
# x in [DX0, DX1] and y in [0, DH].

W, H = 2.5, 2.8
ZF, ZB, T = 4.5, -3.6, 0.15
DX0, DX1, DH = -1.3, -0.3, 2.1

CAMERA_EYE, CAMERA_TARGET = (2.1, 1.4, 4.3), (-1.0, 0.55, -0.5)
SPOT_POS, SPOT_AIM = (-0.3, 2.45, ZB + 0.2), (-0.6, 0.0, 2.0)
PANEL_LIGHT = (-0.8, 0.0, -1.3)  # centre of the ceiling panel, over the back room's floor


def wall_with_door(z, facing_front):
    """One face of the shared wall at depth z: three quads around the doorway."""
    parts = [((-W, 0, z), DX0 + W, H), ((DX1, 0, z), W - DX1, H), ((DX0, DH, z), DX1 - DX0, H - DH)]
    mesh = ([], [], [], [])
    for (x, y, zz), width, height in parts:
        if facing_front:
            append(mesh, quad((x, y, zz), (width, 0, 0), (0, height, 0)))
        else:
            append(mesh, quad((x + width, y, zz), (-width, 0, 0), (0, height, 0)))
    return mesh


def doorway_reveals():
    """The opening's three inner faces, facing into it."""
    return merge(quad((DX0, 0, 0), (0, 0, -T), (0, DH, 0)),      # left jamb, faces +x
                 quad((DX1, 0, -T), (0, 0, T), (0, DH, 0)),      # right jamb, faces -x
                 quad((DX0, DH, -T), (DX1 - DX0, 0, 0), (0, 0, T)))  # head, faces down


ROOM = [
    ("front floor", "polished stone", quad((-W, 0, ZF), (2 * W, 0, 0), (0, 0, -ZF))),
    ("back floor", "polished stone", quad((-W, 0, -T), (2 * W, 0, 0), (0, 0, ZB + T))),
    ("doorway floor", "polished stone", quad((DX0, 0, 0), (DX1 - DX0, 0, 0), (0, 0, -T))),
    ("ceiling", "white plaster", quad((-W, H, ZB), (2 * W, 0, 0), (0, 0, ZF - ZB))),
    ("front wall", "sage plaster", quad((W, 0, ZF), (-2 * W, 0, 0), (0, H, 0))),
    ("back wall", "warm plaster", quad((-W, 0, ZB), (2 * W, 0, 0), (0, H, 0))),
    ("left wall, front", "sage plaster", quad((-W, 0, ZF), (0, 0, -ZF), (0, H, 0))),
    ("right wall, front", "sage plaster", quad((W, 0, 0), (0, 0, ZF), (0, H, 0))),
    ("left wall, back", "warm plaster", quad((-W, 0, 0), (0, 0, ZB), (0, H, 0))),
    ("right wall, back", "warm plaster", quad((W, 0, ZB), (0, 0, -ZB), (0, H, 0))),
    ("shared wall, front", "white plaster", wall_with_door(0.0, True)),
    ("shared wall, back", "warm plaster", wall_with_door(-T, False)),
    ("doorway", "white plaster", doorway_reveals()),
    # 1 x 0.8 m, 1 cm under the ceiling, facing down.
    ("ceiling panel", "ceiling panel", quad((PANEL_LIGHT[0] - 0.5, H - 0.01, PANEL_LIGHT[2] - 0.4), (1.0, 0, 0),
                                            (0, 0, 0.8))),
    # Polished steel on the front room's left wall, beside the doorway: it shows the lit floor.
    ("steel panel", "polished steel", quad((-W + 0.02, 0.3, 1.8), (0, 0, -1.4), (0, 1.6, 0))),
    ("panel frame", "dark bronze", quad((-W + 0.01, 0.25, 1.85), (0, 0, -1.5), (0, 1.7, 0))),
]


def cabinet():
    """A low sideboard: body on four short legs."""
    body = moved(box((1.4, 0.6, 0.45)), (0, 0.42, 0))
    legs = [moved(cylinder(0.02, 0.02, 0.12, 8), (x, 0, z)) for x in (-0.65, 0.65) for z in (-0.18, 0.18)]
    return merge(body, *legs)


OBJECTS = [  # name, material, mesh, translation, rotation
    ("steel sideboard", "brushed steel", cabinet(), (1.15, 0.0, 0.3), None),
    ("chrome sphere", "chrome", sphere(0.3), (-0.2, 0.3, 2.4), None),
    ("pouf", "blue linen", box((0.55, 0.4, 0.55)), (1.75, 0.2, 1.5), yaw(20)),
    # The back room, seen through the door.
    ("table", "oak", merge(moved(box((1.2, 0.05, 0.7)), (0, 0.73, 0)),
                           *[moved(box((0.05, 0.7, 0.05)), (x, 0.35, z)) for x in (-0.55, 0.55) for z in (-0.3, 0.3)]),
     (-0.6, 0.0, -2.2), yaw(10)),
    ("pot", "terracotta", cylinder(0.18, 0.24, 0.5, 24), (-1.9, 0.0, -3.1), None),
]


def build():
    s = Scene(MATERIALS)
    for name, material, mesh in ROOM:
        s.mesh(name, material, mesh)
    for name, material, mesh, t, r in OBJECTS:
        s.mesh(name, material, mesh, translation=t, rotation=r)
    s.camera(CAMERA_EYE, CAMERA_TARGET, yfov=0.95)
    s.light(spot("spot", (1.0, 0.9, 0.75), 6000.0, inner=0.2, outer=0.3), SPOT_POS, SPOT_AIM)
    return s.document("glint doorway", "glint assets/scenes/make_doorway.py")


if __name__ == "__main__":
    write(build(), __file__, "doorway")
