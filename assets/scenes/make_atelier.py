#!/usr/bin/env python3
"""Writes atelier.gltf, the built-in scene `atelier`: a closed room lit only by a torchiere, a
floor lamp whose spot shines at the ceiling. What the camera sees is lit indirectly, by the
bright patch on the ceiling and by a polished brass reflector hung in the beam, which throws
the spot's light down onto a glossy wooden floor, a chrome sphere, a copper cube and a lacquered
cabinet: sharp glossy virtual lights and glossy-to-glossy highlights, the many-light methods'
home ground.

    python3 assets/scenes/make_atelier.py   # rewrites assets/scenes/atelier.gltf
"""
from gltfkit import (Scene, add, box, cylinder, merge, metal_rough, moved, normalize, phong, quad, rotation_between,
                     scale, sphere, spot, sub, write, yaw)

MATERIALS = [
    metal_rough("white plaster", (0.78, 0.77, 0.74)),
    metal_rough("ceiling plaster", (0.82, 0.82, 0.8)),
    metal_rough("teal accent wall", (0.08, 0.3, 0.33)),
    # Oiled oak planks in three tones: glossy Phong over a diffuse base.
    phong("oak", (0.45, 0.3, 0.17), kd=(0.4, 0.25, 0.12), ks=(0.3, 0.3, 0.3), exponent=100),
    phong("oak, dark", (0.38, 0.24, 0.13), kd=(0.32, 0.19, 0.09), ks=(0.3, 0.3, 0.3), exponent=100),
    phong("oak, light", (0.5, 0.35, 0.2), kd=(0.45, 0.3, 0.16), ks=(0.3, 0.3, 0.3), exponent=100),
    metal_rough("chrome", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.12),
    metal_rough("copper", (0.95, 0.64, 0.54), metallic=1.0, roughness=0.5),
    # The reflector: polished brass, GGX alpha 0.09.
    metal_rough("polished brass", (1.0, 0.82, 0.5), metallic=1.0, roughness=0.3),
    phong("red lacquer", (0.5, 0.06, 0.04), kd=(0.42, 0.04, 0.03), ks=(0.4, 0.4, 0.4), exponent=300),
    metal_rough("satin brass", (0.9, 0.75, 0.45), metallic=1.0, roughness=0.4),
    metal_rough("black metal", (0.05, 0.05, 0.05), metallic=1.0, roughness=0.6),
    metal_rough("linen", (0.75, 0.7, 0.6)),
    metal_rough("ochre canvas", (0.72, 0.46, 0.14)),
    metal_rough("wool", (0.55, 0.5, 0.45)),
]

# ---- the room: x in [-3, 3], y in [0, 3], z in [-2.25, 2.25]; walls face inwards -------------

W, H, D = 3.0, 3.0, 2.25
PLANK = 0.25  # plank width along z
TONES = ["oak", "oak, dark", "oak, light", "oak", "oak, light", "oak, dark"]

LAMP = (-2.4, 0.0, -1.7)  # the torchiere's foot, in the back-left corner
SHADE_Y, SHADE_H = 1.72, 0.16
SPOT_POS = add(LAMP, (0.0, SHADE_Y + SHADE_H + 0.01, 0.0))

CAMERA_EYE, CAMERA_TARGET = (2.65, 1.35, 1.75), (-1.3, 0.35, -1.6)
CAMERA2_EYE, CAMERA2_TARGET = (-2.6, 1.6, 1.85), (1.4, 0.6, -1.2)

# The reflector: three polished brass leaves hung under the ceiling in the beam, each turned to
# throw the spot's light somewhere else. The first throws it to where the camera sees the leaf in
# the glossy floor: a double reflection of the spot (camera - floor - leaf - spot), a highlight,
# whose lobe at the floor also takes in the other leaves, turned another way.
LEAF_SIZE = (0.3, 0.015, 0.75)
LEAF_Y = 2.6  # hung from the ceiling on rods
LEAF_XZ = [(-1.85, -1.2), (-2.17, -1.2), (-1.53, -1.2)]
SPHERE = (0.3, 0.35, -0.5)
CABINET = (0.6, 0.4, -D + 0.23)


def floor_mirror_point(p):
    """Where the camera sees p reflected in the floor."""
    m = (p[0], -p[1], p[2])
    t = CAMERA_EYE[1] / (CAMERA_EYE[1] - m[1])
    return add(CAMERA_EYE, scale(sub(m, CAMERA_EYE), t))


def leaves():
    centres = [(x, LEAF_Y, z) for x, z in LEAF_XZ]
    aims = [floor_mirror_point(centres[0]), add(SPHERE, (0, 0.2, 0)), add(CABINET, (0, 0.4, 0.3))]
    return list(zip(centres, aims))


def leaf_rotation(centre, aim):
    """A leaf's underside faces the half vector between the directions to the spot and to where
    its light should land, so the beam's centre is mirrored onto aim."""
    half = add(normalize(sub(SPOT_POS, centre)), normalize(sub(aim, centre)))
    return rotation_between((0, -1, 0), half)


def floor_planks():
    """Planks along x, PLANK wide, in a repeating run of tones; together they tile the floor."""
    planks = []
    n = round(2 * D / PLANK)
    for i in range(n):
        z = D - i * PLANK
        planks.append(("floor plank %d" % i, TONES[i % len(TONES)],
                       quad((-W, 0, z), (2 * W, 0, 0), (0, 0, -PLANK))))
    return planks


def torchiere():
    base = cylinder(0.16, 0.14, 0.03, 32)
    pole = moved(cylinder(0.014, 0.014, SHADE_Y - 0.03, 12, caps=False), (0, 0.03, 0))
    shade = moved(cylinder(0.05, 0.26, SHADE_H, 48, caps=False), (0, SHADE_Y, 0))
    return [("torchiere stand", "black metal", merge(base, pole), LAMP),
            ("torchiere shade", "satin brass", shade, LAMP)]


def sofa():
    """A sofa against the left wall, facing +X: seat, back and two arms, 2.1 m long."""
    return merge(moved(box((0.9, 0.42, 1.7)), (0.0, 0.21, 0.0)),
                 moved(box((0.22, 0.82, 2.1)), (-0.34, 0.41, 0.0)),
                 moved(box((0.9, 0.62, 0.2)), (0.0, 0.31, 0.95)),
                 moved(box((0.9, 0.62, 0.2)), (0.0, 0.31, -0.95)))


ROOM = floor_planks() + [
    ("ceiling", "ceiling plaster", quad((-W, H, -D), (2 * W, 0, 0), (0, 0, 2 * D))),
    ("back wall", "white plaster", quad((-W, 0, -D), (2 * W, 0, 0), (0, H, 0))),
    ("front wall", "white plaster", quad((W, 0, D), (-2 * W, 0, 0), (0, H, 0))),
    ("left wall", "teal accent wall", quad((-W, 0, D), (0, 0, -2 * D), (0, H, 0))),
    ("right wall", "white plaster", quad((W, 0, -D), (0, 0, 2 * D), (0, H, 0))),
]

OBJECTS = [  # name, material, mesh, translation, rotation
    ("chrome sphere", "chrome", sphere(0.35), SPHERE, None),
    ("copper cube", "copper", box((0.5, 0.5, 0.5)), (1.35, 0.25, -0.95), yaw(32)),
    ("lacquer cabinet", "red lacquer", box((1.5, 0.8, 0.45)), CABINET, None),
    ("linen ottoman", "linen", box((0.7, 0.42, 0.7)), (-1.1, 0.21, 0.7), yaw(-15)),
    ("sofa", "wool", sofa(), (-W + 0.45, 0.0, 0.55), None),
    ("canvas", "ochre canvas", box((1.3, 0.85, 0.03)), (CABINET[0], 1.7, -D + 0.016), None),
]


def build():
    s = Scene(MATERIALS)
    s.add_meshes(ROOM)
    for name, material, mesh, t in torchiere():
        s.mesh(name, material, mesh, translation=t)
    for i, (centre, aim) in enumerate(leaves()):
        s.mesh("brass reflector leaf %d" % i, "polished brass", box(LEAF_SIZE), translation=centre,
               rotation=leaf_rotation(centre, aim))
        s.mesh("rod %d" % i, "black metal", cylinder(0.006, 0.006, H - LEAF_Y, 8, caps=False), translation=centre)
    s.add_meshes(OBJECTS)
    s.camera(CAMERA_EYE, CAMERA_TARGET, yfov=1.15)
    # A second view, from the front-left corner towards the sideboard: the viewer's camera jumps.
    s.camera(CAMERA2_EYE, CAMERA2_TARGET, yfov=1.0, name="camera 1")
    # A wide beam straight up at the ceiling: 55 degrees to the edge of the cone.
    s.light(spot("torchiere", (1.0, 0.86, 0.68), 8000.0, inner=0.75, outer=0.96), SPOT_POS, add(SPOT_POS, (0, 1, 0)))
    return s.document("glint atelier", "glint assets/scenes/make_atelier.py")


if __name__ == "__main__":
    write(build(), __file__, "atelier")
