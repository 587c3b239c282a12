# High/low pairs the project did not design, for scripts/bench-bake-blender.sh (section `outside`),
# made from ../shared/testdata the way an artist makes them in Blender:
#   blender -b --factory-startup --python scripts/bench-bake-outside.py -- TESTDATA OUT_DIR
# writes OUT_DIR/NAME_low.gltf and NAME_high.gltf (glTF, separate .bin) for
#   bunny   the Stanford bunny (69,451 triangles, open at its base) as the high-poly; its LOD, the
#           Decimate modifier at 3% and Smart UV Project, as the low-poly (a sculpt onto its
#           simplification);
#   hard    the Khronos OrientationTest (a cube, six arrows and six target plates close beside it)
#           as the low-poly, every part's own UV islands packed into one map; the high-poly is each
#           part bevelled (Bevel modifier, 3 segments, edges sharper than 30°) and smooth-shaded,
#           named PART_high beside PART_low: a hard-surface set to bake matched by name.
# Each set is scaled to a 2-unit bounding-box diagonal (the bench's cages are in scene units). The
# mirrored-UV pair (Khronos NormalTangentMirrorTest onto itself, its normal map as the detail) needs
# no preparing.
import os
import sys

import bpy
import numpy

if not hasattr(numpy, "bool"):  # as in bench-bake-blender.py: Debian's Blender 3.4 with NumPy 1.24
    numpy.bool = bool

testdata, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def select(objects):
    bpy.ops.object.select_all(action="DESELECT")
    for o in objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def scale_to_diagonal(objects, diagonal):
    """Scales the objects' meshes (about the origin) so that their joint bounding box has this diagonal."""
    corners = numpy.array([o.matrix_world @ v.co for o in objects for v in o.data.vertices])
    factor = diagonal / numpy.linalg.norm(corners.max(axis=0) - corners.min(axis=0))
    for o in objects:
        o.matrix_world = o.matrix_world.copy()
        o.scale = [s * factor for s in o.scale]
        o.location = [c * factor for c in o.location]
    select(objects)
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)


def export(objects, name):
    select(objects)
    bpy.ops.export_scene.gltf(filepath=os.path.join(out_dir, name + ".gltf"), export_format="GLTF_SEPARATE",
                              use_selection=True, export_normals=True, export_texcoords=True, export_apply=True)


def one_material(objects, name):
    material = bpy.data.materials.new(name)
    for o in objects:
        o.data.materials.clear()
        o.data.materials.append(material)


def smart_uvs(objects):
    """One UV map over all the objects: Smart UV Project's islands, packed together."""
    select(objects)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.uv.smart_project(angle_limit=1.15, island_margin=0.01)
    bpy.ops.object.mode_set(mode="OBJECT")


def bunny():
    clear()
    bpy.ops.import_mesh.ply(filepath=os.path.join(testdata, "meshes-hard/draco/bun_zipper.ply"))
    high = bpy.context.selected_objects[0]
    scale_to_diagonal([high], 2.0)
    select([high])
    bpy.ops.object.shade_smooth()
    high.name = "bunny_high"
    bpy.ops.object.duplicate()
    low = bpy.context.view_layer.objects.active
    low.name = "bunny_low"
    decimate = low.modifiers.new("decimate", "DECIMATE")
    decimate.ratio = 0.03
    select([low])
    bpy.ops.object.modifier_apply(modifier=decimate.name)
    smart_uvs([low])
    one_material([low], "bunny")
    one_material([high], "bunny_high")
    export([low], "bunny_low")
    export([high], "bunny_high")


def hard_surface():
    clear()
    bpy.ops.import_scene.gltf(filepath=os.path.join(testdata, "gltf/OrientationTest/glTF-Embedded/OrientationTest.gltf"))
    lows = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    scale_to_diagonal(lows, 2.0)
    highs = []
    for low in lows:
        select([low])
        bpy.ops.object.duplicate()
        high = bpy.context.view_layer.objects.active
        high.name = low.name + "_high"
        # The importer splits vertices along hard edges (one normal each): weld them, or no edge is
        # shared for the bevel to round.
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.ops.mesh.select_all(action="SELECT")
        bpy.ops.mesh.remove_doubles(threshold=1e-5)
        bpy.ops.object.mode_set(mode="OBJECT")
        bevel = high.modifiers.new("bevel", "BEVEL")
        bevel.width, bevel.segments, bevel.limit_method = 0.004, 3, "ANGLE"
        bpy.ops.object.modifier_apply(modifier=bevel.name)
        bpy.ops.object.shade_smooth()
        high.data.use_auto_smooth = True  # the bevels smooth, the faces between them flat
        highs.append(high)
    for low in lows:
        low.name = low.name + "_low"
    smart_uvs(lows)
    one_material(lows, "set")
    one_material(highs, "set_high")
    export(lows, "hard_low")
    export(highs, "hard_high")


bunny()
hard_surface()
print("made=" + out_dir)
