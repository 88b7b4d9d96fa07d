"""The add-on's interactive path: the modal operator in a Blender with a window (run under Xvfb).

xvfb-run -a blender --factory-startup --python tests/blender/test_modal.py -- --pmr PMR --work DIR

With the factory start-up scene (cube, camera, light) and one area turned into an Image Editor:
1. the operator invoked as from the panel's button runs pmr modally: the status bar shows progress,
   and when pmr is done the quilt is shown in the Image Editor;
2. a longer sequence is cancelled with the Cancel operator after its first frame: pmr exits 143 and
   leaves no temporary file. Prints PASSED or FAILED (and quits Blender with status 0 or 1).
"""

import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_addon as t  # noqa: E402

state = {"step": "start", "statuses": set(), "ticks": 0}


def ui_context():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "IMAGE_EDITOR")
    return dict(window=window, screen=window.screen, area=area, region=area.regions[-1])


def invoke_render(settings_update):
    s = bpy.context.scene.pmr_lightfield
    for key, value in settings_update.items():
        setattr(s, key, value)
    with bpy.context.temp_override(**ui_context()):
        result = bpy.ops.pmr.render_lightfield("INVOKE_DEFAULT")
    if result != {"RUNNING_MODAL"}:
        t.fail("invoke returned %s, not RUNNING_MODAL" % result)


def step():
    """Timer: one state machine step; returns the delay to the next one."""
    ops = sys.modules["pmr_lightfield.operators"]
    state["ticks"] += 1
    if state["ticks"] > 600:
        t.fail("timed out in step %s" % state["step"])
    if state["step"] == "start":
        invoke_render(dict(mode="STILL", output_dir=os.path.join(state["work"], "modal")))
        state["step"] = "rendering"
    elif state["step"] == "rendering":
        if ops.running():
            return 0.1
        r = ops.last_result
        t.check(r.get("returncode") == 0, "modal render failed: %s" % r)
        shown = ui_context()["area"].spaces.active.image
        t.check(shown is not None and shown.name == r.get("image"),
                "the Image Editor shows %r, not the quilt %r" % (shown and shown.name, r.get("image")))
        t.log("modal render finished in %.1f s, quilt %s shown in the Image Editor"
              % (r["elapsed"], r["image"]))
        # long enough to be cancelled: 40 frames of 48 views of 420x560
        invoke_render(dict(mode="SEQUENCE", use_scene_range=False, frame_start=0, frame_end=39,
                           views=0, view_width=0, view_height=0,
                           output_dir=os.path.join(state["work"], "cancel")))
        state["step"] = "cancel"
    elif state["step"] == "cancel":
        job = ops._job
        if job is None:
            t.fail("the long render ended before it could be cancelled: %s" % ops.last_result)
        if job.process.progress[1] < 1:
            return 0.1
        with bpy.context.temp_override(**ui_context()):
            bpy.ops.pmr.cancel_lightfield()
        state["step"] = "cancelled"
    elif state["step"] == "cancelled":
        if ops.running():
            return 0.1
        r = ops.last_result
        t.check(r.get("returncode") == 143, "cancelled pmr exited %s, not 143" % r.get("returncode"))
        out = os.path.join(state["work"], "cancel")
        leftovers = [f for f in os.listdir(out) if f.startswith(".") and not f.startswith(".pmr-lock")]
        t.check(not leftovers, "temporary files left after cancel: %s" % leftovers)
        done = len([f for f in os.listdir(out) if f.endswith(".json")])
        t.log("cancelled after %d of 40 frames: pmr exited 143, no temporary file left" % done)
        t.log("PASSED")
        sys.stdout.flush()
        os._exit(0)
    return 0.2


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    p = argparse.ArgumentParser()
    p.add_argument("--pmr", required=True)
    p.add_argument("--work", required=True)
    a = p.parse_args(argv)
    state["work"] = os.path.abspath(a.work)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 96, 128
    cube = scene.objects["Cube"]
    cube.keyframe_insert("location", frame=0)
    cube.location.x = 2
    cube.keyframe_insert("location", frame=39)
    screen = bpy.context.window_manager.windows[0].screen
    max(screen.areas, key=lambda a: a.width * a.height).type = "IMAGE_EDITOR"
    t.install_addon(state["work"], a.pmr)
    s = scene.pmr_lightfield
    s.preset, s.views, s.view_width, s.view_height, s.write = "lg-portrait", 9, 48, 64, "QUILT"
    bpy.app.timers.register(step, first_interval=1.0)


try:
    main()
except Exception as e:  # noqa: BLE001
    t.fail("set-up: %s" % e)
