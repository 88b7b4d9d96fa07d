"""pmr's command line: the arguments for a render, and reading what pmr prints. No bpy here."""

import json
import re
import shlex

WRITE = {"QUILT": "quilt", "ENCODED": "encoded", "BOTH": "encoded,quilt"}


def colour_args(config, display, view, look, exposure, gamma):
    """pmr's options for Blender's colour management: the PNG previews through the same OpenColorIO
    config, display, view, look, exposure and gamma as Blender's own view (docs/COLOUR.md)."""
    args = ["--preview"]
    if config:
        args += ["--ocio", config, "--display-device", display, "--view", view]
        if look and look != "None":
            args += ["--look", look]
    args += ["--view-exposure", "%.10g" % exposure, "--view-gamma", "%.10g" % gamma]
    return args


def render_args(settings, scene_path, out_dir, camera, frames, fps, environment, animated, colour=()):
    """The argument list of `pmr render` (without the program).

    settings: the scene's pmr_lightfield settings; camera: the camera object's name (its glTF node
    name); frames: (first, last); fps: frames per second; environment: its options from the world;
    animated: whether the glTF has animations (pmr refuses --animation all without any); colour:
    colour_args' options."""
    args = ["render", scene_path, "--out", out_dir, "--name", settings.name or "frame_####"]
    if settings.display_source == "CONFIG" and settings.display_config:
        args += ["--display-config", settings.display_config]
    else:
        args += ["--preset", settings.preset]
    if settings.views > 0:
        args += ["--views", str(settings.views)]
    if settings.view_width > 0 and settings.view_height > 0:
        args += ["--view-size", "%dx%d" % (settings.view_width, settings.view_height)]
    if settings.sampling != "DEFAULT":
        args += ["--sampling", settings.sampling]
    args += ["--samples", settings.samples, "--texture-filter", settings.texture_filter]
    args += ["--write", WRITE[settings.write]]
    args += ["--camera", camera]
    if animated:
        # Blender's exporter writes one glTF animation per action: play them all, as Blender does.
        args += ["--animation", "all"]
    args += ["--fps", "%.10g" % fps]
    first, last = frames
    args += ["--frames", str(first) if first == last else "%d:%d" % (first, last)]
    args += environment
    args += list(colour)
    if settings.shadow_catcher:
        args += ["--ground", "shadow"]
    # a folder is one configuration for pmr; re-rendering with changed settings is the normal case here
    args += ["--overwrite"]
    try:
        args += shlex.split(settings.extra_args)
    except ValueError as e:  # an unbalanced quote: a report, not a traceback
        raise RuntimeError("Extra options: %s (%s)" % (settings.extra_args, e)) from None
    return args


def planned_outputs(lines):
    """{frame: sidecar file name} from the JSON lines of `pmr render ... --print-outputs`: pmr alone
    expands --name, so the add-on finds exactly the files pmr writes."""
    sidecars = {}
    for line in lines:
        line = line.strip()
        if line.startswith("{"):
            entry = json.loads(line)
            sidecars[int(entry["frame"])] = entry["sidecar"]
    return sidecars


PROGRESS = re.compile(r"^pmr: frame (\d+) written \((\d+)/(\d+)\)")
ERROR = re.compile(r"^pmr: error: (.*)$")
WARNING = re.compile(r"^pmr: warning: (.*)$")


def parse_line(line):
    """('progress', (frame, done, total)) | ('error', text) | ('warning', text) | ('info', line)."""
    line = line.rstrip("\r\n")
    m = PROGRESS.match(line)
    if m:
        return "progress", tuple(int(g) for g in m.groups())
    m = ERROR.match(line)
    if m:
        return "error", m.group(1)
    m = WARNING.match(line)
    if m:
        return "warning", m.group(1)
    return "info", line
