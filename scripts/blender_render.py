"""Renders a glTF scene with Blender Cycles as glint renders it, for an independent comparison
(tests/bench/blender_twin.py, docs/benchmarks.md). Runs inside Blender:

    blender -b --factory-startup -P scripts/blender_render.py -- SCENE.gltf OUT.exr \\
        --size WxH --samples N --camera STATS.json [--env MAP.hdr] [--max-depth D] [--lambert] [--seed S]
        [--time-limit SECONDS]

SCENE is imported with Blender's own glTF importer. The camera is the one `glint render --stats`
recorded (position, forward, up, yfov_degrees; glTF's Y up becomes Blender's Z up as the
importer converts the scene). The environment map lights the scene with glint's orientation,
which is Blender's (the image centre is +X, glTF +Z a quarter turn on, the top row up). Cycles
is set to match glint's path tracer: up to D bounces of every kind (glint's --max-depth,
default 16), no clamping, no glossy filter, caustics on, a box pixel filter one pixel wide,
no denoising. OUT.exr is linear float RGB. --lambert replaces every material by a Diffuse BSDF
(Lambert) of its base colour: the control, where the two renderers should agree exactly.
--time-limit renders for that many seconds (Cycles' time limit, its scene set-up not counted)
rather than a number of samples. glint's own lobes (a material's extras "glint": the papers'
modified Phong, anisotropic Ward), which Blender's importer leaves as their glTF fallback, become
the nearest Cycles lobes: a Diffuse BSDF of kd plus a Glossy BSDF (Beckmann) of ks as wide (Phong's
exponent n as Beckmann's alpha sqrt(2 / (n + 2)), Ward's two alphas as their geometric mean): close,
not the same BRDF. An emitter that glTF does not call double-sided emits from its front only, as
in glint, and punctual lights have glint's units (a candela as a watt per steradian).
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
             "--camera STATS.json [--env MAP] [--max-depth D] [--lambert] [--seed S] [--time-limit SECONDS]")
    opts = {"scene": args[0], "out": args[1], "size": "320x240", "samples": 64, "camera": None, "env": None,
            "max_depth": 16, "lambert": False, "seed": 1, "time_limit": 0}
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


def glint_lobes():
    """Materials with glint's own lobes (extras "glint") as a Diffuse plus a Glossy BSDF; their count."""
    n = 0
    for mat in bpy.data.materials:
        model = mat.get("glint")
        if model is None or not mat.use_nodes:
            continue
        model = model.to_dict() if hasattr(model, "to_dict") else dict(model)
        if model.get("model") == "phong":
            alpha = math.sqrt(2.0 / (float(model["exponent"]) + 2.0))
        elif model.get("model") == "ward":
            alpha = math.sqrt(float(model["alpha_x"]) * float(model["alpha_y"]))
        else:
            continue
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL"), None)
        if output is None:
            continue
        diffuse = nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = list(model["kd"]) + [1.0]
        diffuse.inputs["Roughness"].default_value = 0.0
        glossy = nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "BECKMANN"
        glossy.inputs["Color"].default_value = list(model["ks"]) + [1.0]
        glossy.inputs["Roughness"].default_value = math.sqrt(alpha)  # Cycles squares it
        add = nodes.new("ShaderNodeAddShader")
        links.new(diffuse.outputs["BSDF"], add.inputs[0])
        links.new(glossy.outputs["BSDF"], add.inputs[1])
        links.new(add.outputs["Shader"], output.inputs["Surface"])
        n += 1
    return n


def one_sided_emission():
    """Emission from the front face only where glTF says the material is not double-sided, as
    glint emits (Cycles emits from both): the importer marks those with backface culling. The back
    face is black (an emitter's glTF base colour is black). Their count."""
    n = 0
    for mat in bpy.data.materials:
        if not mat.use_nodes or not mat.use_backface_culling:
            continue
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
        output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL"), None)
        if principled is None or output is None or not output.inputs["Surface"].is_linked:
            continue
        emission = principled.inputs["Emission"]
        if not emission.is_linked and max(emission.default_value[:3]) <= 0.0:
            continue
        surface = output.inputs["Surface"].links[0].from_socket
        back = nodes.new("ShaderNodeBsdfDiffuse")
        back.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        geometry = nodes.new("ShaderNodeNewGeometry")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
        links.new(surface, mix.inputs[1])
        links.new(back.outputs["BSDF"], mix.inputs[2])
        links.new(mix.outputs["Shader"], output.inputs["Surface"])
        n += 1
    return n


def configure(opts):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    w, h = (int(x) for x in opts["size"].split("x"))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = int(opts["samples"])
    if float(opts["time_limit"]) > 0:
        cy.time_limit = float(opts["time_limit"])
        cy.samples = 1 << 24  # the time limit stops it
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
    # Punctual lights in glint's units: glTF's candela as W/sr (scene.h), which is a Blender point or
    # spot light of 4 pi times as many watts; the importer's default (physical) mode divides by
    # 683 lm/W instead, its raw mode takes the number as watts. Lux stays W/m^2 (a sun's strength).
    raw = "convert_lighting_mode" in bpy.ops.import_scene.gltf.get_rna_type().properties
    result = bpy.ops.import_scene.gltf(filepath=opts["scene"], **({"convert_lighting_mode": "RAW"} if raw else {}))
    if "FINISHED" not in result:
        fail(opts["scene"] + ": Blender's glTF importer failed")
    if not raw and any(o.type == "LIGHT" for o in bpy.data.objects):
        fail("this Blender's glTF importer cannot import lights in raw units")
    for obj in bpy.data.objects:
        if obj.type == "LIGHT" and obj.data.type in ("POINT", "SPOT"):
            obj.data.energy *= 4.0 * math.pi
            obj.data.shadow_soft_size = 0.0  # a point, as glTF's and glint's (Blender's default is a ball)
    if opts["lambert"]:
        make_lambert()
    else:
        lobes = glint_lobes()
        if lobes:
            print("blender_render: %d materials with glint's own lobes, as Cycles' nearest" % lobes)
    one_sided = one_sided_emission()
    if one_sided:
        print("blender_render: %d one-sided emitters" % one_sided)
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
