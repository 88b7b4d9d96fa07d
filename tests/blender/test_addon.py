"""Integration test of the pmr_lightfield Blender add-on (run by scripts/test-blender.sh).

blender -b --factory-startup --python tests/blender/test_addon.py -- --pmr PMR --work DIR

Installs the add-on from a zip into the user scripts folder (the script sets BLENDER_USER_SCRIPTS
and BLENDER_USER_CONFIG to temporary folders), builds a small scene, renders through the add-on's
operator and checks the files, the quilt layout, the camera, the point light's brightness against
Cycles and Blender's reading of the quilt sequence. Exits 1 with a FAILED line at the first failure.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import traceback

import addon_utils
import bpy
from mathutils import Matrix, Vector

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from cycles_common import plain_cycles  # noqa: E402 (after its folder is on the path)
ADDON_SRC = os.path.join(HERE, "..", "..", "blender", "pmr_lightfield")
ADDON = "pmr_lightfield"

FRAMES = (0, 2)  # the sequence: Blender frames 0 to 2 = pmr frames 0 to 2 (time f / fps)
VIEWS = 9  # odd: the center view N // 2 is the camera itself
SEQ_VIEW = (48, 64)  # lg-portrait's 3:4 view aspect
LIGHT_VIEW = (96, 128)
# Tolerance of pmr's patch means against Cycles', relative. The light's units are the point: a unit
# error is a factor of 683 (the exporter's default 'SPEC' lumens), 4 pi or pi. What remains is the
# BRDF: pmr weights its Lambert lobe by (1 - F), F0 = 0.04 (docs/SHADING.md), Cycles 3.4's Principled
# does not, so pmr is expected at 0.96-0.97 of Cycles where the plane is seen and lit near its normal
# (there Cycles' Disney diffuse is Lambert's). 64 Cycles samples add < 1% noise to a patch mean.
LIGHT_TOLERANCE = 0.05
# The whole-scene comparison (check_scene_against_cycles): 192x256 views, and the mean |sRGB
# difference| allowed without and with the area light, in 255ths (measured 4.0 and 4.2: pmr's (1 - F)
# diffuse weight, docs/BLENDER.md; a missing light or a wrong unit is tens of 255ths). The lights and
# the world are dimmed so that no pixel clips.
SCENE_VIEW = (192, 256)
SCENE_TOLERANCE = {False: 5.0, True: 5.0}
SCENE_LIGHT_SCALE = {"Sun": 0.5, "Bulb": 0.15, "Panel": 0.05}
SCENE_WORLD_STRENGTH = 0.3
FOREST = "/usr/share/blender/datafiles/studiolights/world/forest.exr"


def fail(message):
    print("test-blender: FAILED: " + message, flush=True)
    sys.stdout.flush()
    os._exit(1)  # Blender would otherwise keep running after an exception in --python


def check(condition, message):
    if not condition:
        fail(message)


def log(message):
    print("test-blender: " + message, flush=True)


# ---- the add-on ---------------------------------------------------------------------------------

def install_addon(work, pmr):
    """Installs the add-on from a zip, as a user would, and points its preferences at pmr."""
    user_scripts = os.environ.get("BLENDER_USER_SCRIPTS", "")
    check(user_scripts.startswith(work), "BLENDER_USER_SCRIPTS must be the test's own folder")
    staging = os.path.join(work, "zip")
    shutil.copytree(ADDON_SRC, os.path.join(staging, ADDON),
                    ignore=shutil.ignore_patterns("__pycache__"))
    archive = shutil.make_archive(os.path.join(work, ADDON), "zip", staging)
    bpy.ops.preferences.addon_install(filepath=archive, overwrite=True)
    check(os.path.isdir(os.path.join(user_scripts, "addons", ADDON)),
          "addon_install did not install into the user scripts folder")
    addon_utils.enable(ADDON, default_set=True, handle_error=lambda e: fail("enable: %s" % e))
    bpy.context.preferences.addons[ADDON].preferences.pmr_path = pmr
    return sys.modules[ADDON + ".operators"]


# ---- the scene ----------------------------------------------------------------------------------

def material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = 1.0
    return mat


def look_at(obj, target):
    obj.rotation_euler = (Vector(target) - obj.location).to_track_quat("-Z", "Y").to_euler()


def build_scene():
    """Camera (active, off the default position), sun, point light, keyframed cube, ground."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = FRAMES
    scene.render.fps, scene.render.fps_base = 24, 1.0
    scene.render.resolution_x, scene.render.resolution_y = LIGHT_VIEW  # the display's 3:4
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world

    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    ground = bpy.context.object
    ground.name = "Ground"
    ground.data.materials.append(material("Grey", (0.8, 0.8, 0.8, 1)))

    bpy.ops.mesh.primitive_cube_add(size=1, location=(-1.5, 0, 0.5))
    cube = bpy.context.object
    cube.name = "Mover"
    cube.data.materials.append(material("Red", (0.8, 0.1, 0.05, 1)))
    cube.keyframe_insert("location", frame=FRAMES[0])
    cube.location.x = 1.5
    cube.keyframe_insert("location", frame=FRAMES[1])

    cam_data = bpy.data.cameras.new("Lens")
    cam = bpy.data.objects.new("ShotCam", cam_data)
    scene.collection.objects.link(cam)
    cam.location = (4.0, -3.0, 3.0)
    look_at(cam, (0, 0, 0))
    scene.camera = cam

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 2.0
    sun.rotation_euler = (math.radians(40), 0, math.radians(30))
    scene.collection.objects.link(sun)

    point = bpy.data.objects.new("Bulb", bpy.data.lights.new("Bulb", "POINT"))
    point.data.energy = 500.0
    point.data.shadow_soft_size = 0.0  # a true point light, as glTF's
    point.location = (0, 0, 3)
    scene.collection.objects.link(point)
    # an area light (2 m x 1 m, facing down and tilted toward the origin): EXT_lights_area
    panel = bpy.data.objects.new("Panel", bpy.data.lights.new("Panel", "AREA"))
    panel.data.shape, panel.data.size, panel.data.size_y = "RECTANGLE", 2.0, 1.0
    panel.data.energy = 300.0
    panel.location = (0, 1, 3)
    panel.rotation_euler = (math.radians(-20), 0, 0)
    scene.collection.objects.link(panel)
    scene.frame_set(FRAMES[0])
    return scene


def settings_for(scene, out, mode, view):
    s = scene.pmr_lightfield
    s.preset = "lg-portrait"
    s.views = VIEWS
    s.view_width, s.view_height = view
    s.samples = "4"
    s.output_dir = out
    s.mode = mode
    s.write = "QUILT"
    s.environment = "WORLD"
    return s


def run_operator(ops_module):
    try:
        result = bpy.ops.pmr.render_lightfield()
    except RuntimeError as e:  # an ERROR report raises in background mode
        result = str(e)
    r = ops_module.last_result
    if result != {"FINISHED"}:
        fail("the operator returned %s; pmr %s exited %s: %s\n%s" % (
            result, r.get("argv"), r.get("returncode"), r.get("errors"), "\n".join(r.get("log", []))))
    return r


# ---- checks -------------------------------------------------------------------------------------

def read_sidecar(out, frame):
    path = os.path.join(out, "frame_%04d.json" % frame)
    check(os.path.isfile(path), "missing sidecar %s" % path)
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def check_quilt(out, frame, sidecar):
    """The quilt exists, its name says its layout, its size is columns x rows views."""
    q = sidecar["quilt"]
    name = sidecar["outputs"].get("quilt")
    check(name and os.path.isfile(os.path.join(out, name)), "frame %d: no quilt file" % frame)
    check("_qs%dx%da" % (q["columns"], q["rows"]) in name, "quilt name %s lacks its layout" % name)
    check(q["columns"] * q["rows"] >= VIEWS, "quilt layout %dx%d holds fewer than %d views"
          % (q["columns"], q["rows"], VIEWS))
    check((q["tile_width"], q["tile_height"]) == SEQ_VIEW, "tile size %dx%d, asked %dx%d"
          % (q["tile_width"], q["tile_height"], *SEQ_VIEW))
    img = bpy.data.images.load(os.path.join(out, name))
    want = (q["columns"] * q["tile_width"], q["rows"] * q["tile_height"])
    check(tuple(img.size) == want, "quilt %s is %s, expected %s" % (name, tuple(img.size), want))
    return img


# Blender (x, y, z) -> glTF (x, z, -y): the exporter's Y-up conversion.
Y_UP = Matrix(((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), (0, 0, 0, 1)))


def check_camera(sidecar, cam):
    """The center view matrix is the inverse of the camera's world matrix in glTF axes."""
    m = sidecar["center_view"]
    got = Matrix([[m[4 * c + r] for c in range(4)] for r in range(4)])
    want = (Y_UP @ cam.matrix_world).inverted()
    err = max(abs(got[r][c] - want[r][c]) for r in range(4) for c in range(4))
    check(err < 1e-4, "center view is not the active camera's (max error %.3g)\n%s\n%s"
          % (err, got, want))
    check(sidecar.get("camera") not in (-1, None), "the sidecar says no glTF camera was used")
    check(sidecar.get("camera_name", cam.name) == cam.name, "the sidecar's camera_name is %r, not %r"
          % (sidecar.get("camera_name"), cam.name))
    return err


def pixels(img):
    """(width, height, flat RGBA list, bottom row first)."""
    return img.size[0], img.size[1], list(img.pixels)


def patch_mean(img, x0, y0, w, h, cx, cy, frac=0.12):
    """Mean of R, G, B over a patch of frac x frac of the tile (x0, y0, w, h) centered on (cx, cy)
    in the tile's fractions (0..1, y up)."""
    width, _, px = pixels(img)
    pw, ph = max(1, int(w * frac)), max(1, int(h * frac))
    xs, ys = x0 + int(cx * w - pw / 2), y0 + int(cy * h - ph / 2)
    total, n = 0.0, 0
    for y in range(ys, ys + ph):
        for x in range(xs, xs + pw):
            i = 4 * (y * width + x)
            total += px[i] + px[i + 1] + px[i + 2]
            n += 3
    return total / n


def cycles_render(scene, path):
    """The camera's view with Cycles: linear EXR, Standard view transform, no denoiser."""
    plain_cycles(scene, 64)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return bpy.data.images.load(path)


def compare_center_view(scene, sidecar, out, work, what):
    """pmr's center view of `out` against Cycles' render of the camera: brightness ratios of three
    patches, each within LIGHT_TOLERANCE."""
    q = sidecar["quilt"]
    quilt = bpy.data.images.load(os.path.join(out, sidecar["outputs"]["quilt"]))
    center = VIEWS // 2
    col, row = center % q["columns"], center // q["columns"]  # view 0 bottom-left, rows upward
    tw, th = q["tile_width"], q["tile_height"]
    ref = cycles_render(scene, os.path.join(work, "cycles_%s.exr" % what.replace(" ", "_")))
    ratios = []
    for cx, cy in ((0.5, 0.5), (0.35, 0.6), (0.65, 0.4)):
        a = patch_mean(quilt, col * tw, row * th, tw, th, cx, cy)
        b = patch_mean(ref, 0, 0, *LIGHT_VIEW, cx, cy)
        check(b > 0.01, "Cycles' patch at %s is black (%g)" % ((cx, cy), b))
        ratios.append(a / b)
        log("%s patch at (%.2f, %.2f): pmr %.4f, Cycles %.4f, ratio %.4f" % (what, cx, cy, a, b, a / b))
    worst = max(abs(r - 1) for r in ratios)
    check(worst <= LIGHT_TOLERANCE, "%s: pmr / Cycles brightness ratios %s: off by %.1f%% (> %.0f%%)"
          % (what, ["%.4f" % r for r in ratios], 100 * worst, 100 * LIGHT_TOLERANCE))
    return ratios


def check_area_light(scene, ops_module, work):
    """The grey plane lit only by the area light (no shadow falls in the patches): pmr's center view
    against Cycles, seen from above as check_point_light."""
    for name in ("Mover", "Sun", "Bulb"):
        scene.objects[name].hide_render = True
    scene.objects["Panel"].hide_render = False
    out = os.path.join(work, "area")
    settings_for(scene, out, "STILL", LIGHT_VIEW)
    scene.frame_set(FRAMES[0])
    run_operator(ops_module)
    sidecar = read_sidecar(out, FRAMES[0])
    check([l["type"] for l in sidecar["shading"]["lights"]] == ["rect"],
          "expected only the area light, the sidecar lists %s" % sidecar["shading"]["lights"])
    return compare_center_view(scene, sidecar, out, work, "area light")


def check_shadow_catcher(scene, ops_module, work):
    """The panel's Shadow catcher reaches pmr as --ground shadow: the sidecar records the catcher, at
    or below the lowest point of the framed scene."""
    out = os.path.join(work, "catcher")
    settings_for(scene, out, "STILL", LIGHT_VIEW).shadow_catcher = True
    scene.frame_set(FRAMES[0])
    try:
        r = run_operator(ops_module)
    finally:
        scene.pmr_lightfield.shadow_catcher = False
    check("--ground" in r.get("argv", []), "the shadow catcher is not passed to pmr: %s" % r.get("argv"))
    sidecar = read_sidecar(out, FRAMES[0])
    ground = sidecar["shading"].get("ground")
    check(ground is not None and ground.get("kind") == "shadow", "pmr drew no shadow catcher: %s" % ground)
    low = sidecar["scene_bounds"]["min"][1]
    check(ground["height"] <= low, "the catcher (y = %g) is above the scene's lowest point (%g)"
          % (ground["height"], low))
    return ground["height"]


def srgb(c):
    c = min(max(c, 0.0), 1.0)
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1.0 / 2.4) - 0.055


def mean_srgb_difference(scene, sidecar, out, work, what):
    """pmr's center view against Cycles with direct light only (max bounces 0: what pmr computes):
    the mean |sRGB difference| over the pixels both cover (alpha above 0.99), and that count."""
    q = sidecar["quilt"]
    quilt = bpy.data.images.load(os.path.join(out, sidecar["outputs"]["quilt"]))
    center = VIEWS // 2
    col, row, tw, th = center % q["columns"], center // q["columns"], q["tile_width"], q["tile_height"]
    plain_cycles(scene, 128)
    scene.cycles.max_bounces = 0
    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = os.path.join(work, "cycles_%s.exr" % what)
    bpy.ops.render.render(write_still=True)
    ref = bpy.data.images.load(scene.render.filepath)
    qw, _, qp = pixels(quilt)
    rw, _, rp = pixels(ref)
    total, signed, level, clipped, n = 0.0, 0.0, 0.0, 0, 0
    for y in range(th):
        for x in range(tw):
            i, j = 4 * ((row * th + y) * qw + col * tw + x), 4 * (y * rw + x)
            if qp[i + 3] > 0.99 and rp[j + 3] > 0.99:
                total += sum(abs(srgb(qp[i + k]) - srgb(rp[j + k])) for k in range(3)) / 3.0
                signed += sum(srgb(qp[i + k]) - srgb(rp[j + k]) for k in range(3)) / 3.0
                level += sum(srgb(rp[j + k]) for k in range(3)) / 3.0
                clipped += max(rp[j:j + 3]) >= 1.0
                n += 1
    scene.cycles.max_bounces, scene.render.film_transparent = 12, False
    log("%s: Cycles' mean sRGB level %.3f (pmr - Cycles %+.4f), %d of %d pixels clipped at 1" % (
        what, level / max(n, 1), signed / max(n, 1), clipped, n))
    check(clipped < n // 10, "%s: %d of %d pixels are clipped: the comparison would see no difference" % (
        what, clipped, n))
    return total / max(n, 1), n


def check_scene_against_cycles(scene, ops_module, work, with_area):
    """The scene of objects on a ground plane, a sun, a point light and an HDRI world (Blender's
    forest.exr), with the 2 m x 1 m area light when `with_area`, through the add-on, against Cycles
    with direct light only, as DESIGN's quality goal measures it (docs/BLENDER.md)."""
    for name in ("Mover", "Sun", "Bulb", "Ground"):
        scene.objects[name].hide_render = False
    scene.objects["Panel"].hide_render = not with_area
    nodes, links = scene.world.node_tree.nodes, scene.world.node_tree.links
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(FOREST)
    link = links.new(tex.outputs["Color"], nodes["Background"].inputs["Color"])
    # dimmer lights and world than the light checks use, so that the grey ground stays below 1 (a clipped
    # pixel compares equal whatever the light)
    energies = {name: bpy.data.lights[name].energy for name in ("Sun", "Bulb", "Panel")}
    for name, k in SCENE_LIGHT_SCALE.items():
        bpy.data.lights[name].energy = energies[name] * k
    strength = nodes["Background"].inputs["Strength"]
    strength.default_value = SCENE_WORLD_STRENGTH
    what = "scene_area" if with_area else "scene"
    out = os.path.join(work, what)
    settings_for(scene, out, "STILL", SCENE_VIEW)
    scene.render.resolution_x, scene.render.resolution_y = SCENE_VIEW
    scene.frame_set(FRAMES[0])
    try:
        run_operator(ops_module)
        sidecar = read_sidecar(out, FRAMES[0])
        diff, n = mean_srgb_difference(scene, sidecar, out, work, what)
    finally:
        links.remove(link)
        nodes.remove(tex)
        strength.default_value = 1.0
        for name, e in energies.items():
            bpy.data.lights[name].energy = e
        scene.render.resolution_x, scene.render.resolution_y = LIGHT_VIEW
    limit = SCENE_TOLERANCE[with_area]
    log("%s: mean |sRGB difference| to Cycles (direct light) %.4f (%.1f/255) over %d pixels" % (
        "sun, point light, area light and HDRI" if with_area else "sun, point light and HDRI", diff, 255 * diff, n))
    check(n > SCENE_VIEW[0] * SCENE_VIEW[1] // 4, "pmr and Cycles cover only %d pixels in common" % n)
    check(diff <= limit / 255.0, "%s: mean |sRGB difference| %.1f/255 > %.1f/255" % (what, 255 * diff, limit))
    return diff


def check_point_light(scene, ops_module, work):
    """A grey plane lit only by the point light: pmr's center view against Cycles."""
    for name in ("Mover", "Sun", "Panel"):
        scene.objects[name].hide_render = True
    # Seen and lit from near the normal, where Cycles' Disney diffuse is Lambert's (its grazing
    # retro-reflection term vanishes); switching the active camera also tests that it is followed.
    # TopCam shares ShotCam's camera data (Alt+D in Blender): one glTF camera placed by two nodes,
    # so only the node's name (--camera NAME) tells them apart, not the camera's index or name
    top = bpy.data.objects.new("TopCam", scene.camera.data)
    scene.collection.objects.link(top)
    top.location = (0.0, -1.0, 6.0)
    look_at(top, (0, 0, 0))
    scene.camera = top
    out = os.path.join(work, "light")
    settings_for(scene, out, "STILL", LIGHT_VIEW)
    scene.frame_set(FRAMES[0])
    run_operator(ops_module)
    sidecar = read_sidecar(out, FRAMES[0])
    check_camera(sidecar, top)
    lights = sidecar["shading"]["lights"]
    check(len(lights) == 1, "expected only the point light, the sidecar lists %s" % lights)
    want_cd = 500.0 / (4 * math.pi)
    check(abs(lights[0]["intensity"] - want_cd) < 1e-3 * want_cd,
          "point light intensity %s cd, expected 500 W / 4 pi = %.4f" % (lights[0]["intensity"], want_cd))
    return compare_center_view(scene, sidecar, out, work, "point light")


def environment_image(path):
    """An equirectangular EXR, black but for a bright patch at Blender's image center (azimuth +-45
    degrees, elevation +-45 degrees), which Blender shows around +X."""
    w, h = 64, 32
    img = bpy.data.images.new("env_probe", w, h, float_buffer=True)
    px = []
    for y in range(h):  # bottom row first
        for x in range(w):
            bright = 0.375 <= (x + 0.5) / w <= 0.625 and 0.25 <= (y + 0.5) / h <= 0.75
            px += [4.0, 4.0, 4.0, 1.0] if bright else [0.0, 0.0, 0.0, 1.0]
    img.pixels = px
    img.filepath_raw, img.file_format = path, "OPEN_EXR"
    img.save()
    return path


def check_environment(scene, ops_module, work):
    """A grey cube lit only by a world HDRI bright toward +X: its +X and -Y faces in pmr against
    Cycles. An image turned wrongly by pmr (90 or 180 degrees) swaps which face is lit."""
    from bpy_extras.object_utils import world_to_camera_view
    for obj in scene.objects:
        obj.hide_render = obj.type != "CAMERA"
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0))
    probe = bpy.context.object
    probe.data.materials.append(bpy.data.materials["Grey"])
    scene.camera = scene.objects["ShotCam"]
    nodes, links = scene.world.node_tree.nodes, scene.world.node_tree.links
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(environment_image(os.path.join(work, "env_probe.exr")))
    links.new(tex.outputs["Color"], nodes["Background"].inputs["Color"])
    out = os.path.join(work, "env")
    settings_for(scene, out, "STILL", LIGHT_VIEW)
    run_operator(ops_module)
    sidecar = read_sidecar(out, FRAMES[0])
    check(sidecar["shading"]["environment"]["kind"] == "image", "pmr got no environment image: %s"
          % sidecar["shading"]["environment"])
    q = sidecar["quilt"]
    quilt = bpy.data.images.load(os.path.join(out, sidecar["outputs"]["quilt"]))
    center = VIEWS // 2
    col, row, tw, th = center % q["columns"], center // q["columns"], q["tile_width"], q["tile_height"]
    scene.cycles.samples = 128
    ref = cycles_render(scene, os.path.join(work, "cycles_env.exr"))
    result = {}
    for face, point in (("+X", (0.5, 0, 0)), ("-Y", (0, -0.5, 0))):
        uv = world_to_camera_view(scene, scene.camera, Vector(point))
        a = patch_mean(quilt, col * tw, row * th, tw, th, uv.x, uv.y, frac=0.06)
        b = patch_mean(ref, 0, 0, *LIGHT_VIEW, uv.x, uv.y, frac=0.06)
        result[face] = (a, b)
        log("environment: %s face pmr %.4f, Cycles %.4f" % (face, a, b))
    (px, cx), (py, cy) = result["+X"], result["-Y"]
    check(cx > 3 * cy, "Cycles does not light the +X face most (%.3f vs %.3f)" % (cx, cy))
    check(0.75 <= px / cx <= 1.25 and px > 3 * py,
          "pmr lights the cube from another side than Blender: +X %.3f / %.3f, -Y %.3f / %.3f "
          "(--environment-rotation)" % (px, cx, py, cy))


def check_backdrop(scene, ops_module, work):
    """Blender's film not transparent: pmr draws the world behind the scene (--background environment),
    opaque, in the world's colour where nothing covers it; a transparent film keeps pmr's transparent."""
    saved, hidden = scene.world, {obj.name: obj.hide_render for obj in scene.objects}
    for obj in scene.objects:  # the cube alone in front of the world
        obj.hide_render = obj.type != "CAMERA" and obj.name != "Mover"
    world = (0.2, 0.3, 0.5)
    scene.world = bpy.data.worlds.new("Plain")
    scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = world + (1.0,)
    out = os.path.join(work, "backdrop")
    settings_for(scene, out, "STILL", SEQ_VIEW)
    try:
        scene.render.film_transparent = False
        argv = run_operator(ops_module)["argv"]
        check(" --background environment" in " ".join(argv), "an opaque film does not reach pmr: %s" % argv)
        sidecar = read_sidecar(out, scene.frame_current)
        _, _, px = pixels(bpy.data.images.load(os.path.join(out, sidecar["outputs"]["quilt"])))
        opaque = all(px[i + 3] == 1.0 for i in range(0, len(px), 4))
        sky = sum(all(abs(px[i + c] - world[c]) <= 0.01 * world[c] for c in range(3)) for i in range(0, len(px), 4))
        scene.render.film_transparent = True
        argv = run_operator(ops_module)["argv"]
    finally:
        scene.world = saved
        scene.render.film_transparent = False
        for obj in scene.objects:
            obj.hide_render = hidden[obj.name]
    check(opaque, "the quilt over the world is not opaque")
    check(sky > len(px) // 4 // 2, "only %d of %d quilt pixels show the world's colour %s"
          % (sky, len(px) // 4, world))
    check("--background" not in argv, "a transparent film gave pmr a background: %s" % argv)
    return sky, len(px) // 4


def check_errors(scene, ops_module, work):
    """A missing pmr names the preference to set; pmr's own error lines reach Blender's reports."""
    prefs = bpy.context.preferences.addons[ADDON].preferences
    pmr, prefs.pmr_path = prefs.pmr_path, os.path.join(work, "no-such-pmr")
    settings_for(scene, os.path.join(work, "err"), "STILL", SEQ_VIEW)
    try:
        bpy.ops.pmr.render_lightfield()
        fail("a missing pmr did not raise an error report")
    except RuntimeError as e:
        check("Preferences" in str(e) and "pmr executable" in str(e),
              "the missing-pmr error does not say where to set the path: %s" % e)
    prefs.pmr_path = pmr
    scene.pmr_lightfield.extra_args = "--bogus-option"
    try:
        bpy.ops.pmr.render_lightfield()
        fail("pmr's error did not become an error report")
    except RuntimeError as e:
        check("unknown option --bogus-option" in str(e), "pmr's error line is not reported: %s" % e)
    scene.pmr_lightfield.extra_args = ""
    check(ops_module.last_result["returncode"] == 2, "pmr's usage error did not exit 2")


def check_names(scene, ops_module, work):
    """pmr alone names the files: a camera named "1" is that camera (not index 1), a file name pattern
    shot_%0d gives the files the add-on then finds, and an unbalanced quote in the extra options is a
    report, not a traceback."""
    cam = bpy.data.objects.new("1", bpy.data.cameras.new("One"))
    scene.collection.objects.link(cam)
    cam.location = (-4.0, -3.5, 2.5)
    look_at(cam, (0, 0, 0))
    bpy.context.view_layer.update()
    shot = scene.camera
    scene.camera = cam
    out = os.path.join(work, "names")
    s = settings_for(scene, out, "STILL", SEQ_VIEW)
    s.name = "shot_%0d"
    r = run_operator(ops_module)
    s.name = ""
    scene.camera = shot
    check(r["argv"][r["argv"].index("--camera") + 1] == "1", "pmr was not given --camera 1: %s" % r["argv"])
    frame = scene.frame_current
    check(list(r["outputs"]) == [frame], "the add-on found no outputs for shot_%%0d: %s" % r["outputs"])
    path = os.path.join(out, "shot_%d.json" % frame)
    check(os.path.isfile(path), "pmr did not write %s" % path)
    with open(path, encoding="utf-8") as f:
        sidecar = json.load(f)
    check(sidecar.get("camera_name") == "1", "the sidecar's camera is %r, not '1'" % sidecar.get("camera_name"))
    check_camera(sidecar, cam)
    s.extra_args = "--background '0,0,0"
    try:
        bpy.ops.pmr.render_lightfield()
        fail("an unbalanced quote in the extra options did not raise an error report")
    except RuntimeError as e:
        check("Extra options" in str(e), "the extra options' error does not say so: %s" % e)
    s.extra_args = ""
    bpy.data.objects.remove(cam)


def check_fps_base(scene, ops_module, work):
    """With fps 30 / 1.001 the kept export's key times are frame / 29.97 (the exporter alone writes
    frame / 30) and pmr gets --fps 29.97: pmr's frame F is Blender's frame F."""
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.keep_export = True
    scene.render.fps, scene.render.fps_base = 30, 1.001
    for obj in scene.objects:
        obj.hide_render = obj.name not in ("Mover", "Ground", "Sun", "ShotCam")
    scene.camera = scene.objects["ShotCam"]
    out = os.path.join(work, "fps")
    settings_for(scene, out, "STILL", SEQ_VIEW)
    run_operator(ops_module)
    fps = scene.render.fps / scene.render.fps_base  # fps_base is a float32: 1.00100004673
    prefs.keep_export = False
    scene.render.fps, scene.render.fps_base = 24, 1.0
    check(abs(read_sidecar(out, FRAMES[0])["fps"] - fps) < 1e-6, "pmr's fps is not 30 / 1.001")
    with open(os.path.join(out, "pmr_scene", "scene.gltf"), encoding="utf-8") as f:
        doc = json.load(f)
    acc = doc["accessors"][doc["animations"][0]["samplers"][0]["input"]]
    want = (FRAMES[0] / fps, FRAMES[1] / fps)
    got = (acc["min"][0], acc["max"][0])
    check(all(abs(g - w) < 1e-5 for g, w in zip(got, want)),
          "key times %s, expected frame / 29.97 = %s" % (got, want))


def check_colour_management(scene, ops_module, work):
    """Blender's own view (Filmic, a look, exposure, gamma; dither 0) of pmr's quilt EXR, saved by
    Blender as a PNG, equals pmr's quilt PNG within one 8-bit code wherever the quilt is covered."""
    out = os.path.join(work, "colour")
    settings_for(scene, out, "STILL", SEQ_VIEW)
    vs = scene.view_settings
    saved = (vs.view_transform, vs.look, vs.exposure, vs.gamma, scene.render.dither_intensity)
    vs.view_transform, vs.look, vs.exposure, vs.gamma = "Filmic", "High Contrast", 0.5, 1.2
    scene.render.dither_intensity = 0.0
    try:
        run_operator(ops_module)
        sidecar = read_sidecar(out, scene.frame_current)
        applied = sidecar.get("view_transform", {})
        check(applied.get("view") == "Filmic" and applied.get("look") == "High Contrast"
              and abs(applied.get("exposure", 0) - 0.5) < 1e-6 and abs(applied.get("gamma", 0) - 1.2) < 1e-6,
              "the view settings did not reach pmr: %s" % applied)
        exr = bpy.data.images.load(os.path.join(out, sidecar["outputs"]["quilt"]))
        fmt = scene.render.image_settings
        fmt.file_format, fmt.color_mode, fmt.color_depth = "PNG", "RGBA", "8"
        theirs_path = os.path.join(work, "colour_blender.png")
        exr.save_render(theirs_path, scene=scene)
        ours = list(bpy.data.images.load(os.path.join(out, sidecar["outputs"]["preview_quilt"])).pixels)
        theirs = list(bpy.data.images.load(theirs_path).pixels)
        linear = list(exr.pixels)
        check(len(ours) == len(theirs) == len(linear), "the PNGs and the EXR differ in size")
        worst, covered = 0.0, 0
        for i in range(0, len(linear), 4):
            if linear[i + 3] < 1.0:
                continue
            covered += 1
            worst = max(worst, max(abs(ours[i + c] - theirs[i + c]) for c in range(3)) * 255.0)
    finally:
        vs.view_transform, vs.look, vs.exposure, vs.gamma, scene.render.dither_intensity = saved
    check(covered > len(linear) // 40, "only %d covered pixels in the quilt" % covered)
    check(worst <= 1.0 + 1e-6, "pmr's quilt PNG differs from Blender's view of its EXR by %.1f codes" % worst)
    return worst, covered


def check_blender_sequence(out, sidecars):
    """Blender's own sequence logic (the last digit group of the file name is the frame) finds the
    quilt of every frame from the first file."""
    first = min(sidecars)
    img = bpy.data.images.load(os.path.join(out, sidecars[first]["outputs"]["quilt"]))
    img.source = "SEQUENCE"
    tex = bpy.data.textures.new("seq", "IMAGE")
    tex.image = img
    user = tex.image_user
    user.frame_start, user.frame_duration, user.frame_offset = first, len(sidecars), first - 1
    wrong = []
    for frame, sc in sorted(sidecars.items()):
        user.frame_current = frame
        got = os.path.basename(img.filepath_from_user(image_user=user))
        if got != sc["outputs"]["quilt"]:
            wrong.append("frame %d -> %s (pmr wrote %s)" % (frame, got, sc["outputs"]["quilt"]))
    check(not wrong, "Blender reads the quilt sequence wrongly: the frame number is not the last "
                     "digit group of pmr's quilt names: " + "; ".join(wrong))


def check_farm_names(pmr, work):
    """A farm's repair loop on a 12-frame quilt sequence: delete frames, `pmr verify` lists them, the
    list is rendered again with --resume; Blender's sequence reader then finds all 12 frames (the
    re-rendered ones keep the sequence's names, not a still's). Once for one frame, once for two."""
    out = os.path.join(work, "farm")
    args = ["--turntable", "360:12", "--views", "4", "--view-size", "32x32", "--display", "120x68",
            "--write", "quilt", "--out", out, "-q"]
    subprocess.run([pmr, "render", "--frames", "1:12"] + args, check=True)
    for deleted in ([5], [3, 8]):
        for name in os.listdir(out):
            if any("%04d" % f in name for f in deleted):
                os.remove(os.path.join(out, name))
        v = subprocess.run([pmr, "verify", out, "--frames", "1:12", "--write", "quilt"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        frames = v.stdout.strip()  # pmr's frame list, as --frames takes it: "5", "3,8", "3:5"
        listed = []
        for part in frames.replace(",", " ").split():
            first, _, last = part.partition(":")
            listed += list(range(int(first), int(last or first) + 1))
        check(v.returncode == 1 and listed == deleted, "pmr verify listed %r (exit %d) for deleted frames %s"
              % (frames, v.returncode, deleted))
        subprocess.run([pmr, "render", "--frames", frames, "--resume"] + args, check=True)
        sidecars = {f: read_sidecar(out, f) for f in range(1, 13)}
        check_blender_sequence(out, sidecars)
        log("farm: frames %s deleted, listed by verify, rendered again: Blender reads 12 frames" % frames)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--pmr", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args(argv)
    work = os.path.abspath(args.work)

    scene = build_scene()  # first: its factory reset would disable the add-on
    ops_module = install_addon(work, args.pmr)
    log("add-on installed and enabled from a zip")

    out = os.path.join(work, "seq")
    settings_for(scene, out, "SEQUENCE", SEQ_VIEW)
    r = run_operator(ops_module)
    log("sequence of %d frames rendered through the add-on in %.1f s" % (len(r["outputs"]), r["elapsed"]))
    check("--camera" in r["argv"] and r["argv"][r["argv"].index("--camera") + 1] == "ShotCam",
          "pmr was not given --camera ShotCam: %s" % r["argv"])
    check(not [w for w in r["warnings"] if "light" in w], "light warnings for an exportable scene: %s"
          % r["warnings"])
    sidecars = {f: read_sidecar(out, f) for f in range(FRAMES[0], FRAMES[1] + 1)}
    quilts = [check_quilt(out, f, sc) for f, sc in sidecars.items()]
    check(list(quilts[0].pixels) != list(quilts[-1].pixels),
          "the first and last quilts are identical: the animation did not play")
    log("3 quilts + sidecars, layout %(columns)dx%(rows)d of %(tile_width)dx%(tile_height)d, "
        "animation plays" % sidecars[FRAMES[0]]["quilt"])
    sun_data = bpy.data.lights["Sun"]
    recorded = [l for l in sidecars[FRAMES[0]]["shading"]["lights"] if l["type"] == "directional"]
    check(len(recorded) == 1 and abs(recorded[0].get("angle", 0.0) - sun_data.angle) < 1e-6,
          "the sun's angle (%g rad) does not reach pmr: %s" % (sun_data.angle, recorded))
    check(sidecars[FRAMES[0]]["shading"].get("shadows") is not None, "pmr rendered without shadows")
    areas = [l for l in sidecars[FRAMES[0]]["shading"]["lights"] if l["type"] == "rect"]
    check(len(areas) == 1 and abs(areas[0]["width"] - 2.0) < 1e-6 and abs(areas[0]["height"] - 1.0) < 1e-6,
          "the 2 m x 1 m area light does not reach pmr as a rect: %s" % areas)
    want = 300.0 / (4.0 * 2.0)  # Cycles' radiance of an area light of power P and area A: P / (4 A)
    check(abs(areas[0]["intensity"] - want) < 1e-3 * want, "area light luminance %s, expected P / (4 A) = %g"
          % (areas[0]["intensity"], want))
    log("the area light reaches pmr as EXT_lights_area (2 m x 1 m, %g nits)" % want)
    log("the sun's angle reaches pmr (%g rad: soft shadows)" % sun_data.angle)
    err = check_camera(sidecars[FRAMES[0]], scene.camera)
    log("center view = the active camera (max error %.2g)" % err)

    height = check_shadow_catcher(scene, ops_module, work)
    log("the shadow catcher reaches pmr (--ground shadow at y = %.4g)" % height)

    check_point_light(scene, ops_module, work)
    log("point light matches Cycles within %.0f%%" % (100 * LIGHT_TOLERANCE))

    check_area_light(scene, ops_module, work)
    log("area light matches Cycles within %.0f%%" % (100 * LIGHT_TOLERANCE))

    if os.path.isfile(FOREST):
        check_scene_against_cycles(scene, ops_module, work, False)
        check_scene_against_cycles(scene, ops_module, work, True)
    else:
        log("skipped the whole-scene comparison: %s is missing" % FOREST)

    sky, total = check_backdrop(scene, ops_module, work)
    log("an opaque film: pmr draws the world behind the scene (%d of %d quilt pixels in its colour)" % (sky, total))

    check_environment(scene, ops_module, work)
    log("the world's HDRI lights the cube from the side Blender shows it")

    check_errors(scene, ops_module, work)
    log("a missing pmr names its preference; pmr's error lines become error reports")

    check_names(scene, ops_module, work)
    log("a camera named 1, the pattern shot_%0d and a bad quote in the extra options")

    check_fps_base(scene, ops_module, work)
    log("fps 30 / 1.001: pmr --fps 29.97, the exported key times frame / 29.97")

    worst, covered = check_colour_management(scene, ops_module, work)
    log("the quilt PNG is Blender's own view (Filmic, High Contrast, exposure 0.5, gamma 1.2) of the "
        "quilt EXR within %.2g codes over %d covered pixels" % (worst, covered))

    check_blender_sequence(out, sidecars)
    log("Blender reads the quilt sequence as frames %d..%d" % FRAMES)

    check_farm_names(args.pmr, work)
    log("PASSED")


if __name__ == "__main__":
    try:
        main()
    except BaseException:
        traceback.print_exc()
        fail("exception (above)")
    sys.stdout.flush()
    os._exit(0)
