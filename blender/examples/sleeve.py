"""The docs' example, headless: a silk sleeve on an arm its armature bends at the elbow,
baked through the extension's operator and rendered with Cycles at frames 1 and 15.

    HOOKE_BIN=target/release/hooke python blender/examples/sleeve.py docs/img

(any Python with `bpy` from pip; or `blender --background --python blender/examples/sleeve.py
-- docs/img` with the extension installed). Writes blender-sleeve-1.png and
blender-sleeve-15.png into the folder given.
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def tube(name, radius, span, rings, capped):
    """A tube of 16 sides along x over ``span`` at height 1 m, ``rings`` rings of vertices;
    closed by a fan at each end when ``capped``."""
    sides = 16
    points, faces = [], []
    for i in range(rings):
        x = span[0] + (span[1] - span[0]) * i / (rings - 1)
        for j in range(sides):
            a = 2.0 * math.pi * j / sides
            points.append((x, radius * math.sin(a), 1.0 + radius * math.cos(a)))
    for i in range(rings - 1):
        for j in range(sides):
            a, b = i * sides + j, i * sides + (j + 1) % sides
            faces.append((a, a + sides, b + sides, b))
    if capped:
        points += [(span[0], 0.0, 1.0), (span[1], 0.0, 1.0)]
        first, last = len(points) - 2, len(points) - 1
        top = (rings - 1) * sides
        for j in range(sides):
            faces.append((first, j, (j + 1) % sides))
            faces.append((last, top + (j + 1) % sides, top + j))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(points, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj



def sleeve_scene():
    """Builds the scene in the current file: the arm (a deforming collider skinned to the
    bones 'upper' and 'fore' of an armature that bends it by 50° at frame 15 and back by
    frame 30) and the silk sleeve pinned at its shoulder ring; returns (arm, sleeve)."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 30
    scene.render.fps = 24
    arm = tube("Arm", 0.08, (-0.5, 0.5), 21, capped=True)
    bpy.ops.object.armature_add(location=(-0.5, 0.0, 1.0))
    rig = bpy.context.active_object
    bpy.ops.object.mode_set(mode="EDIT")
    upper = rig.data.edit_bones[0]
    upper.name = "upper"
    upper.head, upper.tail = (-0.5, 0.0, 1.0), (0.0, 0.0, 1.0)
    fore = rig.data.edit_bones.new("fore")
    fore.head, fore.tail = (0.0, 0.0, 1.0), (0.5, 0.0, 1.0)
    fore.parent = upper
    bpy.ops.object.mode_set(mode="OBJECT")
    rig.location = (0.0, 0.0, 0.0)
    for name in ("upper", "fore"):
        arm.vertex_groups.new(name=name)
    for v in arm.data.vertices:
        w = min(1.0, max(0.0, (v.co.x + 0.1) / 0.2))
        arm.vertex_groups["upper"].add([v.index], 1.0 - w, "REPLACE")
        arm.vertex_groups["fore"].add([v.index], w, "REPLACE")
    arm.modifiers.new("rig", "ARMATURE").object = rig
    pose = rig.pose.bones["fore"]
    pose.rotation_mode = "XYZ"
    for frame, angle in ((1, 0.0), (15, -50.0), (30, 0.0)):
        pose.rotation_euler = (0.0, 0.0, math.radians(angle))
        pose.keyframe_insert("rotation_euler", frame=frame)
    arm.hooke.kind = "COLLIDER"
    arm.hooke.motion = "DEFORMING"
    arm.hooke.friction = 0.5
    sleeve = tube("Sleeve", 0.12, (-0.45, 0.25), 15, capped=False)
    shoulder = sleeve.vertex_groups.new(name="shoulder")
    shoulder.add([v.index for v in sleeve.data.vertices if v.co.x < -0.44], 1.0, "REPLACE")
    sleeve.hooke.kind = "CLOTH"
    sleeve.hooke.preset = "silk"
    sleeve.hooke.pin_group = "shoulder"
    sleeve.hooke.substeps = 2
    bpy.context.view_layer.objects.active = sleeve
    bpy.ops.object.shade_smooth()
    return arm, sleeve


def main(out):
    import hooke_blender

    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Object, "hooke"):
        hooke_blender.register()
    scene = bpy.context.scene
    arm, sleeve = sleeve_scene()
    assert bpy.ops.hooke.bake() == {"FINISHED"}

    for obj, colour in ((arm, (0.8, 0.55, 0.4, 1.0)), (sleeve, (0.15, 0.3, 0.8, 1.0))):
        mat = bpy.data.materials.new(obj.name)
        mat.diffuse_color = colour
        if mat.node_tree is None:
            mat.use_nodes = True
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = colour
        obj.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, 0.0))
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), 0.0, math.radians(30)))
    bpy.context.active_object.data.energy = 3.0
    bpy.ops.object.camera_add(location=(0.4, -2.4, 1.7))
    camera = bpy.context.active_object
    bpy.ops.object.empty_add(location=(0.0, 0.0, 0.9))
    aim = camera.constraints.new("TRACK_TO")
    aim.target = bpy.context.active_object
    scene.camera = camera
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.7, 0.8, 1.0)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.render.resolution_x, scene.render.resolution_y = 640, 360
    os.makedirs(out, exist_ok=True)
    for frame in (1, 15):
        scene.frame_set(frame)
        scene.render.filepath = os.path.join(out, f"blender-sleeve-{frame}.png")
        bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    main(args[0] if args else ".")
