"""Renders a glTF scene with Blender Cycles as glint renders it, for an independent comparison
(tests/bench/blender_twin.py, docs/benchmarks.md). Runs inside Blender:

    blender -b --factory-startup -P scripts/blender_render.py -- SCENE.gltf OUT.exr \\
        --size WxH --samples N --camera STATS.json [--env MAP.hdr] [--max-depth D] [--lambert] [--seed S]

SCENE is imported with Blender's own glTF importer. The camera is the one `glint render --stats`
recorded (position, forward, up, yfov_degrees; glTF's Y up becomes Blender's Z up as the
importer converts the scene). The environment map lights the scene with glint's orientation,
which is Blender's (the image centre is +X, glTF +Z a quarter turn on, the top row up). Cycles
is set to match glint's path tracer: up to D bounces of every kind (glint's --max-depth,
default 16), no clamping, no glossy filter, caustics on, a box pixel filter one pixel wide,
no denoising. OUT.exr is linear float RGB. --lambert replaces every material by a Diffuse BSDF
(Lambert) of its base colour: the control, where the two renderers should agree exactly.
"""
import json
import math
import sys

import bpy
from mathutils import Matrix, Vector


def fail(msg):
    print("blender_render: error: " + msg, file=sys.stderr)
    sys.exit(1)


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2:
        fail("usage: blender -b -P blender_render.py -- SCENE.gltf OUT.exr --size WxH --samples N "
             "--camera STATS.json [--env MAP] [--max-depth D] [--lambert] [--seed S]")
    opts = {"scene": args[0], "out": args[1], "size": "320x240", "samples": 64, "camera": None, "env": None,
            "max_depth": 16, "lambert": False, "seed": 1}
    i = 2
    while i < len(args):
        a = args[i]
        if a == "--lambert":
            opts["lambert"] = True
            i += 1
            continue
        if i + 1 >= len(args):
            fail(a + " needs a value")
        key = a.lstrip("-").replace("-", "_")
        if key not in opts:
            fail("unknown option " + a)
        opts[key] = args[i + 1]
        i += 2
    if opts["camera"] is None:
        fail("--camera STATS.json is required (glint render --stats writes it)")
    return opts


def gltf_to_blender(v):
    """glTF's Y-up (x, y, z) as the importer places it in Blender's Z-up frame: (x, -z, y)."""
    return Vector((v[0], -v[2], v[1]))


def add_camera(stats_path, aspect):
    with open(stats_path) as f:
        cam = json.load(f)["camera"]
    pos, fwd, up = (gltf_to_blender(cam[k]) for k in ("position", "forward", "up"))
    fwd.normalize()
    right = fwd.cross(up).normalized()
    up = right.cross(fwd).normalized()
    data = bpy.data.cameras.new("glint")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(cam["yfov_degrees"])
    # The shared scenes span millimetres to metres: clip by the distance, not Blender's 0.1 m.
    dist = max(pos.length, 1e-6)
    data.clip_start = dist * 1e-5
    data.clip_end = dist * 1e5
    obj = bpy.data.objects.new("glint", data)
    # A camera looks down its -Z with +Y up.
    rot = Matrix((right, up, -fwd)).transposed()
    obj.matrix_world = Matrix.Translation(pos) @ rot.to_4x4()
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj


def set_world(env_path):
    world = bpy.data.worlds.new("glint")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    if env_path:
        tex = nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(env_path)
        tex.image.colorspace_settings.name = "Linear"
        tex.interpolation = "Linear"
        links.new(tex.outputs["Color"], background.inputs["Color"])
    else:
        background.inputs["Color"].default_value = (0, 0, 0, 1)
    background.inputs["Strength"].default_value = 1.0
    bpy.context.scene.world = world


def make_lambert():
    """Every material a Diffuse BSDF (roughness 0: Lambert) of its Principled BSDF's base colour."""
    for mat in bpy.data.materials:
        if not mat.use_nodes:
            continue
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
        output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL"), None)
        if principled is None or output is None:
            continue
        diffuse = nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Roughness"].default_value = 0.0
        base = principled.inputs["Base Color"]
        if base.is_linked:
            links.new(base.links[0].from_socket, diffuse.inputs["Color"])
        else:
            diffuse.inputs["Color"].default_value = base.default_value
        links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])


def configure(opts):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    w, h = (int(x) for x in opts["size"].split("x"))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = int(opts["samples"])
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = int(opts["seed"])
    d = int(opts["max_depth"])
    cy.max_bounces = d
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = cy.volume_bounces = d
    cy.transparent_max_bounces = d
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGB"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.filepath = opts["out"]
    scene.render.use_file_extension = False


def main():
    opts = parse_args(sys.argv)
    # Debian 12's Blender 3.4 importer still uses numpy.bool, which Debian 12's numpy 1.24 removed:
    # give the alias back before importing.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
    bpy.ops.wm.read_factory_settings(use_empty=True)
    result = bpy.ops.import_scene.gltf(filepath=opts["scene"])
    if "FINISHED" not in result:
        fail(opts["scene"] + ": Blender's glTF importer failed")
    if opts["lambert"]:
        make_lambert()
    w, h = (int(x) for x in opts["size"].split("x"))
    add_camera(opts["camera"], w / h)
    set_world(opts["env"])
    configure(opts)
    principled = [n for m in bpy.data.materials if m.use_nodes for n in m.node_tree.nodes
                  if n.type == "BSDF_PRINCIPLED"]
    if principled:
        print("blender_render: %d Principled BSDFs, distribution %s, subsurface method %s" %
              (len(principled), principled[0].distribution, principled[0].subsurface_method))
    bpy.ops.render.render(write_still=True)


main()
