"""The render operator: export, run pmr (modal, or blocking in background mode), load the result."""

import json
import os
import shutil
import tempfile
import time

import bpy

from . import command, export, runner
from .properties import addon_prefs

# The running job (one at a time) and the outcome of the last one, for scripts and the cancel button.
_job = None
last_result = {}


class RenderJob:
    """Everything one render needs: prepared in Blender's main thread, then pmr runs on its own."""

    def __init__(self, context):
        scene = context.scene
        settings = scene.pmr_lightfield
        self.settings = settings  # read during set-up only: undo may replace it while pmr runs
        self.warnings = []
        self.program = runner.resolve_program(addon_prefs(context).pmr_path)
        if scene.camera is None:
            raise RuntimeError("the scene has no active camera")
        self.camera = scene.camera.name
        self.out_dir = _output_dir(settings.output_dir)
        os.makedirs(self.out_dir, exist_ok=True)
        self.frames = _frame_range(scene, settings)
        self.fps = scene.render.fps / scene.render.fps_base
        self.export_dir, self.temporary = _export_dir(context, self.out_dir)
        try:
            self.scene_path = self._export(context)
            self.environment, more = self._world(scene)
            if not scene.render.film_transparent:
                # Blender's film shows the world behind the scene: pmr draws its environment there, on
                # the focal plane, where the panel shows it sharp
                self.environment = self.environment + ["--background", "environment"]
            self.args = command.render_args(settings, self.scene_path, self.out_dir, self.camera,
                                            self.frames, self.fps, self.environment,
                                            export.has_animations(self.scene_path), _colour(scene, more))
            # the files each frame goes to, as pmr names them (the options are checked on the way)
            self.sidecars = runner.print_outputs(self.program, self.args, cwd=self.out_dir)
        except Exception:
            self.cleanup()
            raise
        self.warnings += more

    def _export(self, context):
        """The glTF for pmr, area lights included; notes what a light loses on the way in self.warnings."""
        scene = context.scene
        path = export.export_gltf(self.export_dir)
        if scene.render.fps_base != 1.0:
            export.retime_animations(path, scene.render.fps_base)
        self.warnings += export.add_area_lights(path, scene, context.view_layer)
        return path

    def _world(self, scene):
        mode = self.settings.environment
        if mode == "STUDIO":
            return [], []
        if mode == "NONE":
            return ["--environment-intensity", "0"], []
        return export.world_environment(scene.world, self.export_dir)

    def start(self):
        self.started = time.monotonic()
        self.process = runner.PmrProcess(self.program, self.args, cwd=self.out_dir)

    def cleanup(self):
        if self.temporary:
            shutil.rmtree(self.export_dir, ignore_errors=True)

    def outputs(self):
        """The files pmr wrote, per frame: {frame: sidecar's outputs}, from the sidecars present."""
        found = {}
        for frame, name in sorted(self.sidecars.items()):
            sidecar = os.path.join(self.out_dir, name)
            if os.path.isfile(sidecar):
                with open(sidecar, encoding="utf-8") as f:
                    found[frame] = json.load(f).get("outputs", {})
        return found


def _blender_ocio_config():
    """The OpenColorIO config Blender itself uses: $OCIO when set, else the one it ships."""
    if os.environ.get("OCIO"):
        return os.environ["OCIO"]
    datafiles = bpy.utils.system_resource("DATAFILES")  # its `path` argument finds folders only
    path = os.path.join(datafiles, "colormanagement", "config.ocio") if datafiles else ""
    return path if os.path.isfile(path) else ""


def _colour(scene, warnings):
    """pmr's colour options from the scene's Color Management panel, so that the quilt PNG shows what
    Blender shows; a note in `warnings` for what cannot follow."""
    view = scene.view_settings
    config = _blender_ocio_config()
    if not config:
        warnings.append("Blender's OpenColorIO config was not found: the PNG previews use Standard")
    if view.use_curve_mapping:
        warnings.append("Color Management curves are not carried to pmr's PNG previews")
    return command.colour_args(config, scene.display_settings.display_device, view.view_transform, view.look,
                               view.exposure, view.gamma)


def _output_dir(path):
    """The absolute output folder; '//' of an unsaved file means the temporary folder."""
    if path.startswith("//") and not bpy.data.filepath:
        return os.path.join(tempfile.gettempdir(), path[2:] or "pmr")
    return os.path.abspath(bpy.path.abspath(path))


def _export_dir(context, out_dir):
    """Where the glTF goes: a fresh temporary folder, or out_dir/pmr_scene when it is kept."""
    if addon_prefs(context).keep_export:
        folder = os.path.join(out_dir, "pmr_scene")
        os.makedirs(folder, exist_ok=True)
        return folder, False
    return tempfile.mkdtemp(prefix="pmr-export-"), True


def _frame_range(scene, settings):
    if settings.mode == "STILL":
        first = last = scene.frame_current
    elif settings.use_scene_range:
        first, last = scene.frame_start, scene.frame_end
    else:
        first, last = settings.frame_start, settings.frame_end
    if first < 0 or last < first:
        raise RuntimeError("pmr renders frames 0 and up; the range is %d to %d" % (first, last))
    return first, last


# ---- results ------------------------------------------------------------------------------------

def load_result(job):
    """Loads the first frame's quilt (or panel image) into bpy.data.images, as a sequence when several
    frames were rendered, and shows it in every Image Editor; returns the image or None."""
    outputs = job.outputs()
    if not outputs:
        return None
    first = min(outputs)
    kind = "quilt" if "quilt" in outputs[first] else "encoded"
    path = os.path.join(job.out_dir, outputs[first][kind])
    image = bpy.data.images.load(path, check_existing=False)
    if len(outputs) > 1:
        image.source = "SEQUENCE"
    _show(image, first, len(outputs))
    return image


def _show(image, first, count):
    wm = bpy.context.window_manager
    for window in wm.windows:
        for area in window.screen.areas:
            if area.type != "IMAGE_EDITOR":
                continue
            space = area.spaces.active
            space.image = image
            if image.source == "SEQUENCE":
                space.image_user.frame_start = first
                space.image_user.frame_duration = count
                space.image_user.frame_offset = first - 1
            area.tag_redraw()


def finish(job, operator):
    """Reports pmr's outcome in Blender; returns the operator's result set."""
    job.process.poll()
    elapsed = time.monotonic() - job.started
    proc = job.process
    for text in job.warnings + proc.warnings:
        operator.report({"WARNING"}, "pmr: " + text)
    for text in proc.errors:
        operator.report({"ERROR"}, "pmr: " + text)
    last_result.clear()
    last_result.update(returncode=proc.returncode, errors=list(proc.errors), argv=proc.argv,
                       warnings=job.warnings + proc.warnings, elapsed=elapsed, out_dir=job.out_dir,
                       log=list(proc.log))
    job.cleanup()
    if proc.returncode != 0:
        if proc.returncode in (143, -15):
            operator.report({"WARNING"}, "pmr render cancelled")
            return {"CANCELLED"}
        if not proc.errors:  # crashed or killed without saying why: show its last lines
            operator.report({"ERROR"}, "pmr exited with status %d: %s"
                            % (proc.returncode, " | ".join(proc.log[-3:])))
        return {"CANCELLED"}
    outputs = job.outputs()
    last_result["outputs"] = outputs
    image = load_result(job)
    last_result["image"] = image.name if image else None
    operator.report({"INFO"}, "pmr: %d frame(s) in %.1f s to %s%s" % (
        len(outputs), elapsed, job.out_dir, " (image %r)" % image.name if image else ""))
    return {"FINISHED"}


# ---- operators ----------------------------------------------------------------------------------

class PMR_OT_render(bpy.types.Operator):
    """Export the scene and render it with pmr as a light field (Esc cancels)"""

    bl_idname = "pmr.render_lightfield"
    bl_label = "Render Light Field"

    blocking: bpy.props.BoolProperty(
        name="Blocking", default=False, options={"SKIP_SAVE"},
        description="Wait for pmr to finish (always so in background mode, where timers do not run)")

    @classmethod
    def poll(cls, context):
        return _job is None

    def _start(self, context):
        """The job prepared and pmr started (the running job); None after an error report."""
        global _job
        try:
            job = RenderJob(context)
        except (runner.PmrNotFound, RuntimeError, OSError) as e:
            last_result.clear()
            last_result.update(returncode=getattr(e, "returncode", None), errors=[str(e)])
            self.report({"ERROR"}, str(e))
            return None
        job.start()
        _job = job
        return job

    def execute(self, context):
        """Blocking run: pmr's progress goes to the console."""
        global _job
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        try:
            while not job.process.finished():
                for kind, value in job.process.poll():
                    if kind == "progress":
                        print("pmr: frame %d written (%d/%d)" % value, flush=True)
                time.sleep(0.05)
            return finish(job, self)
        except KeyboardInterrupt:
            job.process.cancel()
            job.process.wait()
            return finish(job, self)
        finally:
            _job = None

    def invoke(self, context, event):
        if self.blocking or bpy.app.background:
            return self.execute(context)
        if self._start(context) is None:
            return {"CANCELLED"}
        self._timer = context.window_manager.event_timer_add(0.2, window=context.window)
        context.window_manager.modal_handler_add(self)
        context.window_manager.progress_begin(0, 1)
        context.workspace.status_text_set("pmr: exporting done, rendering... (Esc to cancel)")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = _job
        if event.type == "ESC":
            job.process.cancel()  # pmr exits soon after; the timer below sees it
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        job.process.poll()
        if not job.process.finished():
            self._show_progress(context, job)
            return {"RUNNING_MODAL"}
        return self._end(context, job)

    def _show_progress(self, context, job):
        frame, done, total = job.process.progress
        if total:
            context.window_manager.progress_update(done / total)
            text = "pmr: frame %d written (%d/%d)" % (frame, done, total)
        else:
            text = "pmr: starting (exported to glTF)"
        context.workspace.status_text_set(text + " - Esc to cancel")

    def _end(self, context, job):
        global _job
        context.window_manager.event_timer_remove(self._timer)
        context.window_manager.progress_end()
        context.workspace.status_text_set(None)
        _job = None
        return finish(job, self)


class PMR_OT_cancel(bpy.types.Operator):
    """Stop the running pmr render"""

    bl_idname = "pmr.cancel_lightfield"
    bl_label = "Cancel Light Field Render"

    @classmethod
    def poll(cls, context):
        return _job is not None

    def execute(self, context):
        _job.process.cancel()
        return {"FINISHED"}


def running():
    return _job is not None


CLASSES = [PMR_OT_render, PMR_OT_cancel]
