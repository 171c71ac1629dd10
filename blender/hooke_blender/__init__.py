"""Hooke inside Blender: mark a mesh as cloth or jelly and others as colliders, then Bake.

The bake writes the scene Hooke reads (docs/blender.md): the object as a body (its
vertices in their order; Bake All: every cloth and jelly of the scene, simulated together,
each with its own cache), every collider (still, rigidly animated, or deforming: the
evaluated mesh per frame as a PC2 cache), the scene's frame range, frame rate, gravity and
units; it runs ``hooke run`` with a progress bar (Esc cancels it; Ctrl-C in ``blender
--background``) and, once it has finished, puts the cache in place and plays it through a
Mesh Cache modifier named ``Hooke``. A bake that fails or is cancelled leaves the earlier
cache as it was.
"""

import contextlib
import os
import re
import shutil
import signal
import tempfile
import threading
import time

import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import pc2
from .run import Run, find_hooke
from .scene import PRESETS, BakeError, from_hooke, ignored_settings, write_scene

#: The modifier that plays a bake.
MODIFIER = "Hooke"


class HookePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    program: StringProperty(
        name="Program",
        description="The hooke program (empty: HOOKE_BIN, or hooke on the PATH)",
        subtype="FILE_PATH",
    )

    def draw(self, context):
        self.layout.prop(self, "program")


class HookeSettings(bpy.types.PropertyGroup):
    kind: EnumProperty(
        name="Kind",
        items=(
            ("NONE", "None", "Not part of a Hooke bake"),
            ("CLOTH", "Cloth", "A cloth made of this mesh: its vertices are the particles"),
            ("JELLY", "Jelly", "A jelly filling this closed mesh with a lattice"),
            ("COLLIDER", "Collider", "A shape the bodies collide with"),
        ),
        default="NONE",
    )
    preset: EnumProperty(
        name="Fabric",
        items=[(p, p.capitalize(), f"Hooke's {p} (docs/materials.md)") for p in PRESETS],
        default="cotton",
    )
    thickness: FloatProperty(
        name="Thickness",
        description="How far the cloth keeps from colliders and itself",
        default=0.005,
        min=0.0,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    friction: FloatProperty(name="Friction", description="Coulomb's μ", default=0.3, min=0.0)
    pin_group: StringProperty(
        name="Pin Group",
        description="Vertices of this group are pinned: they follow the object's own animation",
    )
    integrator: EnumProperty(
        name="Integrator",
        items=(
            ("VBD", "Block descent", "Large steps without crossings (cloth)"),
            ("NEWTON", "Newton", "Large steps on stiff and volumetric bodies (jelly)"),
            ("SYMPLECTIC", "Symplectic Euler", "Small explicit steps: give many substeps"),
        ),
        default="VBD",
    )
    substeps: IntProperty(name="Substeps", description="Steps per frame", default=1, min=1)
    spacing: FloatProperty(
        name="Spacing",
        description="The jelly's lattice spacing",
        default=0.1,
        min=1e-4,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    mass: FloatProperty(name="Mass", description="kg per lattice particle", default=0.05, min=1e-9)
    stiffness: FloatProperty(name="Stiffness", description="Springs' ks, N/m", default=600.0, min=0.0)
    damping: FloatProperty(name="Damping", description="Springs' kd, N·s/m", default=1.0, min=0.0)
    motion: EnumProperty(
        name="Motion",
        items=(
            ("STATIC", "Static", "Where it is at the first frame"),
            ("RIGID", "Rigid", "Its object transform, sampled every frame"),
            ("DEFORMING", "Deforming", "Its evaluated mesh (armature, shape keys, modifiers) every frame"),
        ),
        default="STATIC",
    )
    folder: StringProperty(
        name="Cache Folder",
        description="Where the bake's scene and cache go",
        default="//hooke",
        subtype="DIR_PATH",
    )


class HOOKE_PT_physics(bpy.types.Panel):
    bl_label = "Hooke"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "physics"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw(self, context):
        layout = self.layout
        s = context.object.hooke
        layout.prop(s, "kind")
        if s.kind == "CLOTH":
            layout.prop(s, "preset")
            layout.prop(s, "thickness")
            layout.prop(s, "friction")
            layout.prop_search(s, "pin_group", context.object, "vertex_groups")
        elif s.kind == "JELLY":
            for name in ("spacing", "mass", "stiffness", "damping"):
                layout.prop(s, name)
        elif s.kind == "COLLIDER":
            layout.prop(s, "motion")
            layout.prop(s, "friction")
        if s.kind in ("CLOTH", "JELLY"):
            layout.prop(s, "integrator")
            layout.prop(s, "substeps")
            layout.prop(s, "folder")
            row = layout.row()
            row.operator("hooke.bake")
            row.operator("hooke.free_bake")
            row = layout.row()
            row.operator("hooke.bake_all")
            row.operator("hooke.free_all")


def folder_of(obj):
    """The bake folder of ``obj`` (its setting, relative to the .blend; the system's
    temporary folder for an unsaved file)."""
    path = obj.hooke.folder or "//hooke"
    if path.startswith("//") and not bpy.data.filepath:
        path = os.path.join(tempfile.gettempdir(), "hooke", path[2:])
    return os.path.abspath(bpy.path.abspath(path))


def cache_of(obj):
    """Where ``obj``'s baked cache goes."""
    return os.path.join(folder_of(obj), re.sub(r"[^\w.-]", "_", obj.name) + ".pc2")


def bodies_of(context):
    """Every cloth and jelly of the scene, the active object first when it is one (it sets
    the integrator and substeps of a bake of them all), the others by name."""
    active = context.active_object
    return sorted(
        (o for o in context.scene.objects if o.hooke.kind in ("CLOTH", "JELLY")),
        key=lambda o: (o is not active, o.name),
    )


def title_of(objs):
    """The objects of a bake, as messages name them: ``Object 'Cloth'``."""
    names = ", ".join(f"'{o.name}'" for o in objs)
    return f"Object {names}" if len(objs) == 1 else f"Objects {names}"


class Job:
    """One bake of ``objs`` together: their scene written into a fresh folder beside the
    first one's cache, and hooke running on it."""

    def __init__(self, context, objs):
        self.objs = objs
        folder = folder_of(objs[0])
        self.finals = [cache_of(o) for o in objs]
        for final in self.finals:
            os.makedirs(os.path.dirname(final), exist_ok=True)
        self.work = tempfile.mkdtemp(prefix=".bake-", dir=folder)
        try:
            prefs = context.preferences.addons.get(__package__)
            program = find_hooke(prefs.preferences.program if prefs else "")
            self.scene, self.frames, self.bodies = write_scene(
                context, objs, self.work, MODIFIER
            )
            # One body: its cache; several: a folder of one per body, named as the bodies.
            if len(objs) == 1:
                out = os.path.join(self.work, "out.pc2")
                self.outs = [out]
            else:
                out = os.path.join(self.work, "out") + os.sep
                self.outs = [os.path.join(out, name + ".pc2") for name, _ in self.bodies]
            self.run = Run(program, self.scene, out)
        except BaseException:
            shutil.rmtree(self.work, ignore_errors=True)
            raise

    @property
    def title(self):
        """The objects baked, as messages name them."""
        return title_of(self.objs)

    def finish(self, context):
        """Puts the finished run's caches in place (each in its object's own coordinates)
        and plays them; raises when the run failed.

        Until the caches replace the earlier ones, an interrupt (KeyboardInterrupt) cancels
        the bake and leaves the earlier ones; from then on interrupts are held, so that the
        new caches, the scene beside the first and the modifiers change together. Returns
        whether an interrupt came while they were held."""
        staged = []
        try:
            if self.run.poll() != 0:
                raise BakeError(f"{self.title}: hooke stopped: {self.run.failure()}")
            scale = context.scene.unit_settings.scale_length or 1.0
            for k, ((_, matrices), out, final) in enumerate(
                zip(self.bodies, self.outs, self.finals)
            ):
                samples = pc2.read(out)
                local = [
                    [tuple(m.inverted() @ from_hooke(p, scale)) for p in sample]
                    for m, sample in zip(matrices, samples)
                ]
                # Written beside the cache it replaces, on its file system: the move below
                # is a rename.
                path = f"{final}.{os.getpid()}-{k}.staged"
                staged.append(path)
                pc2.write(path, local)
                os.remove(out)
            with interrupts_held() as held:
                for path, final in zip(staged, self.finals):
                    os.replace(path, final)
                # The scene that made them stays beside the first one's cache, for
                # `hooke run` by hand.
                kept = os.path.splitext(self.finals[0])[0] + "-scene"
                shutil.rmtree(kept, ignore_errors=True)
                os.replace(self.work, kept)
                # The others' own scenes, from earlier bakes of them alone, made no more.
                for final in self.finals[1:]:
                    shutil.rmtree(os.path.splitext(final)[0] + "-scene", ignore_errors=True)
                for obj, final in zip(self.objs, self.finals):
                    play(context, obj, final)
            return bool(held)
        finally:
            for path in staged:
                if os.path.exists(path):
                    os.remove(path)
            shutil.rmtree(self.work, ignore_errors=True)

    def cancel(self):
        self.run.stop()
        shutil.rmtree(self.work, ignore_errors=True)


@contextlib.contextmanager
def interrupts_held():
    """Holds Ctrl-C (SIGINT) for the block and yields a list that gets an entry per
    interrupt held. Only where Python's own handler is in place and on the main thread:
    elsewhere (Blender's own handler, a worker thread) the block runs as it is."""
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield []
        return
    held = []
    signal.signal(signal.SIGINT, lambda *_: held.append(True))
    try:
        yield held
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def play(context, obj, path):
    """Plays the cache at ``path`` on ``obj`` through the Mesh Cache modifier ``Hooke``."""
    mod = obj.modifiers.get(MODIFIER) or obj.modifiers.new(MODIFIER, "MESH_CACHE")
    mod.cache_format = "PC2"
    mod.filepath = path
    mod.frame_start = context.scene.frame_start
    mod.frame_scale = 1.0
    mod.play_mode = "SCENE"
    mod.time_mode = "FRAME"
    mod.deform_mode = "OVERWRITE"
    mod.interpolation = "LINEAR"
    mod.show_viewport = True
    mod.show_render = True


class BakeOperator:
    """What a bake does, whatever it bakes (``objects``): the scene written, hooke run with
    a progress bar (modal in the UI, polled in the background), the caches put in place."""

    def objects(self, context):
        raise NotImplementedError

    def execute(self, context):
        objs = self.objects(context)
        try:
            if not objs:
                raise BakeError(
                    f"Scene '{context.scene.name}': no object is a cloth or a jelly (Physics > "
                    "Hooke > Kind)"
                )
            self.job = Job(context, objs)
            for note in ignored_settings(objs):
                self.report({"WARNING"}, note)
        except BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except KeyboardInterrupt:
            self.report({"WARNING"}, f"{title_of(objs)}: bake cancelled; the earlier cache is kept")
            return {"CANCELLED"}
        if bpy.app.background or context.window is None:
            return self.wait(context)
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def wait(self, context):
        """The bake without a window: polled until done; Ctrl-C cancels it."""
        shown = -1
        names = ", ".join(f"'{o.name}'" for o in self.job.objs)
        try:
            while self.job.run.poll() is None:
                percent = int(100 * self.job.run.fraction)
                if percent // 10 != shown // 10:
                    print(f"Hooke: baking {names}: {percent} %", flush=True)
                    shown = percent
                time.sleep(0.05)
        except KeyboardInterrupt:
            return self.cancelled()
        return self.done(context)

    def done(self, context):
        try:
            late = self.job.finish(context)
        except BakeError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        except KeyboardInterrupt:
            return self.cancelled()
        title = self.job.title
        # What the run could not keep of its promises is said where the user looks, as the
        # command line says it: a bake that finished is not a bake without a doubt.
        for said in self.job.run.warnings():
            self.report({"WARNING"}, f"{title}: hooke warns: {said}")
        if late:
            self.report({"WARNING"}, f"{title}: the interrupt came as the bake was put in place; it is kept")
        self.report({"INFO"}, f"{title}: baked {self.job.frames} frames")
        return {"FINISHED"}

    def cancelled(self):
        self.job.cancel()
        self.report({"WARNING"}, f"{self.job.title}: bake cancelled; the earlier cache is kept")
        return {"CANCELLED"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            self.end(context)
            return self.cancelled()
        if event.type == "TIMER":
            wm.progress_update(int(1000 * self.job.run.fraction))
            if self.job.run.poll() is not None:
                self.end(context)
                return self.done(context)
        return {"PASS_THROUGH"}

    def end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self.timer)
        wm.progress_end()


class HOOKE_OT_bake(BakeOperator, bpy.types.Operator):
    """Simulate the active object with Hooke over the scene's frame range and play it"""

    bl_idname = "hooke.bake"
    bl_label = "Bake"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None

    def objects(self, context):
        return [context.active_object]


class HOOKE_OT_bake_all(BakeOperator, bpy.types.Operator):
    """Simulate every cloth and jelly of the scene together with Hooke (they collide with
    each other), each with its own cache; the active one's integrator and substeps apply"""

    bl_idname = "hooke.bake_all"
    bl_label = "Bake All"

    def objects(self, context):
        return bodies_of(context)


def free(obj):
    """Removes ``obj``'s bake: its Mesh Cache modifier, its cache and the scene beside it."""
    mod = obj.modifiers.get(MODIFIER)
    if mod is not None:
        obj.modifiers.remove(mod)
    path = cache_of(obj)
    if os.path.isfile(path):
        os.remove(path)
    shutil.rmtree(os.path.splitext(path)[0] + "-scene", ignore_errors=True)


class HOOKE_OT_free_bake(bpy.types.Operator):
    """Remove the active object's Hooke bake: its Mesh Cache modifier and its cache"""

    bl_idname = "hooke.free_bake"
    bl_label = "Free Bake"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None

    def execute(self, context):
        free(context.active_object)
        return {"FINISHED"}


class HOOKE_OT_free_all(bpy.types.Operator):
    """Remove the Hooke bake of every cloth and jelly of the scene"""

    bl_idname = "hooke.free_all"
    bl_label = "Free All"

    def execute(self, context):
        for obj in bodies_of(context):
            free(obj)
        return {"FINISHED"}


CLASSES = (
    HookePreferences,
    HookeSettings,
    HOOKE_PT_physics,
    HOOKE_OT_bake,
    HOOKE_OT_bake_all,
    HOOKE_OT_free_bake,
    HOOKE_OT_free_all,
)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Object.hooke = PointerProperty(type=HookeSettings)


def unregister():
    del bpy.types.Object.hooke
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
