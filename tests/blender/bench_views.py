"""Speed of the same light-field views: pmr through the add-on against Blender view by view.

blender -b --factory-startup --python tests/blender/bench_views.py -- \
    --model MODEL.gltf --pmr PMR --out DIR [--blender-views K] [--engines cycles16,cycles128,eevee64]

(Eevee needs an OpenGL context: run under xvfb-run -a.) Imports MODEL onto a ground plane with a sun,
a point light and a grey world, frames it with a camera, installs the add-on (as test_addon.py does;
set BLENDER_USER_SCRIPTS / BLENDER_USER_CONFIG to folders inside DIR) and renders the lg-portrait
preset's 48 views of 420x560 with pmr; then renders K of those views (evenly spread, the center view
among them) with each Blender engine from cameras placed as pmr's sidecar says (offset along the
camera's x axis, lens shift keeping the focal plane). Prints a table row per engine and writes
DIR/side_by_side.png: pmr's center view beside Cycles' 128-sample render of it.
"""

import argparse
import json
import math
import os
import re
import sys
import time

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_addon as t  # noqa: E402  (the add-on installer and scene helpers)

# Debian's Blender 3.4 glTF importer uses np.bool, which numpy 1.24 removed (the exporter does not)
if "bool" not in np.__dict__:
    np.bool = bool

RES = (420, 560)  # lg-portrait's view size


def build_scene(model):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = RES
    scene.frame_start = scene.frame_end = scene.frame_current = 0
    bpy.ops.import_scene.gltf(filepath=model)
    meshes = [o for o in scene.objects if o.type == "MESH"]
    corners = [o.matrix_world @ Vector(c) for o in meshes for c in o.bound_box]
    lo = Vector([min(c[i] for c in corners) for i in range(3)])
    hi = Vector([max(c[i] for c in corners) for i in range(3)])
    center, size = (lo + hi) / 2, max(hi - lo)

    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.08, 0.08, 0.08, 1)
    scene.world = world
    bpy.ops.mesh.primitive_plane_add(size=size * 6, location=(center.x, center.y, lo.z))
    bpy.context.object.data.materials.append(t.material("Ground", (0.5, 0.5, 0.5, 1)))

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location = center + Vector((0.9, -1.6, 0.7)) * size
    t.look_at(cam, center)
    scene.camera = cam
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(35), 0, math.radians(-40))
    scene.collection.objects.link(sun)
    point = bpy.data.objects.new("Fill", bpy.data.lights.new("Fill", "POINT"))
    point.data.energy = 40.0 * size * size
    point.data.shadow_soft_size = 0.0
    point.location = center + Vector((-1.2, -0.8, 1.0)) * size
    scene.collection.objects.link(point)
    return scene


def run_pmr(scene, ops_module, out):
    s = scene.pmr_lightfield
    s.preset, s.views, s.view_width, s.view_height = "lg-portrait", 0, 0, 0
    s.samples, s.output_dir, s.mode, s.write = "4", out, "STILL", "QUILT"
    t0 = time.monotonic()
    r = t.run_operator(ops_module)
    total = time.monotonic() - t0
    with open(os.path.join(out, "frame_0000.json"), encoding="utf-8") as f:
        sidecar = json.load(f)
    summary = [line for line in r["log"] if " frame(s) in " in line]
    return sidecar, total, r["elapsed"], summary


def view_camera(scene, base, sidecar, index):
    """A camera for view `index`: moved along the center camera's x, lens-shifted so that the focal
    plane (the rig's focal_distance) stays where the center view has it."""
    rig = sidecar["rig"]
    offset = sidecar["views"][index]["offset"]
    cam = bpy.data.objects.new("View%03d" % index, base.data.copy())
    scene.collection.objects.link(cam)
    cam.matrix_world = base.matrix_world.copy()
    cam.location = base.matrix_world @ Vector((offset, 0, 0))
    # Blender's shift is in units of the larger frame side; here the height (portrait)
    height_at_focus = 2 * rig["focal_distance"] * math.tan(rig["yfov_rad"] / 2)
    cam.data.shift_x = -offset / height_at_focus
    return cam


def render_views(scene, sidecar, engine, samples, indices, path):
    scene.render.engine = engine
    if engine == "CYCLES":
        scene.cycles.device, scene.cycles.samples, scene.cycles.use_denoising = "CPU", samples, False
    else:
        scene.eevee.taa_render_samples = samples
    scene.view_settings.view_transform, scene.view_settings.look = "Standard", "None"
    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    base, times = scene.camera, []
    for i in indices:
        scene.camera = view_camera(scene, base, sidecar, i)
        scene.render.filepath = "%s_view%02d.exr" % (path, i)
        t0 = time.monotonic()
        bpy.ops.render.render(write_still=True)
        times.append(time.monotonic() - t0)
    scene.camera = base
    return times


def rgba(path):
    img = bpy.data.images.load(path)
    return np.array(img.pixels[:], dtype=np.float32).reshape(img.size[1], img.size[0], 4)


def side_by_side(quilt_path, sidecar, center, cycles_path, out_png, scene):
    """pmr's center view (its quilt tile) | Cycles, both over the same grey, sRGB PNG."""
    q = sidecar["quilt"]
    tw, th = q["tile_width"], q["tile_height"]
    col, row = center % q["columns"], center // q["columns"]
    quilt = rgba(quilt_path)
    left = quilt[row * th:(row + 1) * th, col * tw:(col + 1) * tw]  # rows bottom-up, as the quilt's
    right = rgba(cycles_path)
    gap = np.ones((th, 8, 4), dtype=np.float32)
    both = np.concatenate([left, gap, right], axis=1)
    bg = 0.18
    both[..., :3] += (1 - both[..., 3:4]) * bg  # premultiplied over grey
    both[..., 3] = 1
    img = bpy.data.images.new("side_by_side", both.shape[1], both.shape[0], float_buffer=True)
    img.pixels[:] = both.ravel()
    scene.view_settings.view_transform = "Standard"  # linear -> sRGB, no Filmic curve
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_depth = "8"
    img.save_render(out_png, scene=scene)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    p = argparse.ArgumentParser()
    p.add_argument("--model", required=True)
    p.add_argument("--pmr", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--blender-views", type=int, default=3)
    p.add_argument("--engines", default="cycles16,cycles128,eevee64")
    a = p.parse_args(argv)
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)

    scene = build_scene(os.path.abspath(a.model))
    ops_module = t.install_addon(out, a.pmr)
    sidecar, total, pmr_wall, summary = run_pmr(scene, ops_module, os.path.join(out, "pmr"))
    n = sidecar["rig"]["views"]
    w, h = sidecar["rig"]["view_width"], sidecar["rig"]["view_height"]
    print("BENCH pmr add-on: %d views of %dx%d, 4 samples: export+pmr %.2f s, pmr process %.2f s, "
          "%.3f s/view | %s" % (n, w, h, total, pmr_wall, total / n, " ".join(summary)), flush=True)
    center = n // 2
    k = a.blender_views
    indices = sorted({center} | {round(i * (n - 1) / max(1, k - 1)) for i in range(k)})[:max(k, 1)]
    if center not in indices:
        indices[-1] = center
    for spec in a.engines.split(","):
        engine = "CYCLES" if spec.startswith("cycles") else "BLENDER_EEVEE"
        samples = int(re.sub(r"\D", "", spec))
        try:
            times = render_views(scene, sidecar, engine, samples, indices, os.path.join(out, spec))
        except Exception as e:  # Eevee without a GL context
            print("BENCH %s: failed: %s" % (spec, e), flush=True)
            continue
        per = sum(times) / len(times)
        print("BENCH %s: %d of %d views of %dx%d rendered, %s s each (first includes set-up); "
              "%.2f s/view -> %.0f s for all %d views" % (
                  spec, len(times), n, w, h, ", ".join("%.2f" % x for x in times), per, per * n, n),
              flush=True)
    quilt = os.path.join(out, "pmr", sidecar["outputs"]["quilt"])
    cyc = os.path.join(out, "cycles128_view%02d.exr" % center)
    if os.path.exists(cyc):
        side_by_side(quilt, sidecar, center, cyc, os.path.join(out, "side_by_side.png"), scene)
        print("BENCH side by side: %s" % os.path.join(out, "side_by_side.png"), flush=True)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
