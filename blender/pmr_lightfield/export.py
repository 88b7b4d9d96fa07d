"""Exporting the scene for pmr: glTF with cameras, lights and animation, and the world as an image."""

import array
import json
import math
import os
import struct

import bpy

SCENE_FILE = "scene.gltf"

# Blender's glTF exporter in 3.4 converts lights with 'SPEC' by default: point and spot lights come out
# 683 times brighter (lm per W) than Blender renders them. 'COMPAT' writes W / (4 pi) for point and
# spot and W / m^2 for sun, which are the units pmr's shading and Cycles agree on.
LIGHTING_MODE = "COMPAT"


def export_gltf(folder):
    """Writes folder/scene.gltf (+ .bin and textures); returns its path."""
    path = os.path.join(folder, SCENE_FILE)
    options = dict(
        filepath=path,
        export_format="GLTF_SEPARATE",  # plain JSON: pmr reads it, and so can the light fix below
        export_cameras=True,
        export_lights=True,
        use_renderable=True,  # what the render would show: hide_render objects stay out
        export_apply=True,  # modifiers applied, as rendered
        export_animations=True,
        export_yup=True,
        check_existing=False,
    )
    has_mode = "convert_lighting_mode" in bpy.ops.export_scene.gltf.get_rna_type().properties
    if has_mode:
        options["convert_lighting_mode"] = LIGHTING_MODE
    result = bpy.ops.export_scene.gltf(**options)
    if "FINISHED" not in result or not os.path.exists(path):
        raise RuntimeError("the glTF export failed (see the console)")
    if not has_mode:
        _edit_json(path, _rewrite_light_intensities)
    _edit_json(path, _add_light_sizes)
    return path


# Blender is Z-up, glTF Y-up: glTF (x, y, z) = Blender (x, z, -y), a rotation.
_TO_GLTF = ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0))


def _to_gltf(v):
    return [sum(_TO_GLTF[r][c] * v[c] for c in range(3)) for r in range(3)]


def area_light_entry(obj):
    """EXT_lights_area's light and node for a Blender area light object at the current frame, and the
    warnings it needs: (light, node, warnings). The node carries the object's world position and
    rotation turned to glTF's Y-up (a light's -Z shines along Blender's -Z, as in glTF), and no scale:
    the object's scale is multiplied into the size. Luminance L = P / (4 A) for power P (W) over the
    area A: the radiance Cycles gives an area light (P / (pi A) rendered 4 / pi = 1.27 times brighter
    than Cycles in tests/blender/test_addon.py), in the units convention of the point lights (W / (4 pi)
    as candela: what Cycles shows)."""
    data, warnings = obj.data, []
    loc, rot, scale = obj.matrix_world.decompose()
    height = data.size_y if data.shape in ("RECTANGLE", "ELLIPSE") else data.size
    sx, sy = abs(data.size * scale.x), abs(height * scale.y)
    shape = data.shape
    if shape == "DISK" and abs(sx - sy) > 1e-6 * max(sx, sy):
        shape = "ELLIPSE"  # a disk under non-uniform scale
    if shape == "ELLIPSE":
        # the rect of the same area and aspect
        warnings.append("light %s: an ellipse is exported as the rect of its area and aspect" % obj.name)
        sx, sy = sx * math.sqrt(math.pi) / 2.0, sy * math.sqrt(math.pi) / 2.0
        shape = "RECTANGLE"
    if getattr(data, "spread", math.pi) < math.pi - 1e-6:
        warnings.append("light %s: a spread of %.0f degrees is not carried (pmr's area lights emit over "
                        "the whole half space)" % (obj.name, math.degrees(data.spread)))
    disk = shape == "DISK"
    area = math.pi * sx * sx / 4.0 if disk else sx * sy
    if not area > 0.0:
        return None, None, ["light %s has no area: not exported" % obj.name]
    light = {"name": obj.name, "type": "disk" if disk else "rect", "color": list(data.color),
             "intensity": max(data.energy, 0.0) / (4.0 * area), "size": sx if disk else sy}
    if not disk:
        light["rect"] = {"aspect": sx / sy}
    # C R: the light's local axes in glTF's world (its node's local frame stays Blender's local one)
    m = rot.to_matrix()
    g = [[sum(_TO_GLTF[r][k] * m[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
    node = {"name": obj.name, "translation": _to_gltf(loc), "rotation": _quaternion(g)}
    return light, node, warnings


def _quaternion(m):
    """The unit quaternion [x, y, z, w] of the rotation matrix m (rows)."""
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0.0:
        s = 2.0 * math.sqrt(t + 1.0)
        return [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(max(1.0 + m[i][i] - m[j][j] - m[k][k], 1e-30))
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return q


def add_area_lights(path, scene, view_layer):
    """Writes the rendered area lights into the exported .gltf as EXT_lights_area lights on nodes of
    their own (Blender 3.4's exporter has no such extension); returns the warnings."""
    objs = [o for o in scene.objects if o.type == "LIGHT" and o.data.type == "AREA" and not o.hide_render
            and o.name in view_layer.objects]
    if not objs:
        return []
    warnings = []

    def edit(doc):
        ext = doc.setdefault("extensions", {}).setdefault("EXT_lights_area", {"lights": []})
        for obj in objs:
            light, node, more = area_light_entry(obj)
            warnings.extend(more)
            if light is None:
                continue
            node["extensions"] = {"EXT_lights_area": {"light": len(ext["lights"])}}
            ext["lights"].append(light)
            doc.setdefault("nodes", []).append(node)
            doc["scenes"][doc.get("scene", 0)].setdefault("nodes", []).append(len(doc["nodes"]) - 1)
        used = doc.setdefault("extensionsUsed", [])
        if "EXT_lights_area" not in used:
            used.append("EXT_lights_area")
        return True

    _edit_json(path, edit)
    return warnings


def _edit_json(path, edit):
    """Applies edit(doc) to the .gltf; rewrites the file when edit returns True."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    if edit(doc):
        with open(path, "w", encoding="utf-8") as f:
            json.dump(doc, f)


def _rewrite_light_intensities(doc):
    """For exporters without convert_lighting_mode: intensities from the Blender lights, by name."""
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for light in lights:
        data = bpy.data.lights.get(light.get("name", ""))
        if data is not None:
            light["intensity"] = data.energy / (1.0 if data.type == "SUN" else 4.0 * math.pi)
    return bool(lights)


def _add_light_sizes(doc):
    """Each light's size as pmr reads it (docs/SHADING.md, "Shadows"): a point or spot light's
    radius as extras.pmr_radius, a sun's angle as extras.pmr_angle; they soften its shadows as in
    Cycles. glTF's KHR_lights_punctual has neither. The lights are found by name, as above."""
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    changed = False
    for light in lights:
        data = bpy.data.lights.get(light.get("name", ""))
        if data is None:
            continue
        size = data.angle if data.type == "SUN" else getattr(data, "shadow_soft_size", 0.0)
        if size > 0.0 and data.type in ("SUN", "POINT", "SPOT"):
            light.setdefault("extras", {})["pmr_angle" if data.type == "SUN" else "pmr_radius"] = float(size)
            changed = True
    return changed


def has_animations(path):
    with open(path, encoding="utf-8") as f:
        return bool(json.load(f).get("animations"))


def retime_animations(path, factor):
    """Multiplies every animation key time of the exported .gltf by factor, in its .bin.

    The 3.4 exporter writes frame f at f / scene.render.fps, ignoring fps_base; pmr samples frame f at
    f / --fps. With factor = fps_base and --fps = fps / fps_base both give frame f the same time."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    inputs = {s["input"] for a in doc.get("animations", []) for s in a["samplers"]}
    folder = os.path.dirname(path)
    for index in sorted(inputs):
        acc = doc["accessors"][index]
        view = doc["bufferViews"][acc["bufferView"]]
        bin_path = os.path.join(folder, doc["buffers"][view["buffer"]]["uri"])
        offset = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        times = array.array("f")
        with open(bin_path, "r+b") as f:
            f.seek(offset)
            times.frombytes(f.read(4 * acc["count"]))
            times = array.array("f", (t * factor for t in times))
            f.seek(offset)
            f.write(times.tobytes())  # float32, little-endian like glTF on every machine Blender runs on
        acc["min"], acc["max"] = [min(times)], [max(times)]
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f)


# ---- the world ----------------------------------------------------------------------------------

def _background_node(world):
    """The Background node feeding the world's active output, or None."""
    if world is None or not world.use_nodes or world.node_tree is None:
        return None
    for node in world.node_tree.nodes:
        if node.type == "OUTPUT_WORLD" and node.is_active_output:
            link = node.inputs["Surface"].links
            if link and link[0].from_node.type == "BACKGROUND":
                return link[0].from_node
    return None


def world_environment(world, folder):
    """pmr's environment options for the world: (arguments, warnings).

    An Environment Texture image becomes --environment FILE (turned to Blender's orientation, see
    environment_rotation), a plain colour a small constant image, a black or missing world none."""
    node = _background_node(world)
    if node is None:
        return ["--environment-intensity", "0"], []
    strength = node.inputs["Strength"].default_value
    color_in = node.inputs["Color"]
    if color_in.links:
        tex = color_in.links[0].from_node
        if tex.type == "TEX_ENVIRONMENT" and tex.image is not None:
            image_path, warnings = _environment_file(tex.image, folder)
            args = ["--environment", image_path,
                    "--environment-rotation", "%.6g" % environment_rotation(tex),
                    "--environment-intensity", "%.6g" % strength]
            return args, warnings
        return ["--environment-intensity", "0"], [
            "the world's colour comes from a %s node, which pmr cannot use: no environment light"
            % tex.bl_label]
    rgb = [c * strength for c in color_in.default_value[:3]]
    if max(rgb) <= 0.0:
        return ["--environment-intensity", "0"], []
    path = os.path.join(folder, "world_color.exr")
    _write_exr(path, 8, 4, list(rgb) + [1.0])
    return ["--environment", path], []


def environment_rotation(tex):
    """pmr's --environment-rotation (degrees) that shows an equirectangular image as Blender does.

    Blender reads direction d at u = 1/2 + atan2(z, x) / (2 pi) in glTF axes (its image center looks
    along +X), pmr at u = 1/2 + atan2(x, -z) / (2 pi) (center along -Z): pmr must turn the image by
    -90 degrees (its rotation is counter-clockwise seen from above). A Mapping node's Z rotation r
    turns Blender's lookup vector, which moves the image the other way."""
    rz = 0.0
    vec = tex.inputs["Vector"].links
    if vec and vec[0].from_node.type == "MAPPING":
        rz = vec[0].from_node.inputs["Rotation"].default_value[2]
    return -90.0 - math.degrees(rz)


def _environment_file(image, folder):
    """A file pmr can read for the image: its own .hdr/.exr, or a float EXR copy."""
    path = bpy.path.abspath(image.filepath, library=image.library) if image.filepath else ""
    ext = os.path.splitext(path)[1].lower()
    if not image.packed_file and ext in (".hdr", ".exr") and os.path.isfile(path):
        return os.path.abspath(path), []
    width, height = image.size
    if width == 0 or height == 0:
        raise RuntimeError("the world's image %r has no pixels" % image.name)
    copy = os.path.join(folder, "world.exr")
    _write_exr(copy, width, height, list(image.pixels))
    warnings = []
    if ext not in (".hdr", ".exr"):
        warnings.append("the world's image %r is not HDR: pmr gets its pixels as linear values"
                        % image.name)
    return copy, warnings


def _write_exr(path, width, height, rgba):
    """A float RGB EXR (uncompressed scanlines) of the linear values as given; rgba is the pixels bottom
    row first (a single RGBA fills the image). Written here rather than by Image.save(), which writes a
    generated float image through the sRGB curve (a world colour of 0.2 became 0.48)."""
    if len(rgba) == 4:
        rgba = list(rgba) * (width * height)

    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    window = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attribute("channels", "chlist", channels) +
              attribute("compression", "compression", b"\0") + attribute("dataWindow", "box2i", window) +
              attribute("displayWindow", "box2i", window) + attribute("lineOrder", "lineOrder", b"\0") +
              attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attribute("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0)) +
              attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line_bytes = 8 + 3 * 4 * width
    first = len(header) + 8 * height
    body = []
    for y in range(height):  # EXR's row 0 is the top one
        row = rgba[4 * width * (height - 1 - y):4 * width * (height - y)]
        data = b"".join(struct.pack("<%df" % width, *row[c::4]) for c in (2, 1, 0))
        body.append(struct.pack("<ii", y, len(data)) + data)
    offsets = struct.pack("<%dQ" % height, *(first + y * line_bytes for y in range(height)))
    with open(path, "wb") as f:
        f.write(header + offsets + b"".join(body))
