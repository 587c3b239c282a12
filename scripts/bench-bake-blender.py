# Blender's "selected to active" bake of one pair, for scripts/bench-bake-blender.sh:
#   blender -b --factory-startup --python scripts/bench-bake-blender.py -- \
#     LOW.gltf HIGH.gltf OUT.exr normal|ao|position|transfer SIZE SAMPLES EXTRUSION MAX_RAY_DISTANCE AO_DISTANCE THREADS [REPEATS [by_name]]
# Cycles on the CPU; the cage is the low-poly extruded by EXTRUSION along its normals, rays reach
# MAX_RAY_DISTANCE inward (scene units). The low-poly is invisible to every ray (it is the surface
# being replaced: it must not occlude the high-poly's AO). Bakes REPEATS times (default 1) and prints
# one line `seconds=T`: the fastest bake call alone (not Blender's start, the imports or the image
# write). Kind position: the high-poly's position at each texel's hit, written in glTF's axes (Y up;
# Blender's are Z up: its importer turns the coordinates, not the objects). Kind transfer: the
# high-poly's base colour (Cycles' diffuse colour pass alone; its importer multiplies COLOR_0 in),
# linear.
# With by_name, parts are matched by name as a Blender artist bakes such a set: each low-poly object
# (NAME_low...) with the high-poly objects of its key (NAME_high...) selected, one bake call each into
# the one image, not cleared between them; the time is the calls' sum.
# Kind ao_self (scripts/bench-ao-blender.sh): a scene's AO onto its own UVs, as `matbake bake-ao
# --texture`: LOW.gltf is the scene, HIGH.gltf is ignored, every mesh object is baked, each material
# into its own SIZE² image; OUT.exr is the first material's (EXTRUSION and MAX_RAY_DISTANCE unused).
# The materials' normal maps are unplugged: Cycles' AO follows the shading normal, matbake's the
# mesh's.
import sys
import time

import bpy
import numpy

# Debian's Blender 3.4 glTF importer calls numpy.bool, an alias NumPy 1.24 (Debian's) removed: the
# importer fails on any mesh with normals. The alias was the builtin bool; give it back.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:]
low_path, high_path, out_path, kind = args[0], args[1], args[2], args[3]
size, samples = int(args[4]), int(args[5])
extrusion, max_ray, ao_distance, threads = float(args[6]), float(args[7]), float(args[8]), int(args[9])
repeats = int(args[10]) if len(args) > 10 else 1
by_name = len(args) > 11 and args[11] == "by_name"

bpy.ops.wm.read_factory_settings(use_empty=True)


def import_meshes(path):
    """The file's mesh objects."""
    bpy.ops.object.select_all(action="DESELECT")
    bpy.ops.import_scene.gltf(filepath=path)
    return [o for o in bpy.context.selected_objects if o.type == "MESH"]


def import_mesh(path):
    """The file's mesh objects joined into one; returns it."""
    meshes = import_meshes(path)
    bpy.ops.object.select_all(action="DESELECT")
    for o in meshes:
        o.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]
    if len(meshes) > 1:
        bpy.ops.object.join()
    return bpy.context.view_layer.objects.active


def bake_into(material, image):
    """Makes a new image node holding `image` the material's active node: the bake's target."""
    nodes = material.node_tree.nodes
    node = nodes.new("ShaderNodeTexImage")
    node.image = image
    nodes.active = node


def new_image(name):
    image = bpy.data.images.new(name, size, size, float_buffer=True, alpha=False)
    image.colorspace_settings.name = "Non-Color"
    return image


def key(name, suffix):
    """A part's name up to its first suffix (_low or _high), as matbake's --match by_name reads it."""
    return name.split(suffix)[0]


if kind == "ao_self":
    bpy.ops.import_scene.gltf(filepath=low_path)
    baked = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    materials = list(dict.fromkeys(slot.material for o in baked for slot in o.material_slots if slot.material))
    images = [new_image(f"bake{i}") for i in range(len(materials))]
    for material, material_image in zip(materials, images):
        bake_into(material, material_image)
        tree = material.node_tree
        for link in [link for link in tree.links if link.to_socket.name == "Normal"]:
            tree.links.remove(link)
    image = images[0]
    calls = [(baked[:-1], baked[-1])]  # every object baked onto itself at once
else:
    highs = import_meshes(high_path) if by_name else [import_mesh(high_path)]
    lows = import_meshes(low_path) if by_name else [import_mesh(low_path)]
    image = new_image("bake")
    for low in lows:
        for attribute in ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission",
                          "visible_volume_scatter", "visible_shadow"):
            setattr(low, attribute, False)
        for slot in low.material_slots:
            bake_into(slot.material, image)
    # Each bake call: the high-poly objects selected, the low-poly one active.
    calls = [([h for h in highs if key(h.name, "_high") == key(low.name, "_low")], low) for low in lows] if by_name \
        else [(highs, lows[0])]

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.use_adaptive_sampling = False  # SAMPLES rays a texel, as asked (adaptive stops early)
scene.cycles.use_denoising = False
scene.render.threads_mode = "FIXED"
scene.render.threads = threads
scene.world = bpy.data.worlds.new("world")
scene.world.light_settings.distance = ao_distance
bake = scene.render.bake
bake.use_selected_to_active = kind != "ao_self"
bake.use_clear = not by_name  # one image for every part's call
bake.use_cage = False
bake.cage_extrusion = extrusion
bake.max_ray_distance = max_ray
bake.margin = 0
bake.normal_space = "TANGENT"
bake.normal_r, bake.normal_g, bake.normal_b = "POS_X", "POS_Y", "POS_Z"
bake.use_pass_direct = bake.use_pass_indirect = False  # the diffuse pass's colour alone (transfer)
bake.use_pass_color = True

seconds = float("inf")
for _ in range(repeats):
    total = 0.0
    for selected, active in calls:
        bpy.ops.object.select_all(action="DESELECT")
        for o in selected + [active]:
            o.select_set(True)
        bpy.context.view_layer.objects.active = active
        started = time.perf_counter()
        bpy.ops.object.bake(type={"normal": "NORMAL", "ao": "AO", "ao_self": "AO", "position": "POSITION", "transfer": "DIFFUSE"}[kind])
        total += time.perf_counter() - started
    seconds = min(seconds, total)

if kind == "position":  # Blender's (x, y, z) is glTF's (x, -z, y)
    pixels = numpy.array(image.pixels[:], dtype=numpy.float32).reshape(-1, 4)
    pixels[:, 1], pixels[:, 2] = pixels[:, 2].copy(), -pixels[:, 1]
    image.pixels[:] = pixels.ravel()

image.filepath_raw = out_path
image.file_format = "OPEN_EXR"
image.save()
print(f"seconds={seconds:.4f}")
