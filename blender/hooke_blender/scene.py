"""A Blender scene as Hooke's: the baked object as a body, the colliders, the frame range.

Hooke is +Y up in metres; Blender is +Z up in its scene units. A Blender point
``(x, y, z)`` (in units of ``scale_length`` metres) is Hooke's ``(x, z, -y)`` times
``scale_length``. Every position written goes through :func:`to_hooke`, every position read
back through :func:`from_hooke`.
"""

import math
import os

from mathutils import Matrix, Vector

from . import pc2

#: Blender's frame (+Z up) to Hooke's (+Y up): Hooke = AXES @ Blender.
AXES = Matrix(((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)))

PRESETS = ("cotton", "silk", "wool", "denim")


class BakeError(Exception):
    """What stops a bake, said as Blender says errors: naming the object and the setting."""


def to_hooke(p, scale):
    """A Blender world point as Hooke's, metres."""
    return (p[0] * scale, p[2] * scale, -p[1] * scale)


def from_hooke(p, scale):
    """A Hooke point (metres) as Blender's world point."""
    return Vector((p[0] / scale, -p[2] / scale, p[1] / scale))


def evaluated_positions(obj, depsgraph):
    """``obj``'s evaluated mesh now: its vertices in world coordinates (Blender's), in the
    mesh's order, its faces, and its world matrix."""
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        world = ev.matrix_world.copy()
        points = [world @ v.co for v in mesh.vertices]
        faces = [tuple(p.vertices) for p in mesh.polygons]
    finally:
        ev.to_mesh_clear()
    return points, faces, world


def write_obj(path, points, faces):
    """An OBJ of ``points`` (Hooke's, metres) and ``faces`` (0-based corners)."""
    with open(path, "w", encoding="utf-8") as f:
        f.write("# written by Hooke's Blender extension\n")
        for p in points:
            f.write(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n")
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def frames(scene):
    """The frames a bake covers, and the frame rate."""
    fps = scene.render.fps / scene.render.fps_base
    return range(scene.frame_start, scene.frame_end + 1), fps


def setting(x):
    """A number the user set (stored as 32-bit) as they typed it: 0.005, not 0.004999999888."""
    return float(f"{x:.7g}")


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def relative_keys(track):
    """Hooke keys ``translate``/``rotate`` for rigid poses ``track`` (``(t, location,
    rotation)`` in Hooke's frame, rotation a 3×3 Matrix), relative to the first, with the
    Euler angles kept continuous from key to key."""
    t0, o0, r0 = track[0]
    inverse = r0.transposed()
    keys, previous = [], None
    for t, o, r in track:
        rel = (r @ inverse).to_euler("XYZ", previous) if previous else (r @ inverse).to_euler("XYZ")
        previous = rel
        keys.append(
            "{ t = %r, translate = %s, rotate = %s }"
            % (
                t - t0,
                toml_value([o[0] - o0[0], o[1] - o0[1], o[2] - o0[2]]),
                toml_value([math.degrees(a) for a in rel]),
            )
        )
    return keys


def check_mesh(obj, what):
    if obj.type != "MESH":
        raise BakeError(f"Object '{obj.name}': Hooke {what} must be a mesh, not {obj.type.lower()}")
    if len(obj.data.polygons) == 0:
        raise BakeError(f"Object '{obj.name}': it has no faces; Hooke {what} needs a surface")


class ColliderTrack:
    """A collider's mesh as the bake reads it: its faces and its points at the first frame,
    and per frame its points (deforming) or its pose (rigid)."""

    def __init__(self, obj):
        self.obj = obj
        self.motion = obj.hooke.motion
        self.faces = None
        self.start = None
        self.samples = []
        self.poses = []

    def read(self, depsgraph, frame, scale):
        """Reads the collider at ``frame`` (its index in the bake, number and time)."""
        k, number, t = frame
        if k > 0 and self.motion == "STATIC":
            return
        if k == 0 or self.motion == "DEFORMING":
            points, faces, _ = evaluated_positions(self.obj, depsgraph)
            points = [to_hooke(p, scale) for p in points]
            if k == 0:
                self.faces, self.start, self.first = faces, points, number
            elif len(faces) != len(self.faces) or len(points) != len(self.start):
                raise BakeError(
                    f"Object '{self.obj.name}': its mesh changes topology at frame {number} "
                    f"({len(points)} vertices and {len(faces)} faces, against "
                    f"{len(self.start)} and {len(self.faces)} at frame {self.first}); a "
                    "deforming collider keeps its vertices and faces (Physics > Hooke > "
                    "Motion: Rigid, or apply the modifier that changes them)"
                )
            if self.motion == "DEFORMING":
                self.samples.append(points)
        if self.motion == "RIGID":
            m = self.obj.evaluated_get(depsgraph).matrix_world
            rotation = AXES @ m.to_3x3().normalized() @ AXES.transposed()
            self.poses.append((t, to_hooke(m.translation, scale), rotation))

    def write(self, folder, n, fps):
        """Writes its files into ``folder`` as collider ``n``; returns its scene lines."""
        name = f"collider-{n}.obj"
        response = (
            'response = { kind = "restitution", cr = 0.0, '
            f"friction = {setting(self.obj.hooke.friction)!r} }}"
        )
        lines = [f"# {self.obj.name} ({self.motion.lower()})", "[[collider]]"]
        if self.motion == "RIGID":
            pivot = self.poses[0][1]
            write_obj(
                os.path.join(folder, name),
                [tuple(a - b for a, b in zip(p, pivot)) for p in self.start],
                self.faces,
            )
            lines.append(
                f'shape = {{ kind = "mesh", path = "{name}", '
                f"translate = {toml_value(list(pivot))} }}"
            )
            lines.append(response)
            lines.append("motion = { keys = [" + ", ".join(relative_keys(self.poses)) + "] }")
            return lines
        write_obj(os.path.join(folder, name), self.start, self.faces)
        lines += [f'shape = {{ kind = "mesh", path = "{name}" }}', response]
        if self.motion == "DEFORMING":
            cache = f"collider-{n}.pc2"
            pc2.write(os.path.join(folder, cache), self.samples)
            lines.append(f'motion = {{ cache = "{cache}", fps = {fps!r} }}')
        return lines


def body_name(obj, k, taken):
    """The name body ``k`` gets in the scene: the object's, unless it could not name its own
    cache file (``hooke run --export DIR/ --format pc2``) or is taken; then ``body-k``."""
    name = obj.name
    fit = name and not name.startswith(".") and not any(
        c in "/\\" or not c.isprintable() for c in name
    )
    if not fit or name in taken:
        name = f"body-{k}"
        while name in taken:
            name += "_"
    taken.add(name)
    return name


def pinned_vertices(obj):
    """The vertices of ``obj``'s pin group (none without one); refused when the group does
    not exist or holds no vertex."""
    settings = obj.hooke
    if settings.kind != "CLOTH" or not settings.pin_group:
        return []
    group = obj.vertex_groups.get(settings.pin_group)
    if group is None:
        raise BakeError(
            f"Object '{obj.name}': vertex group '{settings.pin_group}' does not exist "
            "(Physics > Hooke > Pin Group names one of the object's vertex groups)"
        )
    pins = [
        v.index
        for v in obj.data.vertices
        if any(g.group == group.index and g.weight > 0.0 for g in v.groups)
    ]
    if not pins:
        raise BakeError(
            f"Object '{obj.name}': vertex group '{settings.pin_group}' holds no vertex "
            "(Physics > Hooke > Pin Group)"
        )
    return pins


def body_lines(obj, name, files, track, faces, pins, scale, fps):
    """The scene lines of ``obj`` as body ``name``, its files (``files``: the mesh's and the
    pins' cache's names) written beside the scene: its evaluated points per frame
    (``track``, Hooke's), its faces, its pinned vertices."""
    settings = obj.hooke
    mesh, pin_cache = files
    lines = ["", "[[body]]", f"name = {toml_value(name)}"]
    if settings.kind == "CLOTH":
        lines.append(f"thickness = {setting(settings.thickness) * scale!r}")
        lines.append(f"friction = {setting(settings.friction)!r}")
        if pins:
            lines.append(f"pins = {toml_value(pins)}")
            first = track[0]
            if any(
                max(abs(a - b) for a, b in zip(sample[i], first[i])) > 0.0
                for sample in track[1:]
                for i in pins
            ):
                pc2.write(pin_cache, track)
                lines.append(
                    f"pin_motion = {{ cache = {toml_value(os.path.basename(pin_cache))}, "
                    f"fps = {fps!r} }}"
                )
        lines += ["", "[body.shape]", 'kind = "mesh"', f"path = {toml_value(os.path.basename(mesh))}", ""]
        lines += ["[body.material]", f"preset = {toml_value(settings.preset)}"]
    else:
        lines.append(f"mass = {setting(settings.mass)!r}")
        lines += ["", "[body.shape]", 'kind = "solid"', f"path = {toml_value(os.path.basename(mesh))}"]
        lines.append(f"spacing = {setting(settings.spacing) * scale!r}")
        for kind, ks in (("structural", 1.0), ("shear", 1.0), ("bend", 0.5)):
            lines += [
                "",
                f"[body.springs.{kind}]",
                f"ks = {setting(settings.stiffness) * ks!r}",
                f"kd = {setting(settings.damping)!r}",
            ]
    write_obj(mesh, track[0], faces)
    return lines


def ignored_settings(objs):
    """What a bake of ``objs`` together does not take from the objects after the first, as
    messages: the integrator and substeps are the first one's, and a cloth's air drag
    reaches a jelly baked with it."""
    lead = objs[0].hooke
    said = []
    for obj in objs[1:]:
        s = obj.hooke
        if (s.integrator, s.substeps) != (lead.integrator, lead.substeps):
            said.append(
                f"Object '{obj.name}': its Integrator and Substeps ({s.integrator.lower()}, "
                f"{s.substeps}) are not read; the bake takes '{objs[0].name}''s "
                f"({lead.integrator.lower()}, {lead.substeps})"
            )
    if any(o.hooke.kind == "CLOTH" for o in objs):
        said += [
            f"Object '{o.name}': the cloth's air drag (mass_drag = 0.1) acts on this jelly too"
            for o in objs
            if o.hooke.kind == "JELLY"
        ]
    return said


def write_scene(context, objs, folder, modifier):
    """Writes the scene of baking ``objs`` together into ``folder``: each as a body (the
    first sets the integrator and the substeps), every other collider of the scene, and
    ``scene.toml``. Returns the scene file's path, the number of frames, and per object
    its body's name and its world matrix at each frame (what its own coordinates are
    relative to). ``modifier`` is the name of an earlier bake's modifier, left out of what
    is read."""
    scene = context.scene
    lead = objs[0]
    settings = lead.hooke
    scale = scene.unit_settings.scale_length or 1.0
    span, fps = frames(scene)
    if len(span) < 2:
        raise BakeError(
            f"Scene '{scene.name}': its frame range {scene.frame_start}–{scene.frame_end} "
            "has no frame to bake after the first (Output Properties > Frame Range)"
        )
    for obj in objs:
        if obj.hooke.kind not in ("CLOTH", "JELLY"):
            raise BakeError(
                f"Object '{obj.name}': Hooke bakes a cloth or a jelly; set Physics > Hooke > Kind"
            )
        check_mesh(obj, "a cloth" if obj.hooke.kind == "CLOTH" else "a jelly")
    substeps = max(1, settings.substeps)

    colliders = [o for o in scene.objects if o.hooke.kind == "COLLIDER" and o not in objs]
    for c in colliders:
        check_mesh(c, "a collider")
    pins = [pinned_vertices(obj) for obj in objs]

    # Every object's evaluated mesh at every frame the bake needs, read once per frame.
    # An earlier bake's modifier is left out of what is read, and put back as it was.
    start = scene.frame_current
    earlier = [(m, m.show_viewport) for m in (o.modifiers.get(modifier) for o in objs) if m]
    tracks = [ColliderTrack(c) for c in colliders]
    # Per object: its points (Hooke's) and world matrix at each frame, its faces.
    bodies = [([], [], []) for _ in objs]
    try:
        for m, _ in earlier:
            m.show_viewport = False
        for k, f in enumerate(span):
            scene.frame_set(f)
            depsgraph = context.evaluated_depsgraph_get()
            for obj, (track, matrices, faces) in zip(objs, bodies):
                points, polygons, world = evaluated_positions(obj, depsgraph)
                if k == 0:
                    faces.extend(polygons)
                track.append([to_hooke(p, scale) for p in points])
                matrices.append(world)
            for track in tracks:
                track.read(depsgraph, (k, f, k / fps), scale)
    finally:
        for m, shown in earlier:
            m.show_viewport = shown
        scene.frame_set(start)

    names = [lead.name] if len(objs) == 1 else []
    if not names:
        taken = set()
        names = [body_name(obj, k, taken) for k, obj in enumerate(objs)]
    title = f"'{lead.name}'" if len(objs) == 1 else ", ".join(f"'{o.name}'" for o in objs)
    lines = [
        f"# Hooke scene of the Blender object{'s' if len(objs) > 1 else ''} {title}, "
        "written by the Hooke extension",
        f"name = {toml_value('blender-' + lead.name)}",
        "",
        "[simulation]",
        f"integrator = {toml_value(settings.integrator.lower())}",
        f"dt = {1.0 / (fps * substeps)!r}",
        f"steps = {(len(span) - 1) * substeps}",
        f"every = {substeps}",
    ]
    gravity = scene.gravity if scene.use_gravity else Vector((0.0, 0.0, 0.0))
    lines.append(f"gravity = {toml_value([setting(g) + 0.0 for g in to_hooke(gravity, 1.0)])}")
    if any(o.hooke.kind == "CLOTH" for o in objs):
        lines.append("mass_drag = 0.1")
    for k, (obj, name, (track, _, faces)) in enumerate(zip(objs, names, bodies)):
        stem = "" if k == 0 else f"-{k}"
        files = (os.path.join(folder, f"body{stem}.obj"), os.path.join(folder, f"pins{stem}.pc2"))
        lines += body_lines(obj, name, files, track, faces, pins[k], scale, fps)
    for n, track in enumerate(tracks):
        lines += [""] + track.write(folder, n, fps)
    path = os.path.join(folder, "scene.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return path, len(span), [(name, matrices) for name, (_, matrices, _) in zip(names, bodies)]
