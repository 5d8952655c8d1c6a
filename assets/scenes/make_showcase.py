#!/usr/bin/env python3
"""Writes showcase.gltf, the built-in scene `showcase`: a closed room in miniature of the papers'
kitchen and tableau, where glossy and anisotropic metals reflect each other. It was glint's
default scene; the file must stay byte for byte what it was (references made on it record its
hash), so its generator string and scene name keep their old spelling.

    python3 assets/scenes/make_showcase.py   # rewrites assets/scenes/showcase.gltf
"""
from gltfkit import Scene, anisotropy, box, emissive, metal_rough, phong, quad, sphere, spot, write, ward, yaw

MATERIALS = [
    metal_rough("white plaster", (0.75, 0.75, 0.72)),
    metal_rough("red plaster", (0.63, 0.07, 0.05)),
    metal_rough("green plaster", (0.10, 0.45, 0.12)),
    # A varnished floor: the papers' glossy Phong lobe over a diffuse base.
    phong("varnished floor", (0.4, 0.3, 0.2), kd=(0.32, 0.22, 0.13), ks=(0.25, 0.25, 0.25), exponent=120),
    emissive("ceiling light", (1.0, 0.93, 0.82), 12.0),
    metal_rough("chrome", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.15),
    metal_rough("gold", (1.0, 0.78, 0.34), metallic=1.0, roughness=0.22),
    # Brushed aluminium (anisotropic Ward), as on the VSL paper's kitchen appliances.
    ward("brushed aluminium", (0.8, 0.8, 0.82), kd=(0.02, 0.02, 0.02), ks=(0.78, 0.78, 0.8),
         alpha_x=0.05, alpha_y=0.3),
    # Brushed steel through the glTF extension: anisotropic GGX along the surface tangent.
    metal_rough("brushed steel", (0.86, 0.87, 0.9), metallic=1.0, roughness=0.35,
                extensions=anisotropy(0.85, 1.5708)),
    phong("blue lacquer", (0.05, 0.1, 0.3), kd=(0.04, 0.08, 0.3), ks=(0.5, 0.5, 0.5), exponent=400),
    metal_rough("white card", (0.8, 0.8, 0.78)),
    metal_rough("terracotta", (0.6, 0.28, 0.14), roughness=0.8),
]

# ---- the room: x in [-2, 2], y in [0, 2.6], z in [-1.5, 1.5]; walls face inwards -------------

W, H, D = 2.0, 2.6, 1.5
ROOM = [
    ("floor", "varnished floor", quad((-W, 0, D), (2 * W, 0, 0), (0, 0, -2 * D))),
    ("ceiling", "white plaster", quad((-W, H, -D), (2 * W, 0, 0), (0, 0, 2 * D))),
    ("back wall", "white plaster", quad((-W, 0, -D), (2 * W, 0, 0), (0, H, 0))),
    ("front wall", "white plaster", quad((W, 0, D), (-2 * W, 0, 0), (0, H, 0))),
    ("left wall", "red plaster", quad((-W, 0, D), (0, 0, -2 * D), (0, H, 0))),
    ("right wall", "green plaster", quad((W, 0, -D), (0, 0, 2 * D), (0, H, 0))),
    # The light hangs 1 cm under the ceiling, facing down (single-sided, so it lights the room only).
    ("ceiling light", "ceiling light", quad((-0.5, H - 0.01, -0.3), (1.0, 0, 0), (0, 0, 0.6))),
    # Brushed aluminium panel on the back wall, just off it; stretched highlights of everything.
    ("brushed panel", "brushed aluminium", quad((-1.5, 0.25, -D + 0.01), (2.2, 0, 0), (0, 1.6, 0))),
    # Brushed steel panel high on the right wall, above the lacquer box.
    ("steel panel", "brushed steel", quad((W - 0.01, 0.85, -1.45), (0, 0, 1.2), (0, 1.35, 0))),
]

OBJECTS = [  # name, material, mesh, translation, rotation
    ("chrome sphere", "chrome", sphere(0.4), (-0.75, 0.4, -0.6), None),
    ("gold sphere", "gold", sphere(0.3), (0.45, 0.3, -0.15), None),
    ("lacquer box", "blue lacquer", box((0.5, 0.8, 0.5)), (1.25, 0.4, -0.85), yaw(25)),
    ("card box", "white card", box((0.45, 0.45, 0.45)), (-1.45, 0.225, 0.2), yaw(-20)),
    ("terracotta block", "terracotta", box((0.3, 0.2, 0.5)), (-0.05, 0.1, 0.45), yaw(40)),
]

CAMERA_EYE, CAMERA_TARGET = (0.35, 1.4, 1.45), (-0.1, 0.5, -0.8)
SPOT_POS, SPOT_TARGET = (-1.7, 2.4, 1.2), (0.45, 0.3, -0.15)


def build():
    s = Scene(MATERIALS)
    s.add_meshes(ROOM)
    s.add_meshes(OBJECTS)
    s.camera(CAMERA_EYE, CAMERA_TARGET)
    s.light(spot("spot", (1.0, 0.95, 0.88), 15.0, inner=0.22, outer=0.32), SPOT_POS, SPOT_TARGET)
    return s.document("glint default room", "glint assets/default/make_default_scene.py")


if __name__ == "__main__":
    write(build(), __file__, "showcase")
