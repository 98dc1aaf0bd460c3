// The Python run inside Blender by the `blender` ground-truth provider (DESIGN §6.1). It reads every
// number from PARAMS, which the provider writes above this text; see docs/truth_blender.md.
#include "validation/providers/blender_script.hpp"

namespace sb::validation {

std::string_view blender_script_body() {
  static constexpr std::string_view kBody = R"PY(
import os

import bpy


def fail(message):
    raise RuntimeError("stereobench: " + message)


def gltf_to_blender(v):
    # glTF is +Y up, Blender +Z up: the importer maps (x, y, z) to (x, -z, y).
    return (v[0], -v[2], v[1])


def matrix_from_columns(x, y, z, t):
    from mathutils import Matrix
    return Matrix(((x[0], y[0], z[0], t[0]),
                   (x[1], y[1], z[1], t[1]),
                   (x[2], y[2], z[2], t[2]),
                   (0.0, 0.0, 0.0, 1.0)))


def import_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    # Record the glTF material index of every material the importer creates, so that materials
    # are matched to the in-memory scene by index, never by (possibly duplicated) name.
    from io_scene_gltf2.blender.imp import gltf2_blender_material as material_module
    importer = material_module.BlenderMaterial
    if not hasattr(importer, "create"):
        fail("the glTF importer of this Blender has no BlenderMaterial.create; "
             "this script supports Blender 3.4")
    original_create = importer.create

    def create(gltf, material_idx, vertex_color):
        original_create(gltf, material_idx, vertex_color)
        name = gltf.data.materials[material_idx].blender_material[vertex_color]
        bpy.data.materials[name]["stereobench_material"] = int(material_idx)

    importer.create = staticmethod(create)
    # Record the glTF node of every mesh object, so that a node a path's frame moves is found by
    # index; and import no animation: its actions would pose the nodes at the current frame's keys,
    # where the file places them at rest (as the in-memory scene has them before a path moves them).
    from io_scene_gltf2.blender.imp import gltf2_blender_node as node_module
    from io_scene_gltf2.blender.imp import gltf2_blender_scene as scene_module
    node_importer = node_module.BlenderNode
    scene_importer = scene_module.BlenderScene
    for cls, method in ((node_importer, "create_object"), (scene_importer, "create_animations")):
        if not hasattr(cls, method):
            fail("the glTF importer of this Blender has no %s.%s; this script supports Blender 3.4"
                 % (cls.__name__, method))
    original_object = node_importer.create_object
    original_animations = scene_importer.create_animations

    def create_object(gltf, vnode_id):
        obj = original_object(gltf, vnode_id)
        mesh_node = gltf.vnodes[vnode_id].mesh_node_idx
        if mesh_node is not None:
            obj["stereobench_node"] = int(mesh_node)
        return obj

    node_importer.create_object = staticmethod(create_object)
    scene_importer.create_animations = staticmethod(lambda gltf: None)
    # The importer sets glTF vertex normals as custom normals only with import_shading="NORMALS",
    # whose code uses numpy.bool, an alias that numpy 1.24 removed (Debian's Blender 3.4 runs on
    # the system numpy): restore the alias, which is the builtin bool.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
    try:
        result = bpy.ops.import_scene.gltf(filepath=PARAMS["scene_file"], import_shading="NORMALS",
                                           merge_vertices=False, import_pack_images=False)
    finally:
        importer.create = staticmethod(original_create)
        node_importer.create_object = staticmethod(original_object)
        scene_importer.create_animations = staticmethod(original_animations)
    if "FINISHED" not in result:
        fail("the glTF importer did not finish on " + PARAMS["scene_file"])
    bpy.context.view_layer.update()
    # A mesh whose node hangs below a light's or the camera's keeps its place when they go.
    removed = {obj for obj in bpy.data.objects if obj.type in {"LIGHT", "CAMERA"}}
    place_objects({obj: obj.matrix_world.copy() for obj in bpy.data.objects
                   if obj.type == "MESH" and has_ancestor_in(obj, removed)})
    for obj in removed:
        bpy.data.objects.remove(obj, do_unlink=True)
    # As the in-memory scene renders them: morph targets at their base shape (no shape key weighs
    # in). Skinned meshes keep their armature, posed by the joints' node transforms as the loader
    # skins them.
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        if obj.data.shape_keys is not None:
            for block in obj.data.shape_keys.key_blocks:
                block.value = 0.0
    bpy.context.view_layer.update()


def has_ancestor_in(obj, objects):
    parent = obj.parent
    while parent is not None:
        if parent in objects:
            return True
        parent = parent.parent
    return False


def place_objects(targets):
    # Unparents each object and gives it its world matrix: once none of them has a parent, setting
    # one does not move another. A matrix with shear has no location, rotation and scale, which is
    # all an object without a parent holds: such a target fails, naming the object.
    for obj, matrix in targets.items():
        obj.parent = None
        obj.matrix_world = matrix
    bpy.context.view_layer.update()
    for obj, matrix in targets.items():
        got = obj.matrix_world
        scale = max(1.0, max(abs(matrix[r][c]) for r in range(4) for c in range(4)))
        if max(abs(got[r][c] - matrix[r][c]) for r in range(4) for c in range(4)) > 1e-5 * scale:
            fail("object '%s' cannot be placed as the scene has it: its world transform has shear, which an "
                 "object without a parent cannot hold" % obj.name)


def gltf_transform_in_blender(v):
    # A glTF-space affine transform, 16 numbers column by column, in Blender's axes: conjugated by
    # the map of gltf_to_blender, as the importer turns the nodes' transforms.
    from mathutils import Matrix
    m = Matrix([[v[c * 4 + r] for c in range(4)] for r in range(4)])
    axes = Matrix(((1.0, 0.0, 0.0, 0.0), (0.0, 0.0, -1.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    return axes @ m @ axes.transposed()


def objects_by_node():
    # The mesh object the importer made for each glTF node (create_object recorded it).
    return {int(obj["stereobench_node"]): obj for obj in bpy.data.objects if "stereobench_node" in obj}


def place_moved_nodes():
    # The mesh objects of the nodes a path's frame has moved, and every mesh object below them, are
    # placed where the in-memory scene has them: a moved node at its transform from the file's
    # placement (glTF world space) times its place at rest, the others at rest.
    moved = {m["node"]: gltf_transform_in_blender(m["matrix"]) for m in PARAMS["moved_nodes"]}
    if not moved:
        return
    bpy.context.view_layer.update()  # world matrices as the import left them
    by_node = objects_by_node()
    missing = sorted(set(moved) - set(by_node))
    if missing:
        fail("the importer made no object for the moved glTF node(s) " + ", ".join(map(str, missing)))
    moving = {by_node[n] for n in moved}
    targets = {}
    for obj in bpy.data.objects:
        if obj.type == "MESH" and (obj in moving or has_ancestor_in(obj, moving)):
            rest = obj.matrix_world.copy()
            node = obj.get("stereobench_node")
            if obj in moving:
                rest = moved[int(node)] @ rest
            targets[obj] = rest
    place_objects(targets)


def place_instances():
    # EXT_mesh_gpu_instancing, which the importer does not read: the object of each instanced node
    # stays for what hangs below it but renders nothing, and a copy sharing its mesh stands at each
    # instance, its world matrix the node's (as it now stands, moved or not) times the instance's.
    if not PARAMS["instances"]:
        return
    bpy.context.view_layer.update()
    by_node = objects_by_node()
    targets = {}
    for entry in PARAMS["instances"]:
        node = entry["node"]
        if node not in by_node:
            fail("the importer made no object for the instanced glTF node %d" % node)
        original = by_node[node]
        for v in entry["matrices"]:
            copy = original.copy()
            del copy["stereobench_node"]
            for collection in original.users_collection:
                collection.objects.link(copy)
            targets[copy] = original.matrix_world @ gltf_transform_in_blender(v)
        original.hide_render = True
    place_objects(targets)


def math_node(nodes, operation, vector=False):
    # A Math (or Vector Math) node doing `operation`.
    node = nodes.new("ShaderNodeVectorMath" if vector else "ShaderNodeMath")
    node.operation = operation
    return node


def uv_map_name(texcoord):
    # The importer's names of the TEXCOORD_n sets.
    return "UVMap" if texcoord == 0 else "UVMap.%03d" % texcoord


def transformed_uv(tree, nodes, uv_socket, t):
    # The texture's KHR_texture_transform t (glTF texture space, v down: u' = t0 u + t1 v + t2,
    # v' = t3 u + t4 v + t5) in Blender's, where the importer's UVs are (u, 1 - v):
    # x' = t0 x - t1 y + t1 + t2, y' = -t3 x + t4 y + 1 - t4 - t5.
    split = nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(uv_socket, split.inputs["Vector"])
    along_x = math_node(nodes, "SCALE", vector=True)
    along_x.inputs[0].default_value = (t[0], -t[3], 0.0)
    tree.links.new(split.outputs["X"], along_x.inputs["Scale"])
    along_y = math_node(nodes, "SCALE", vector=True)
    along_y.inputs[0].default_value = (-t[1], t[4], 0.0)
    tree.links.new(split.outputs["Y"], along_y.inputs["Scale"])
    both = math_node(nodes, "ADD", vector=True)
    tree.links.new(along_x.outputs["Vector"], both.inputs[0])
    tree.links.new(along_y.outputs["Vector"], both.inputs[1])
    moved = math_node(nodes, "ADD", vector=True)
    tree.links.new(both.outputs["Vector"], moved.inputs[0])
    moved.inputs[1].default_value = (t[1] + t[2], 1.0 - t[4] - t[5], 0.0)
    return moved.outputs["Vector"]


def make_material(name, spec, textures, switches):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.cycles.sample_as_light = False  # ambient emission must light nothing
    tree = mat.node_tree
    nodes = tree.nodes
    while nodes:
        nodes.remove(nodes[0])
    out = nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    # The shading normal turned to the viewer (DESIGN §3): N * (N . incoming < 0 ? -1 : 1).
    geometry = nodes.new("ShaderNodeNewGeometry")
    facing = math_node(nodes, "DOT_PRODUCT", vector=True)
    tree.links.new(geometry.outputs["Normal"], facing.inputs[0])
    tree.links.new(geometry.outputs["Incoming"], facing.inputs[1])
    away = math_node(nodes, "LESS_THAN")
    tree.links.new(facing.outputs["Value"], away.inputs[0])
    away.inputs[1].default_value = 0.0
    sign = math_node(nodes, "MULTIPLY_ADD")
    tree.links.new(away.outputs["Value"], sign.inputs[0])
    sign.inputs[1].default_value = -2.0
    sign.inputs[2].default_value = 1.0
    turned = math_node(nodes, "SCALE", vector=True)
    tree.links.new(geometry.outputs["Normal"], turned.inputs[0])
    tree.links.new(sign.outputs["Value"], turned.inputs["Scale"])
    tree.links.new(turned.outputs["Vector"], diffuse.inputs["Normal"])
    factor = spec["base_color"]
    rgba = (factor[0], factor[1], factor[2], 1.0)
    colour_socket = None
    uv = None
    if spec["texture"] >= 0:
        uv_node = nodes.new("ShaderNodeUVMap")
        uv_node.uv_map = uv_map_name(spec["texcoord"])
        uv = uv_node.outputs["UV"]
        if spec.get("uv_transform") is not None:
            uv = transformed_uv(tree, nodes, uv, spec["uv_transform"])
        tex = textures[spec["texture"]]
        image_node = nodes.new("ShaderNodeTexImage")
        image_node.image = tex["image"]
        image_node.interpolation = "Linear"
        image_node.extension = tex["extension"]
        tree.links.new(uv, image_node.inputs["Vector"])
        multiply = math_node(nodes, "MULTIPLY", vector=True)
        tree.links.new(image_node.outputs["Color"], multiply.inputs[0])
        multiply.inputs[1].default_value = (factor[0], factor[1], factor[2])
        colour_socket = multiply.outputs["Vector"]
        tree.links.new(colour_socket, diffuse.inputs["Color"])
    else:
        diffuse.inputs["Color"].default_value = rgba
    # The ambient term: an emission of the albedo times `ambient`, rendered in a pass of its own
    # in which the material has no BSDF, so that nothing is lit by it (an emissive mesh would
    # otherwise join Cycles' light distribution).
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = PARAMS["ambient"]
    if colour_socket is not None:
        tree.links.new(colour_socket, emission.inputs["Color"])
    else:
        emission.inputs["Color"].default_value = rgba
    surface = out.inputs["Surface"]
    if spec["cutout"] is not None:
        # A cut-out: a Transparent BSDF where alpha = factor alpha x texture alpha (bilinear, as
        # SceneGeometry::opaque_at reads it) is below the cutoff, the material where it is not.
        alpha = math_node(nodes, "MULTIPLY")
        alpha.inputs[0].default_value = spec["cutout"]["factor_alpha"]
        alpha.inputs[1].default_value = 1.0
        if spec["texture"] >= 0 and textures[spec["texture"]]["alpha"] is not None:
            alpha_node = nodes.new("ShaderNodeTexImage")
            alpha_node.image = textures[spec["texture"]]["alpha"]
            alpha_node.interpolation = "Linear"
            alpha_node.extension = textures[spec["texture"]]["extension"]
            tree.links.new(uv, alpha_node.inputs["Vector"])
            channels = nodes.new("ShaderNodeSeparateColor")
            tree.links.new(alpha_node.outputs["Color"], channels.inputs["Color"])
            tree.links.new(channels.outputs[0], alpha.inputs[1])
        below = math_node(nodes, "LESS_THAN")
        below.use_clamp = False
        tree.links.new(alpha.outputs["Value"], below.inputs[0])
        below.inputs[1].default_value = spec["cutout"]["cutoff"]
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        transparent.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        mix = nodes.new("ShaderNodeMixShader")
        # Fac 1 (below the cutoff) takes the second shader: the transparent one.
        tree.links.new(below.outputs["Value"], mix.inputs["Fac"])
        tree.links.new(transparent.outputs["BSDF"], mix.inputs[2])
        tree.links.new(mix.outputs["Shader"], out.inputs["Surface"])
        surface = mix.inputs[1]
    switches.append((tree, surface, diffuse.outputs["BSDF"], emission.outputs["Emission"]))
    return mat


def setup_materials():
    textures = []
    for t in PARAMS["textures"]:
        if t is None:  # not used by any material
            textures.append(None)
            continue
        image = bpy.data.images.load(t["file"], check_existing=False)
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "STRAIGHT"
        alpha = None
        if "alpha_file" in t:
            alpha = bpy.data.images.load(t["alpha_file"], check_existing=False)
            alpha.colorspace_settings.name = "Non-Color"
        textures.append({"image": image, "alpha": alpha, "extension": t["extension"]})
    switches = []
    ours = [make_material("stereobench_%d" % i, m, textures, switches)
            for i, m in enumerate(PARAMS["materials"])]
    default = make_material("stereobench_default", PARAMS["default_material"], textures, switches)
    plain = {}
    unmatched = set()
    done = set()
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        # Shadow rays start at the surface as ours do (no terminator offsets).
        obj.cycles.shadow_terminator_offset = 0.0
        obj.cycles.shadow_terminator_geometry_offset = 0.0
        mesh = obj.data
        if mesh.as_pointer() in done:  # a mesh instanced by several nodes: its slots are set
            continue
        done.add(mesh.as_pointer())
        if len(mesh.materials) == 0:
            mesh.materials.append(default)
            continue
        for slot, imported in enumerate(mesh.materials):
            if imported is None:
                mesh.materials[slot] = default
                continue
            index = imported.get("stereobench_material")
            if index is None or index >= len(ours):
                unmatched.add(imported.name)
                continue
            spec = PARAMS["materials"][index]
            if spec["texture"] >= 0 and mesh.uv_layers.get(uv_map_name(spec["texcoord"])) is None:
                # Without texture coordinates the albedo is the base colour factor alone.
                if index not in plain:
                    untextured = dict(spec, texture=-1)
                    plain[index] = make_material("stereobench_%d_untextured" % index, untextured,
                                                 textures, switches)
                mesh.materials[slot] = plain[index]
            else:
                mesh.materials[slot] = ours[index]
    if unmatched:
        fail("imported materials without a glTF material index: " + ", ".join(sorted(unmatched)))
    return switches


def setup_world():
    world = bpy.data.worlds.new("stereobench_world")
    bpy.context.scene.world = world
    world.use_nodes = True
    world.cycles.sampling_method = "NONE"  # the background lights nothing
    tree = world.node_tree
    nodes = tree.nodes
    while nodes:
        nodes.remove(nodes[0])
    out = nodes.new("ShaderNodeOutputWorld")
    dark = nodes.new("ShaderNodeBackground")
    dark.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    dark.inputs["Strength"].default_value = 0.0
    seen = nodes.new("ShaderNodeBackground")
    bg = PARAMS["background"]
    seen.inputs["Color"].default_value = (bg[0], bg[1], bg[2], 1.0)
    seen.inputs["Strength"].default_value = 1.0
    path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    tree.links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    tree.links.new(dark.outputs["Background"], mix.inputs[1])
    tree.links.new(seen.outputs["Background"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return seen.inputs["Strength"]


def axes_with_z(z):
    # Right-handed unit axes (x, y, z) with z along the given vector.
    from mathutils import Vector
    zv = Vector(z).normalized()
    helper = (1.0, 0.0, 0.0) if abs(zv[0]) < 0.9 else (0.0, 1.0, 0.0)
    xv = Vector(helper).cross(zv).normalized()
    return xv, zv.cross(xv), zv


def shape_spot(data, spot):
    # Emission strength clamp((-Normal.z - cos_outer) * scale, 0, 1)^2, KHR_lights_punctual's
    # angular attenuation, as -Normal.z * (-scale) + (-cos_outer * scale) clamped, squared.
    tree = data.node_tree
    emission = next(n for n in tree.nodes if n.type == "EMISSION")
    coords = tree.nodes.new("ShaderNodeTexCoord")
    split = tree.nodes.new("ShaderNodeSeparateXYZ")
    ramp = math_node(tree.nodes, "MULTIPLY_ADD")
    ramp.use_clamp = True
    ramp.inputs[1].default_value = -spot["scale"]
    ramp.inputs[2].default_value = -spot["cos_outer"] * spot["scale"]
    square = math_node(tree.nodes, "MULTIPLY")
    tree.links.new(coords.outputs["Normal"], split.inputs[0])
    tree.links.new(split.outputs["Z"], ramp.inputs[0])
    tree.links.new(ramp.outputs[0], square.inputs[0])
    tree.links.new(ramp.outputs[0], square.inputs[1])
    tree.links.new(square.outputs[0], emission.inputs["Strength"])


def setup_lights():
    objects = []
    collection = bpy.context.scene.collection
    for i, l in enumerate(PARAMS["lights"]):
        if l["type"] == "point":
            data = bpy.data.lights.new("stereobench_light_%d" % i, "POINT")
            data.shadow_soft_size = 0.0
            data.energy = l["power_w"]
            p = gltf_to_blender(l["position"])
            matrix = matrix_from_columns((1, 0, 0), (0, 1, 0), (0, 0, 1), p)
            if l.get("spot") is not None:
                # The light's local -Z along the spot's axis; in a light's node tree the Normal
                # is the unit direction of emission in the light's local frame, so -Normal.z is
                # the cosine of the angle to the axis.
                matrix = matrix_from_columns(*axes_with_z([-c for c in gltf_to_blender(l["spot"]["direction"])]), p)
        elif l["type"] == "directional":
            data = bpy.data.lights.new("stereobench_light_%d" % i, "SUN")
            data.angle = 0.0
            data.energy = l["strength"]
            # A sun shines along its local -Z.
            matrix = matrix_from_columns(*axes_with_z([-c for c in gltf_to_blender(l["direction"])]), (0.0, 0.0, 0.0))
        else:
            fail("unsupported light type " + l["type"])
        data.color = l["color"]
        data.use_nodes = l.get("spot") is not None
        if data.use_nodes:
            shape_spot(data, l["spot"])
        data.cycles.cast_shadow = True
        data.cycles.use_multiple_importance_sampling = False
        data.cycles.max_bounces = 0
        obj = bpy.data.objects.new("stereobench_light_%d" % i, data)
        obj.matrix_world = matrix
        collection.objects.link(obj)
        objects.append(obj)
    return objects


def setup_camera():
    cam = PARAMS["camera"]
    data = bpy.data.cameras.new("stereobench_right_eye")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.sensor_height = cam["sensor_height_mm"]
    data.sensor_width = cam["sensor_height_mm"]
    data.lens_unit = "MILLIMETERS"
    data.lens = cam["lens_mm"]
    data.shift_x = cam["shift_x"]
    data.shift_y = cam["shift_y"]
    data.clip_start = cam["clip_start"]
    data.clip_end = cam["clip_end"]
    obj = bpy.data.objects.new("stereobench_right_eye", data)
    obj.matrix_world = matrix_from_columns(gltf_to_blender(cam["right"]), gltf_to_blender(cam["up"]),
                                           gltf_to_blender(cam["back"]), gltf_to_blender(cam["origin"]))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj


def setup_render():
    scene = bpy.context.scene
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x = PARAMS["width"]
    r.resolution_y = PARAMS["height"]
    r.resolution_percentage = 100
    r.pixel_aspect_x = 1.0
    r.pixel_aspect_y = 1.0
    r.use_border = False
    r.film_transparent = False
    r.dither_intensity = 0.0
    r.use_persistent_data = True
    r.use_motion_blur = False
    if PARAMS["threads"] > 0:
        r.threads_mode = "FIXED"
        r.threads = PARAMS["threads"]
    else:
        r.threads_mode = "AUTO"
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_mode = "RGBA"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "ZIP"
    r.use_file_extension = False
    c = scene.cycles
    c.device = "CPU"
    c.feature_set = "SUPPORTED"
    c.shading_system = False
    c.samples = 1
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = PARAMS["seed"]
    c.use_animated_seed = False
    c.sample_offset = 0
    c.max_bounces = 0
    c.diffuse_bounces = 0
    c.glossy_bounces = 0
    c.transmission_bounces = 0
    c.volume_bounces = 0
    # Cut-out holes pass camera and shadow rays; the minimum as large keeps Russian roulette off.
    c.transparent_max_bounces = PARAMS["transparent_bounces"]
    c.min_light_bounces = 0
    c.min_transparent_bounces = PARAMS["transparent_bounces"]
    c.caustics_reflective = False
    c.caustics_refractive = False
    c.blur_glossy = 0.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.direct_light_sampling_type = "NEXT_EVENT_ESTIMATION"
    c.use_guiding = False
    c.pixel_filter_type = "BOX"
    c.filter_width = PARAMS["filter_width"]
    c.film_exposure = 1.0
    c.use_camera_cull = False
    c.use_distance_cull = False
    c.use_fast_gi = False
    c.texture_limit_render = "OFF"
    scene.view_layers[0].use_pass_combined = True
    v = scene.view_settings
    v.view_transform = "Standard"
    v.look = "None"
    v.exposure = 0.0
    v.gamma = 1.0
    v.use_curve_mapping = False
    scene.display_settings.display_device = "sRGB"


def render_passes(lights, switches, background_strength):
    scene = bpy.context.scene
    for k, spec in enumerate(PARAMS["passes"]):
        # A pass is either the ambient term alone (materials emit, reflect nothing) or one light
        # alone (materials reflect, emit nothing): Cycles samples one light per shading point, so
        # one light per render makes its single sample exact.
        for tree, surface, bsdf, emission in switches:
            tree.links.new(emission if spec["ambient"] else bsdf, surface)
        background_strength.default_value = 1.0 if spec["background"] else 0.0
        for i, obj in enumerate(lights):
            obj.hide_render = i != spec["light"]
        scene.render.filepath = spec["file"]
        bpy.ops.render.render(write_still=True)
        if not os.path.isfile(spec["file"]):
            fail("Blender wrote no image to " + spec["file"])
        print("stereobench: wrote pass %d to %s" % (k, spec["file"]), flush=True)


import_scene()
place_moved_nodes()
place_instances()
switches = setup_materials()
background_strength = setup_world()
lights = setup_lights()
setup_camera()
setup_render()
render_passes(lights, switches, background_strength)
)PY";
  return kBody;
}

}  // namespace sb::validation
