#!/usr/bin/env python3
"""Writes doorway.gltf, the built-in scene `doorway`: two rooms joined by an open doorway. Both
lights are in the back room, a ceiling panel and a spot shining through the doorway onto a
polished steel panel in the front room; the camera stands in the front room, which is lit only
by what comes through the door. The polished stone floor shows the spot twice reflected, by the
panel and by itself; a chrome sphere and a brushed steel sideboard show the rest.

    python3 assets/scenes/make_doorway.py   # rewrites assets/scenes/doorway.gltf
"""
from gltfkit import (Scene, add, append, box, cylinder, emissive, merge, metal_rough, moved, phong, quad, scale,
                     sphere, spot, sub, ward, write, yaw)

MATERIALS = [
    metal_rough("white plaster", (0.78, 0.77, 0.74)),
    metal_rough("warm plaster", (0.78, 0.58, 0.36)),
    metal_rough("sage plaster", (0.55, 0.6, 0.5)),
    # Polished limestone tiles in two tones: a sharp Phong lobe over a pale diffuse base.
    phong("polished stone", (0.6, 0.57, 0.52), kd=(0.5, 0.47, 0.42), ks=(0.35, 0.35, 0.35), exponent=300),
    phong("polished stone, grey", (0.5, 0.5, 0.48), kd=(0.4, 0.4, 0.38), ks=(0.35, 0.35, 0.35), exponent=300),
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
    metal_rough("white trim", (0.85, 0.84, 0.8), roughness=0.6),
    metal_rough("slate print", (0.2, 0.27, 0.36)),
]

# ---- two rooms side by side along z; walls face inwards ----------------------------------
# front room z in [0, ZF], back room z in [ZB, -T]; the shared wall is T thick, its doorway spans
# x in [DX0, DX1] and y in [0, DH].

W, H = 2.5, 2.8
ZF, ZB, T = 4.5, -3.6, 0.15
DX0, DX1, DH = -1.3, -0.3, 2.1
TILE = 0.625

CAMERA_EYE, CAMERA_TARGET = (1.6, 1.5, 4.3), (-1.0, 0.7, -0.3)
CAMERA2_EYE, CAMERA2_TARGET = (-1.6, 1.6, 4.3), (0.6, 0.9, -1.5)
PANEL_LIGHT = (-0.8, 0.0, -1.3)  # centre of the ceiling panel, over the back room's floor
SPOT_POS = (1.45, 2.15, -1.55)   # in the back room, right of the door
PANEL_X = -W + 0.02              # the steel panel's plane, on the left wall


def double_mirror():
    """Where the camera sees the spot reflected by the floor and then by the steel panel: the
    floor point F and the panel point P of the path camera - F - P - spot. The spot is aimed at
    P, so that path is the beam's centre: a glossy-to-glossy highlight in the floor."""
    image = (2 * PANEL_X - SPOT_POS[0], -SPOT_POS[1], SPOT_POS[2])  # mirrored by the panel, then the floor
    d = sub(image, CAMERA_EYE)
    f = add(CAMERA_EYE, scale(d, CAMERA_EYE[1] / -d[1]))
    d = (d[0], -d[1], d[2])
    p = add(f, scale(d, (PANEL_X - f[0]) / d[0]))
    # The beam from the spot to P must pass through the doorway.
    for z in (0.0, -T):
        q = add(p, scale(sub(SPOT_POS, p), (z - p[2]) / (SPOT_POS[2] - p[2])))
        assert DX0 < q[0] < DX1 and q[1] < DH, q
    return f, p


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


def tiles(z0, z1):
    """Square tiles over x in [-W, W], z in [z0, z1] in a checker of two tones, as two meshes."""
    tone = (([], [], [], []), ([], [], [], []))
    nx = round(2 * W / TILE)
    z = z0
    for j in range(round((z1 - z0) / TILE + 0.49)):
        depth = min(TILE, z1 - z)
        for i in range(nx):
            append(tone[(i + j) % 2], quad((-W + i * TILE, 0, z + depth), (TILE, 0, 0), (0, 0, -depth)))
        z += depth
    return tone


def trim():
    """An architrave around the doorway on the front room's side: two posts and a lintel."""
    w, d = 0.08, 0.025
    return merge(moved(box((w, DH + w, d)), (DX0 - w / 2, (DH + w) / 2, d / 2)),
                 moved(box((w, DH + w, d)), (DX1 + w / 2, (DH + w) / 2, d / 2)),
                 moved(box((DX1 - DX0, w, d)), ((DX0 + DX1) / 2, DH + w / 2, d / 2)))


FRONT_TILES, BACK_TILES = tiles(0.0, ZF), tiles(ZB, -T)

ROOM = [
    ("front floor", "polished stone", FRONT_TILES[0]),
    ("front floor, grey", "polished stone, grey", FRONT_TILES[1]),
    ("back floor", "polished stone", BACK_TILES[0]),
    ("back floor, grey", "polished stone, grey", BACK_TILES[1]),
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
    # A tall polished steel panel on the front room's left wall, in the spot's beam.
    ("steel panel", "polished steel", quad((PANEL_X, 0.1, 2.3), (0, 0, -1.7), (0, 1.8, 0))),
    ("panel frame", "dark bronze", quad((PANEL_X - 0.01, 0.05, 2.35), (0, 0, -1.8), (0, 1.9, 0))),
]


def cabinet():
    """A low sideboard: body on four short legs."""
    body = moved(box((1.4, 0.6, 0.45)), (0, 0.42, 0))
    legs = [moved(cylinder(0.02, 0.02, 0.12, 8), (x, 0, z)) for x in (-0.65, 0.65) for z in (-0.18, 0.18)]
    return merge(body, *legs)


OBJECTS = [  # name, material, mesh, translation, rotation
    ("steel sideboard", "brushed steel", cabinet(), (1.15, 0.0, 0.3), None),
    ("chrome sphere", "chrome", sphere(0.3), (-0.2, 0.3, 2.4), None),
    ("pouf", "blue linen", cylinder(0.3, 0.28, 0.42, 32), (1.7, 0.0, 1.6), None),
    ("door trim", "white trim", trim(), None, None),
    ("print", "slate print", box((0.6, 0.8, 0.02)), (-1.95, 1.45, 0.011), None),
    # The back room's far left corner, what the camera sees of it through the door.
    ("table", "oak", merge(moved(box((1.2, 0.05, 0.7)), (0, 0.73, 0)),
                           *[moved(box((0.05, 0.7, 0.05)), (x, 0.35, z)) for x in (-0.55, 0.55) for z in (-0.3, 0.3)]),
     (-1.75, 0.0, -2.5), yaw(80)),
    ("pot", "terracotta", cylinder(0.18, 0.24, 0.5, 24), (-2.15, 0.0, -3.25), None),
]


def build():
    s = Scene(MATERIALS)
    s.add_meshes(ROOM)
    s.add_meshes(OBJECTS)
    s.camera(CAMERA_EYE, CAMERA_TARGET, yfov=0.95)
    # A second view, from the front room's left side through the door: the viewer's camera jumps.
    s.camera(CAMERA2_EYE, CAMERA2_TARGET, yfov=0.95, name="camera 1")
    s.light(spot("spot", (1.0, 0.9, 0.75), 3000.0, inner=0.2, outer=0.3), SPOT_POS, double_mirror()[1])
    return s.document("glint doorway", "glint assets/scenes/make_doorway.py")


if __name__ == "__main__":
    write(build(), __file__, "doorway")
