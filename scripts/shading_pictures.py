#!/usr/bin/env python3
"""Turns views that `pmr render --write views` wrote into the PNG pictures of docs/SHADING.md.

Driven by scripts/make_shading_pictures.sh; Python standard library only (struct, zlib).

  shading_pictures.py strip OUT.png PANEL [PANEL ...] [--mark] [--check-center PNG ...]
      PANEL is VIEWS.exr:VIEW (a part of a views file). The panels are cropped to the union of the
      pixels any of them covers (alpha > 0) plus a margin, laid side by side on a grey background
      and written as an 8-bit sRGB PNG. The colours are converted as `pmr render --preview` does
      (linear half -> sRGB, clamped, rounded), so a panel is the renderer's preview of that view.
      --mark ticks each panel's brightest pixel in the margin (its column above and below, its row
      left and right) and prints its position in the view, in pixels from the top-left: the largest
      G, the first in row order on ties, as Pbr.SpecularHighlightMovesWithTheViews finds it.
      --check-center PNG (one per panel, in order; '-' skips one) compares a panel's conversion with
      the center-view preview the renderer wrote for it, byte for byte, and stops on a difference:
      it checks this reader against the renderer's own conversion.

  shading_pictures.py sphere OUT.glb
      A unit sphere of a glossy gold metal (the default scene's Gold, base (0.95, 0.58, 0.1),
      metallic 1, roughness 0.2 instead of 0.3), 128 x 64 segments, for the highlight picture.

  shading_pictures.py arealight OUT.glb ROUGHNESS
      A grey floor of that roughness with a ball and a pole on it, lit only by a rect area light
      (EXT_lights_area) behind them, turned toward the camera: its highlight on the floor and the
      soft shadows, for the area light pictures.

Reads scanline EXR files, single- or multi-part, uncompressed or ZIP/ZIPS, with half R, G, B, A
channels (what `pmr render` writes); anything else stops with one line.
"""
import struct
import sys
import zlib

BACKGROUND = (200, 200, 200)  # the pictures' background where no view covers a pixel (sRGB bytes)
MARGIN = 12  # pixels kept around the covered area
GAP = 6  # pixels between panels, a darker grey
GAP_COLOUR = (150, 150, 150)
MARK = (200, 0, 0)  # the highlight's ticks


def fail(message):
    sys.exit("shading_pictures: " + message)


# ---- EXR (the subset pmr writes) --------------------------------------------------------------


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def _read_header(data, pos):
    attrs = {}
    while data[pos] != 0:
        name, pos = _cstring(data, pos)
        kind, pos = _cstring(data, pos)
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        attrs[name] = (kind, data[pos:pos + size])
        pos += size
    return attrs, pos + 1


def _channels(raw):
    channels, pos = [], 0
    while raw[pos] != 0:
        name, pos = _cstring(raw, pos)
        (pixel_type,) = struct.unpack_from("<i", raw, pos)
        xs, ys = struct.unpack_from("<ii", raw, pos + 8)
        channels.append((name, pixel_type, xs, ys))
        pos += 16
    return channels


def read_exr_part(path, view):
    """(width, height, rows) of the part whose pmrView (or position) is view; rows[y] is a list of
    (r, g, b, a) floats."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        fail(f"{path}: not an OpenEXR file")
    (flags,) = struct.unpack_from("<i", data, 4)
    if flags & 0x200 or flags & 0x800:
        fail(f"{path}: tiled or deep EXR files are not read here")
    multipart = bool(flags & 0x1000)
    pos, headers = 8, []
    while True:
        header, pos = _read_header(data, pos)
        headers.append(header)
        if not multipart or data[pos] == 0:
            break
    if multipart:
        pos += 1
    layouts = []
    for h in headers:
        xmin, ymin, xmax, ymax = struct.unpack("<4i", h["dataWindow"][1])
        compression = h["compression"][1][0]
        lines = {0: 1, 2: 1, 3: 16}.get(compression)
        if lines is None:
            fail(f"{path}: compression {compression} is not read here (use none or zip)")
        chunks = struct.unpack("<i", h["chunkCount"][1])[0] if "chunkCount" in h else \
            (ymax - ymin + lines) // lines
        layouts.append((xmin, ymin, xmax, ymax, compression, lines, chunks, pos))
        pos += 8 * chunks
    index = None
    for i, h in enumerate(headers):
        tagged = struct.unpack("<i", h["pmrView"][1])[0] if "pmrView" in h else i
        if tagged == view:
            index = i
    if index is None:
        fail(f"{path}: no part holds view {view}")
    h = headers[index]
    xmin, ymin, xmax, ymax, compression, lines, chunks, table = layouts[index]
    channels = _channels(h["channels"][1])
    names = [c[0] for c in channels]
    for c in channels:
        if c[1] != 1 or c[2] != 1 or c[3] != 1:
            fail(f"{path}: channel {c[0]} is not an unsampled half channel")
    for want in "RGBA":
        if want not in names:
            fail(f"{path}: view {view} has no {want} channel")
    width, height = xmax - xmin + 1, ymax - ymin + 1
    rows = [None] * height
    offsets = struct.unpack_from(f"<{chunks}Q", data, table)
    for offset in offsets:
        p = offset + (4 if multipart else 0)
        y, size = struct.unpack_from("<ii", data, p)
        block = data[p + 8:p + 8 + size]
        count = min(lines, ymax + 1 - y)
        expected = count * width * 2 * len(channels)
        if compression != 0 and size < expected:
            raw = bytearray(zlib.decompress(block))
            for i in range(1, len(raw)):  # undo the predictor, then the byte interleaving
                raw[i] = (raw[i - 1] + raw[i] - 128) & 0xFF
            half = (len(raw) + 1) // 2
            block = bytearray(len(raw))
            block[0::2], block[1::2] = raw[:half], raw[half:]
        if len(block) != expected:
            fail(f"{path}: chunk at line {y} has {len(block)} bytes, expected {expected}")
        values = struct.unpack(f"<{len(block) // 2}e", block)
        for k in range(count):
            base = k * width * len(channels)
            plane = {n: values[base + i * width: base + (i + 1) * width] for i, n in enumerate(names)}
            rows[y - ymin + k] = list(zip(plane["R"], plane["G"], plane["B"], plane["A"]))
    if any(r is None for r in rows):
        fail(f"{path}: view {view} is missing lines")
    return width, height, rows


# ---- PNG ------------------------------------------------------------------------------------


def _chunk(kind, payload):
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))


def write_png(path, width, height, pixels):
    """pixels: bytes of RGB rows. Each row filtered with Paeth (the best of the five on these
    pictures' flat backgrounds and smooth shading), deflate level 9; marked sRGB as pmr's are."""
    stride = 3 * width
    out = bytearray()
    prev = bytes(stride)
    for y in range(height):
        row = pixels[y * stride:(y + 1) * stride]
        out.append(4)
        for i in range(stride):
            a = row[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out.append((row[i] - pred) & 0xFF)
        prev = row
    png = b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += _chunk(b"sRGB", b"\x00") + _chunk(b"IDAT", zlib.compress(bytes(out), 9)) + _chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def read_png_rgba(path):
    """The renderer's preview: 8-bit RGBA, not interlaced."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path}: not a PNG file")
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        kind = data[pos + 4:pos + 8]
        payload = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", payload)
            if depth != 8 or colour != 6 or interlace != 0:
                fail(f"{path}: not an 8-bit RGBA PNG without interlacing")
        elif kind == b"IDAT":
            idat += payload
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = 4 * width
    out, prev = bytearray(), bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = row[i - 4] if i >= 4 else 0
            b = prev[i]
            c = prev[i - 4] if i >= 4 else 0
            if kind == 1:
                row[i] = (row[i] + a) & 0xFF
            elif kind == 2:
                row[i] = (row[i] + b) & 0xFF
            elif kind == 3:
                row[i] = (row[i] + (a + b) // 2) & 0xFF
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 0xFF
        out += row
        prev = row
    return width, height, bytes(out)


# ---- the conversion pmr's previews use (host/output/png_output.cpp) ------------------------------


def _srgb_byte(x):
    if not x > 0.0:
        return 0
    if x >= 1.0:
        return 255
    v = 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1.0 / 2.4) - 0.055
    return int(min(1.0, max(0.0, v)) * 255.0 + 0.5)  # std::lround of a non-negative value


_LUT = {}


def to_srgb(x):
    b = _LUT.get(x)
    if b is None:
        b = _LUT[x] = _srgb_byte(x)
    return b


def view_bytes(rows):
    """RGBA bytes exactly as `pmr render --preview` writes the view: straight alpha, so a partly
    covered pixel's premultiplied colour is divided by its coverage first."""
    out = bytearray()
    for row in rows:
        for r, g, b, a in row:
            if 0.0 < a < 1.0:
                out += bytes((_srgb_byte(r / a), _srgb_byte(g / a), _srgb_byte(b / a), _alpha_byte(a)))
            else:
                out += bytes((to_srgb(r), to_srgb(g), to_srgb(b), _alpha_byte(a)))
    return bytes(out)


def _linear(byte):
    v = byte / 255.0
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def over_background(r, g, b, a):
    """sRGB bytes of a premultiplied pixel composited over the background, in linear light."""
    return bytes(_srgb_byte(c + (1.0 - a) * _linear(k)) for c, k in zip((r, g, b), BACKGROUND))


def _alpha_byte(a):
    return int(min(1.0, max(0.0, a)) * 255.0 + 0.5)


# ---- the pictures -----------------------------------------------------------------------------


def brightest(rows):
    best, at = -1.0, None
    for y, row in enumerate(rows):
        for x, (_, g, _, a) in enumerate(row):
            if a > 0.0 and g > best:
                best, at = g, (x, y)
    return at, best


def strip(out_path, panels, mark, checks):
    views = []
    for i, panel in enumerate(panels):
        path, _, view = panel.rpartition(":")
        if not path or not view.isdigit():
            fail(f"panel '{panel}': expected VIEWS.exr:VIEW")
        width, height, rows = read_exr_part(path, int(view))
        if checks and checks[i] != "-":
            cw, ch, want = read_png_rgba(checks[i])
            if (cw, ch) != (width, height) or want != view_bytes(rows):
                fail(f"{path} view {view} converts differently from the renderer's preview {checks[i]}")
            print(f"{panel}: the same bytes as {checks[i]}")
        views.append((panel, width, height, rows))
    if len({(w, h) for _, w, h, _ in views}) != 1:
        fail("the panels differ in size")
    width, height = views[0][1], views[0][2]
    covered = [(x, y) for _, _, _, rows in views for y, row in enumerate(rows) for x, p in enumerate(row) if p[3] > 0.0]
    if not covered:
        fail("the panels are empty")
    x0 = max(0, min(x for x, _ in covered) - MARGIN)
    x1 = min(width - 1, max(x for x, _ in covered) + MARGIN)
    y0 = max(0, min(y for _, y in covered) - MARGIN)
    y1 = min(height - 1, max(y for _, y in covered) + MARGIN)
    cw, ch = x1 - x0 + 1, y1 - y0 + 1
    total_w = len(views) * cw + (len(views) - 1) * GAP
    canvas = bytearray(bytes(BACKGROUND) * (total_w * ch))
    for k in range(1, len(views)):
        for y in range(ch):
            o = 3 * (y * total_w + k * (cw + GAP) - GAP)
            canvas[o:o + 3 * GAP] = bytes(GAP_COLOUR) * GAP
    for k, (panel, _, _, rows) in enumerate(views):
        left = k * (cw + GAP)
        for y in range(ch):
            for x in range(cw):
                r, g, b, a = rows[y0 + y][x0 + x]
                if a > 0.0:  # edges are partly covered (pmr's samples per pixel): composited
                    o = 3 * (y * total_w + left + x)
                    canvas[o:o + 3] = bytes((to_srgb(r), to_srgb(g), to_srgb(b))) if a >= 1.0 else over_background(r, g, b, a)
        if mark:
            (hx, hy), value = brightest(rows)
            print(f"{panel}: brightest pixel ({hx}, {hy}), G = {value:.3f}")
            # ticks in the margin at the pixel's column and row: the highlight itself is many pixels
            # of clipped white, which a mark on top would hide
            for t in range(MARGIN - 4):
                for w in (-1, 0, 1):
                    for x, y in ((hx - x0 + w, t), (hx - x0 + w, ch - 1 - t), (t, hy - y0 + w), (cw - 1 - t, hy - y0 + w)):
                        if 0 <= x < cw and 0 <= y < ch:
                            o = 3 * (y * total_w + left + x)
                            canvas[o:o + 3] = bytes(MARK)
    write_png(out_path, total_w, ch, canvas)
    print(f"wrote {out_path}: {total_w}x{ch} (panels of {cw}x{ch} from ({x0}, {y0}) of the {width}x{height} views)")


def _uv_sphere(seg_u=128, seg_v=64):
    """A unit UV sphere: its positions (= normals) and triangle indices."""
    import math

    positions, indices = [], []
    for j in range(seg_v + 1):
        theta = math.pi * j / seg_v
        for i in range(seg_u + 1):
            phi = 2.0 * math.pi * i / seg_u
            positions.append((math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi)))
    for j in range(seg_v):
        for i in range(seg_u):
            a, b = j * (seg_u + 1) + i, (j + 1) * (seg_u + 1) + i
            if j > 0:
                indices += [a, b, a + 1]
            if j < seg_v - 1:
                indices += [a + 1, b, b + 1]
    return positions, indices


def _write_glb(out_path, gltf, meshes):
    """Writes gltf as a .glb whose buffer holds `meshes` [(positions, normals, indices)], adding their
    buffer views and accessors (POSITION, NORMAL, indices: 3 a mesh, in order) and primitives' attributes."""
    import json

    binary, views, accessors = b"", [], []
    for k, (positions, normals, indices) in enumerate(meshes):
        for data, kind in ((positions, "POSITION"), (normals, "NORMAL"), (indices, "indices")):
            index = kind == "indices"
            raw = struct.pack(f"<{len(data)}H", *data) if index else b"".join(struct.pack("<3f", *p) for p in data)
            views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(raw),
                          "target": 34963 if index else 34962})
            acc = {"bufferView": len(views) - 1, "componentType": 5123 if index else 5126, "count": len(data),
                   "type": "SCALAR" if index else "VEC3"}
            if kind == "POSITION":  # required by glTF
                acc["min"] = [float(min(p[c] for p in data)) for c in range(3)]
                acc["max"] = [float(max(p[c] for p in data)) for c in range(3)]
            accessors.append(acc)
            binary += raw + b"\0" * (-len(raw) % 4)
        gltf["meshes"][k]["primitives"][0].update(
            {"attributes": {"POSITION": 3 * k, "NORMAL": 3 * k + 1}, "indices": 3 * k + 2})
    gltf.update({"buffers": [{"byteLength": len(binary)}], "bufferViews": views, "accessors": accessors})
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    with open(out_path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)


def sphere(out_path, base, metallic, roughness):
    """A unit UV sphere (128 x 64 segments, smooth normals) of one material, as a .glb."""
    positions, indices = _uv_sphere()
    gltf = {
        "asset": {"version": "2.0", "generator": "pmr scripts/shading_pictures.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"material": 0}]}],
        "materials": [{"name": "GlossyMetal", "pbrMetallicRoughness": {
            "baseColorFactor": list(base) + [1.0], "metallicFactor": metallic, "roughnessFactor": roughness}}],
    }
    _write_glb(out_path, gltf, [(positions, positions, indices)])  # on a unit sphere, normal = position


def _light_rotation(tilt):
    """The quaternion [x, y, z, w] turning -Z half a turn about Y (toward +Z), then by `tilt` about X."""
    import math

    h = 0.5 * tilt
    # (0, 1, 0, 0) * (sin h, 0, 0, cos h)
    return [0.0, math.cos(h), -math.sin(h), 0.0]


def area_light_floor(out_path, roughness):
    """A 6 m x 6 m grey dielectric floor of `roughness` with a ball of 0.4 m and a pole on it, lit only by
    an EXT_lights_area rect light of 1.6 m x 0.8 m behind them, 1.6 m up and turned toward the camera
    Cam (on +Z, 2.2 m up, looking down at them), whose reflection on the floor lies by the ball, as a
    .glb."""
    import math

    floor = ([(-3, 0, -3), (3, 0, -3), (3, 0, 3), (-3, 0, 3)], [(0, 1, 0)] * 4, [0, 2, 1, 0, 3, 2])
    ball_p, ball_i = _uv_sphere(64, 32)
    tilt = math.radians(-60.0)  # -Z (its light) turned from the horizon toward the floor and the camera
    pitch = math.atan2(2.2 - 0.3, 4.2 + 0.2)  # the camera Cam looks down at (0, 0.3, -0.2)
    gltf = {
        "asset": {"version": "2.0", "generator": "pmr scripts/shading_pictures.py"},
        "extensionsUsed": ["EXT_lights_area"],
        "extensions": {"EXT_lights_area": {"lights": [
            {"name": "Panel", "type": "rect", "intensity": 6.0, "size": 0.8, "rect": {"aspect": 2.0}}]}},
        "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.55, "znear": 0.1}}],
        "nodes": [{"mesh": 0}, {"mesh": 1, "translation": [-0.5, 0.4, 0.3], "scale": [0.4, 0.4, 0.4]},
                  {"mesh": 1, "translation": [0.7, 0.7, 0.2], "scale": [0.06, 0.7, 0.06]},
                  {"name": "Panel", "translation": [0.0, 1.6, -2.2], "rotation": _light_rotation(tilt),
                   "extensions": {"EXT_lights_area": {"light": 0}}},
                  {"name": "Cam", "camera": 0, "translation": [0.0, 2.2, 4.2],
                   "rotation": [math.sin(-0.5 * pitch), 0.0, 0.0, math.cos(0.5 * pitch)]}],
        "meshes": [{"primitives": [{"material": 0}]}, {"primitives": [{"material": 1}]}],
        "materials": [{"name": "Floor", "pbrMetallicRoughness": {
                           "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": roughness}},
                      {"name": "Clay", "pbrMetallicRoughness": {
                           "baseColorFactor": [0.8, 0.35, 0.1, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}}],
    }
    _write_glb(out_path, gltf, [floor, (ball_p, ball_p, ball_i)])


def main(argv):
    if len(argv) == 3 and argv[0] == "arealight":
        area_light_floor(argv[1], float(argv[2]))
        return
    if len(argv) == 2 and argv[0] == "sphere":
        # the metal of the default scene's Gold, smoother: a highlight of a few pixels
        sphere(argv[1], (0.95, 0.58, 0.1), 1.0, 0.2)
        return
    if len(argv) < 3 or argv[0] != "strip":
        sys.exit(__doc__)
    out, rest = argv[1], argv[2:]
    mark = "--mark" in rest
    rest = [a for a in rest if a != "--mark"]
    checks = []
    if "--check-center" in rest:
        i = rest.index("--check-center")
        rest, checks = rest[:i], rest[i + 1:]
        if len(checks) != len(rest):
            fail("--check-center needs one PNG (or '-') per panel")
    strip(out, rest, mark, checks)


if __name__ == "__main__":
    main(sys.argv[1:])
