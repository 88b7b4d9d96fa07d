"""pmr's center view against Cycles drawing the same camera, lights and environment with direct light
only (run by scripts/compare-cycles.sh; docs/SHADING.md, "Against Cycles").

blender -b --factory-startup --python tests/blender/compare_cycles.py -- --scene S.glb --pmr-dir DIR
    --work DIR [--samples N] [--bounces N]

DIR holds what `pmr render S.glb --views 9 --write views --preview` wrote: the sidecar (frame_0000.json:
the center view matrix, the vertical field of view, the view aspect, the lights as used, the
environment) and the center view's preview (frame_0000.center.png, sRGB, square pixels). The script
imports S.glb with Blender's glTF importer, places a camera at the center view, adds pmr's lights
(the default light as a sun of irradiance E; the file's own lights come with the import) and a
uniform world of pmr's environment radiance, renders with Cycles (direct light only: max bounces 0,
no denoiser, Standard view transform, transparent film) at the preview's size, and prints the mean
|sRGB difference| over the pixels both cover (alpha above 0.99 in both), as a fraction of 255 and in
255ths, and the mean signed difference pmr - Cycles.
"""

import argparse
import json
import math
import os
import sys

import bpy
import numpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_common import plain_cycles  # noqa: E402 (after its folder is on the path)

# Blender 3.4's glTF importer names numpy.bool, which newer numpy (Debian's) no longer has: the alias it meant.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

Y_UP = Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))  # Blender -> glTF axes


def setup_scene(scene_path, sidecar, width, height, samples, bounces):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=scene_path)
    scene = bpy.context.scene
    m = sidecar["center_view"]  # world -> center view, column-major, glTF axes
    view = Matrix([[m[4 * c + r] for c in range(4)] for r in range(4)])
    cam = bpy.data.objects.new("PmrCenter", bpy.data.cameras.new("PmrCenter"))
    scene.collection.objects.link(cam)
    cam.matrix_world = Y_UP.inverted() @ view.inverted()
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle_y = sidecar["rig"]["yfov_rad"]
    cam.data.clip_start, cam.data.clip_end = 0.01, 1e4
    scene.camera = cam
    shading = sidecar["shading"]
    for light in shading.get("lights") or []:
        if light.get("source") != "default":
            continue  # the file's lights come with the import
        sun = bpy.data.objects.new("PmrDefault", bpy.data.lights.new("PmrDefault", "SUN"))
        sun.data.energy = light["intensity"]  # irradiance (W/m^2 in Blender, lux in pmr: the same number)
        sun.data.angle = 0.0
        toward = Y_UP.inverted().to_3x3() @ -Vector(light["direction"])  # the sun's +Z points at the light
        sun.rotation_euler = toward.to_track_quat("Z", "Y").to_euler()
        scene.collection.objects.link(sun)
    env = shading.get("environment", {})
    world = bpy.data.worlds.new("PmrUniform")
    world.use_nodes = True
    uniform = env.get("kind", "uniform") == "uniform"
    radiance = env.get("radiance", 0.2) * env.get("intensity", 1.0) if uniform else 0.0
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (radiance, radiance, radiance, 1.0)
    scene.world = world
    plain_cycles(scene, samples)
    scene.cycles.max_bounces = bounces  # 0: direct light only, what pmr computes
    scene.cycles.sample_clamp_direct = 0.0
    scene.render.film_transparent = True
    scene.render.dither_intensity = 0.0
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "8"
    return scene


def compare(a_img, b_img):
    """Mean |difference| and mean signed difference of R, G, B over pixels covered in both."""
    a, b = list(a_img.pixels), list(b_img.pixels)
    total = signed = 0.0
    n = 0
    for i in range(0, len(a), 4):
        if a[i + 3] < 0.99 or b[i + 3] < 0.99:
            continue
        for c in range(3):
            total += abs(a[i + c] - b[i + c])
            signed += a[i + c] - b[i + c]
        n += 3
    return (total / n, signed / n, n // 3) if n else (float("nan"), float("nan"), 0)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--scene", required=True)
    parser.add_argument("--pmr-dir", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--bounces", type=int, default=0, help="Cycles' max bounces (0: direct light, as pmr)")
    args = parser.parse_args(argv)
    with open(os.path.join(args.pmr_dir, "frame_0000.json"), encoding="utf-8") as f:
        sidecar = json.load(f)
    pmr_img = bpy.data.images.load(os.path.join(args.pmr_dir, "frame_0000.center.png"))
    width, height = pmr_img.size
    scene = setup_scene(os.path.abspath(args.scene), sidecar, width, height, args.samples, args.bounces)
    pmr_img = bpy.data.images.load(os.path.join(args.pmr_dir, "frame_0000.center.png"))  # after the reset
    out = os.path.join(os.path.abspath(args.work), "cycles.png")
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    mean, signed, pixels = compare(pmr_img, bpy.data.images.load(out))
    print("compare-cycles: max bounces %d, %d pixels covered in both: mean |sRGB difference| %.4f (%.1f/255), "
          "mean pmr - Cycles %+.4f" % (args.bounces, pixels, mean, 255.0 * mean, signed))


if __name__ == "__main__":
    main()
