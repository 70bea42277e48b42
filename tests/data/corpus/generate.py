# Generates the third-party glTF corpus with Blender's own glTF exporter (Debian's `blender`
# package), so the loader and renderer are tested on files a user would export, not files we wrote
# by hand. Run from the repository root:
#
#   blender -b --factory-startup --python tests/data/corpus/generate.py -- tests/data/corpus
#
# Each file is small (a few tens of KiB) and committed; rerun only to change the set. The files:
#   suzanne.glb        Blender's monkey, smooth shaded, one coloured material, no lights
#   textured_box.glb   a bevelled box with a generated 64x64 checker texture, no lights
#   millimetres.glb    a bracket modelled in millimetres (about 400 units across), no lights
#   point_lamps.glb    a table with two point lamps and a sun (KHR_lights_punctual), no camera
#   dense_monkey.glb   Blender's monkey subdivided twice (about 15,700 triangles) in millimetres (about
#                      2,700 units across), on a floor, no lights: a mesh big enough for the levels
#                      of detail, at another scale; committed as compress.sh's dense_monkey_draco.glb
#   colonnade.glb      twelve linked duplicates of one fluted column (one mesh, twelve nodes), a
#                      floor and a sun: the loader keeps the column as one mesh with twelve instances
#
# Names after the output folder regenerate only those files (for example `-- tests/data/corpus
# colonnade`).
import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out_dir = args[0] if args else "."
wanted = set(args[1:])


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def material(name, rgba, metallic=0.0, roughness=0.5, image=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = rgba
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    if image is not None:
        tex = m.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        m.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def export(name):
    path = os.path.join(out_dir, name)
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_lights=True, export_cameras=True,
                              export_apply=True)
    print("wrote", path, os.path.getsize(path), "bytes")


def suzanne():
    reset()
    bpy.ops.mesh.primitive_monkey_add(size=2.0)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(material("clay", (0.8, 0.45, 0.3, 1.0), roughness=0.6))
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -1.2))
    bpy.context.active_object.data.materials.append(material("floor", (0.7, 0.7, 0.7, 1.0)))
    export("suzanne.glb")


def dense_monkey():
    reset()
    bpy.ops.mesh.primitive_monkey_add(size=2000.0)
    obj = bpy.context.active_object
    subdivision = obj.modifiers.new("subdivision", "SUBSURF")
    subdivision.levels = 2
    subdivision.render_levels = 2
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(material("clay", (0.8, 0.45, 0.3, 1.0), roughness=0.6))
    bpy.ops.mesh.primitive_plane_add(size=8000.0, location=(0.0, 0.0, -1200.0))
    bpy.context.active_object.data.materials.append(material("floor", (0.7, 0.7, 0.7, 1.0)))
    path = os.path.join(out_dir, "dense_monkey.glb")
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_lights=True, export_cameras=True,
                              export_apply=True)
    print("wrote", path, os.path.getsize(path), "bytes")


def textured_box():
    reset()
    size = 64
    img = bpy.data.images.new("checker", width=size, height=size)
    pixels = []
    for y in range(size):
        for x in range(size):
            on = ((x // 8) + (y // 8)) % 2 == 0
            pixels += [0.9, 0.85, 0.2, 1.0] if on else [0.1, 0.3, 0.8, 1.0]
    img.pixels = pixels
    img.pack()
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    obj = bpy.context.active_object
    bevel = obj.modifiers.new("bevel", "BEVEL")
    bevel.width = 0.05
    bevel.segments = 2
    obj.data.materials.append(material("checker", (1.0, 1.0, 1.0, 1.0), image=img))
    obj.rotation_euler = (0.3, 0.0, 0.6)
    export("textured_box.glb")


def millimetres():
    reset()
    # Units as a CAD export gives them: 1 unit = 1 mm, so the part is hundreds of units across.
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 10.0))
    base = bpy.context.active_object
    base.scale = (400.0, 120.0, 20.0)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-190.0, 0.0, 110.0))
    bpy.context.active_object.scale = (20.0, 120.0, 200.0)
    for i in range(5):
        bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=12.0, depth=60.0, location=(-120.0 + 60.0 * i, 0.0, 50.0))
    steel = material("steel", (0.6, 0.62, 0.65, 1.0), metallic=0.8, roughness=0.35)
    for obj in bpy.data.objects:
        obj.data.materials.append(steel)
    export("millimetres.glb")


def point_lamps():
    reset()
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.75))
    bpy.context.active_object.scale = (1.6, 0.9, 0.05)
    for x in (-0.7, 0.7):
        for y in (-0.35, 0.35):
            bpy.ops.mesh.primitive_cylinder_add(vertices=10, radius=0.04, depth=0.75, location=(x, y, 0.375))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=0.15, location=(0.2, 0.0, 0.93))
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    wood = material("wood", (0.55, 0.35, 0.2, 1.0))
    for obj in bpy.data.objects:
        if obj.type == "MESH":
            obj.data.materials.append(wood)
    for name, loc, watts, colour in (("warm lamp", (-0.8, 0.5, 1.8), 60.0, (1.0, 0.8, 0.6)),
                                     ("cool lamp", (0.9, -0.6, 1.6), 40.0, (0.6, 0.75, 1.0))):
        data = bpy.data.lights.new(name, "POINT")
        data.energy = watts
        data.color = colour
        lamp = bpy.data.objects.new(name, data)
        lamp.location = loc
        bpy.context.collection.objects.link(lamp)
    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = 2.0
    sun_obj = bpy.data.objects.new("sun", sun)
    sun_obj.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))
    bpy.context.collection.objects.link(sun_obj)
    export("point_lamps.glb")


def colonnade():
    reset()
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=0.25, depth=3.0, location=(0.0, 0.0, 1.5))
    column = bpy.context.active_object
    column.data.materials.append(material("limestone", (0.8, 0.76, 0.68, 1.0), roughness=0.7))
    # Flutes: every other rim vertex pulled in, then smooth shading.
    for i, v in enumerate(column.data.vertices):
        if (i // 2) % 2 == 1:
            v.co.x *= 0.88
            v.co.y *= 0.88
    bpy.ops.object.shade_smooth()
    # Linked duplicates (Alt+D): twelve objects sharing the column's mesh data, two rows of six,
    # every other one turned and one scaled, as a scene built by hand would have them.
    for i in range(1, 12):
        dup = column.copy()  # shares column.data
        dup.location = (-3.75 + 1.5 * (i % 6), -1.5 if i < 6 else 1.5, 1.5)
        dup.rotation_euler = (0.0, 0.0, math.radians(15.0 * (i % 2)))
        if i == 7:
            dup.scale = (1.2, 1.2, 1.2)
        bpy.context.collection.objects.link(dup)
    column.location = (-3.75, -1.5, 1.5)
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    bpy.context.active_object.data.materials.append(material("paving", (0.55, 0.55, 0.52, 1.0), roughness=0.8))
    sun = bpy.data.lights.new("sun", "SUN")
    sun.energy = 3.0
    sun_obj = bpy.data.objects.new("sun", sun)
    sun_obj.rotation_euler = (math.radians(50.0), 0.0, math.radians(35.0))
    bpy.context.collection.objects.link(sun_obj)
    # No modifier to apply, so the exporter keeps the shared mesh shared.
    path = os.path.join(out_dir, "colonnade.glb")
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_lights=True, export_cameras=True)
    print("wrote", path, os.path.getsize(path), "bytes")


for make in (suzanne, textured_box, millimetres, point_lamps, colonnade, dense_monkey):
    if not wanted or make.__name__ in wanted:
        make()
