#!/usr/bin/env python3
"""Generate the renderer's default scene, data/default_scene.glb.

Usage: python3 scripts/make_default_scene.py [OUTPUT.glb]   (default: data/default_scene.glb)

Everything is built procedurally with the Python standard library only (json, struct, zlib, math),
and the output is deterministic: running the script twice gives byte-identical files (no
timestamps, no dict/set ordering effects, floats written through struct as float32).

Scene conventions: glTF 2.0, metres-ish units, Y up, +Z toward the viewer. The renderer frames
the bounding sphere from +Z and puts the zero-parallax plane through the centre of the bounding
box (about z = 0 here), so objects are spread from z = -1.5 (behind the screen) to z = +1.5 (in
front of it). See data/README.md for a description of the contents.
"""

import json
import math
import os
import struct
import sys
import zlib

# ----------------------------------------------------------------------------------------------
# Small vector / quaternion helpers
# ----------------------------------------------------------------------------------------------


def f32(x):
    """Round a Python float to the nearest float32 (what ends up in the binary chunk)."""
    return struct.unpack('<f', struct.pack('<f', x))[0]


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def length(a):
    return math.sqrt(dot(a, a))


def normalize(a):
    n = length(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def quat_axis_angle(axis, degrees):
    ax = normalize(axis)
    h = math.radians(degrees) / 2.0
    s = math.sin(h)
    return (ax[0] * s, ax[1] * s, ax[2] * s, math.cos(h))


def quat_mul(a, b):
    """Hamilton product a*b (apply b first, then a); quaternions stored as (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def quat_to_mat3(q):
    x, y, z, w = q
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def clean(values):
    """float32-exact Python floats for the JSON (keeps the text short and stable)."""
    return [f32(v) for v in values]


# ----------------------------------------------------------------------------------------------
# Mesh construction
# ----------------------------------------------------------------------------------------------


class MeshData:
    """Vertex arrays plus triangles. Triangles are oriented automatically so that their geometric
    normal agrees with the vertex normals (counter-clockwise front faces, outward normals)."""

    def __init__(self, name, uv=False, color=False):
        self.name = name
        self.pos, self.nrm = [], []
        self.uv = [] if uv else None
        self.col = [] if color else None
        self.tris = []

    def vertex(self, p, n, uv=None, col=None):
        self.pos.append(tuple(p))
        self.nrm.append(normalize(n))
        if self.uv is not None:
            self.uv.append(tuple(uv))
        if self.col is not None:
            self.col.append(tuple(col))
        return len(self.pos) - 1

    def tri(self, a, b, c):
        pa, pb, pc = self.pos[a], self.pos[b], self.pos[c]
        g = cross(sub(pb, pa), sub(pc, pa))
        scale = max(length(sub(pb, pa)), length(sub(pc, pa)), 1e-30)
        if length(g) <= 1e-9 * scale * scale:
            return  # degenerate (e.g. the pole rows of a UV sphere): drop it
        nsum = add(add(self.nrm[a], self.nrm[b]), self.nrm[c])
        if dot(g, nsum) < 0.0:
            b, c = c, b
        self.tris.append((a, b, c))

    def quad(self, a, b, c, d):
        """Quad a-b-c-d around its boundary (either direction)."""
        self.tri(a, b, c)
        self.tri(a, c, d)

    def grid(self, nu, nv, fn, closed_u=False):
        """Parametric surface: fn(i, j) -> (position, normal, uv, colour) for 0<=i<=nu, 0<=j<=nv.
        Vertices along the seams are duplicated so UVs stay continuous."""
        base = len(self.pos)
        for j in range(nv + 1):
            for i in range(nu + 1):
                p, n, uv, col = fn(i, j)
                self.vertex(p, n, uv, col)
        w = nu + 1
        for j in range(nv):
            for i in range(nu):
                a = base + j * w + i
                self.quad(a, a + 1, a + 1 + w, a + w)


def uv_sphere(name, radius, seg_u, seg_v):
    m = MeshData(name)

    def fn(i, j):
        phi = 2.0 * math.pi * i / seg_u
        theta = math.pi * j / seg_v
        n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
        return mul(n, radius), n, None, None

    m.grid(seg_u, seg_v, fn)
    return m


def torus(name, major, minor, seg_u, seg_v):
    """Torus around the Y axis."""
    m = MeshData(name)

    def fn(i, j):
        u = 2.0 * math.pi * i / seg_u
        v = 2.0 * math.pi * j / seg_v
        cu, su, cv, sv = math.cos(u), math.sin(u), math.cos(v), math.sin(v)
        n = (cv * cu, sv, cv * su)
        p = ((major + minor * cv) * cu, minor * sv, (major + minor * cv) * su)
        return p, n, None, None

    m.grid(seg_u, seg_v, fn)
    return m


def rainbow(t):
    """Smooth hue ramp, t in [0, 1) -> linear RGB."""
    r = 0.5 + 0.5 * math.cos(2.0 * math.pi * (t + 0.0))
    g = 0.5 + 0.5 * math.cos(2.0 * math.pi * (t - 1.0 / 3.0))
    b = 0.5 + 0.5 * math.cos(2.0 * math.pi * (t - 2.0 / 3.0))
    # Push towards saturated colours, then to linear light.
    return tuple(max(0.0, min(1.0, c * 1.15 - 0.075)) ** 2.2 for c in (r, g, b))


def tube(m, curve, t0, t1, seg_t, radius, seg_r, closed, colour_fn=None):
    """Sweep a circle of `radius` along curve(t) for t in [t0, t1]. The frame is the Frenet frame
    (the curves used here never have zero curvature). Open tubes get flat end caps."""
    h = (t1 - t0) * 1e-4

    def frame(t):
        p = curve(t)
        d1 = sub(curve(t + h), curve(t - h))
        d2 = add(sub(curve(t + h), mul(p, 2.0)), curve(t - h))
        tang = normalize(d1)
        nrm = normalize(sub(d2, mul(tang, dot(d2, tang))))
        bin_ = cross(tang, nrm)
        return p, tang, nrm, bin_

    frames = [frame(t0 + (t1 - t0) * k / seg_t) for k in range(seg_t + 1)]

    def fn(i, j):
        p, _, nrm, bin_ = frames[j]
        a = 2.0 * math.pi * i / seg_r
        n = add(mul(nrm, math.cos(a)), mul(bin_, math.sin(a)))
        col = colour_fn(j / seg_t) if colour_fn else None
        return add(p, mul(n, radius)), n, None, col

    if closed:
        # Share the ring at t1 with the ring at t0 by reusing the first frame, so the seam is exact.
        frames[seg_t] = frames[0]
    m.grid(seg_r, seg_t, fn)
    if not closed:
        for k, sign in ((0, -1.0), (seg_t, 1.0)):
            p, tang, nrm, bin_ = frames[k]
            n = mul(tang, sign)
            col = colour_fn(k / seg_t) if colour_fn else None
            centre = m.vertex(p, n, None, col)
            ring = []
            for i in range(seg_r):
                a = 2.0 * math.pi * i / seg_r
                d = add(mul(nrm, math.cos(a)), mul(bin_, math.sin(a)))
                ring.append(m.vertex(add(p, mul(d, radius)), n, None, col))
            for i in range(seg_r):
                m.tri(centre, ring[i], ring[(i + 1) % seg_r])


def torus_knot(name, p, q, scale, tube_radius, seg_t, seg_r):
    m = MeshData(name, color=True)

    def curve(t):
        r = math.cos(q * t) + 2.0
        return (scale * r * math.cos(p * t), scale * -math.sin(q * t), scale * r * math.sin(p * t))

    tube(m, curve, 0.0, 2.0 * math.pi, seg_t, tube_radius, seg_r, True, rainbow)
    return m


def helix(name, radius, height, turns, tube_radius, seg_t, seg_r):
    m = MeshData(name)
    lift = 0.12  # straight-ish start height so the spring stands on the ground

    def curve(t):
        return (radius * math.cos(t), lift + (height - 2 * lift) * t / (2 * math.pi * turns),
                radius * math.sin(t))

    tube(m, curve, 0.0, 2.0 * math.pi * turns, seg_t, tube_radius, seg_r, False)
    return m


def cylinder(name, radius, height, seg):
    """Capped cylinder standing on y = 0."""
    m = MeshData(name)

    def fn(i, j):
        a = 2.0 * math.pi * i / seg
        n = (math.cos(a), 0.0, -math.sin(a))
        return (radius * n[0], height * j, radius * n[2]), n, None, None

    m.grid(seg, 1, fn)
    for y, ny in ((0.0, -1.0), (height, 1.0)):
        centre = m.vertex((0.0, y, 0.0), (0.0, ny, 0.0))
        ring = [m.vertex((radius * math.cos(2 * math.pi * i / seg), y,
                          -radius * math.sin(2 * math.pi * i / seg)), (0.0, ny, 0.0))
                for i in range(seg)]
        for i in range(seg):
            m.tri(centre, ring[i], ring[(i + 1) % seg])
    return m


def unit_box(name):
    """Cube [-0.5, 0.5]^3 with flat normals (4 split vertices per face)."""
    m = MeshData(name, uv=True)
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            idx = []
            for (su, sv) in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = 0.5 * sign
                p[u_axis] = 0.5 * su
                p[v_axis] = 0.5 * sv
                idx.append(m.vertex(p, n, (0.5 + 0.5 * su, 0.5 - 0.5 * sv)))
            m.quad(*idx)
    return m


def ground(name, size_x, size_z, nx, nz, tile):
    """Horizontal plane at y = 0; one texture repeat per `tile` units."""
    m = MeshData(name, uv=True)

    def fn(i, j):
        x = -size_x / 2 + size_x * i / nx
        z = -size_z / 2 + size_z * j / nz
        return (x, 0.0, z), (0.0, 1.0, 0.0), (x / tile, z / tile), None

    m.grid(nx, nz, fn)
    return m


def flag(name, width, height, nu, nv):
    """A waving sheet hanging from its left edge (x = 0), in the XY plane, rippling in Z."""
    m = MeshData(name)
    amp, k, ph = 0.07, 2.0 * math.pi * 1.3 / width, 0.4

    def fn(i, j):
        x = width * i / nu
        y = height * j / nv
        a = amp * (x / width)
        s = k * x - ph + 0.9 * y / height
        z = a * math.sin(s)
        dzdx = (amp / width) * math.sin(s) + a * k * math.cos(s)
        dzdy = a * math.cos(s) * 0.9 / height
        # A little droop: the free edge sags by 0.08 * (x / width)^2.
        droop_dx = 0.16 * x / (width * width)
        y -= 0.08 * (x / width) ** 2
        n = (-droop_dx * dzdy - dzdx, -dzdy, 1.0)  # d/dx x d/dy of (x, y - droop, z)
        return (x, y, z), n, None, None

    m.grid(nu, nv, fn)
    return m


def panel(name, width, height, repeats_u, repeats_v):
    """Vertical quad facing +Z, bottom edge centred on the origin."""
    m = MeshData(name, uv=True)
    n = (0.0, 0.0, 1.0)
    a = m.vertex((-width / 2, 0.0, 0.0), n, (0.0, repeats_v))
    b = m.vertex((width / 2, 0.0, 0.0), n, (repeats_u, repeats_v))
    c = m.vertex((width / 2, height, 0.0), n, (repeats_u, 0.0))
    d = m.vertex((-width / 2, height, 0.0), n, (0.0, 0.0))
    m.quad(a, b, c, d)
    return m


# ----------------------------------------------------------------------------------------------
# PNG writer (zlib + chunks, filter type 0 on every row)
# ----------------------------------------------------------------------------------------------


def png(width, height, rows, channels):
    """rows: list of `height` bytes objects, each width*channels long (8-bit RGB or RGBA)."""
    def chunk(kind, data):
        return (struct.pack('>I', len(data)) + kind + data +
                struct.pack('>I', zlib.crc32(kind + data) & 0xFFFFFFFF))

    colour_type = {3: 2, 4: 6}[channels]
    ihdr = struct.pack('>IIBBBBB', width, height, 8, colour_type, 0, 0, 0)
    raw = b''.join(b'\x00' + bytes(r) for r in rows)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) +
            chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))


def checker_texture(size=64):
    """2 x 2 tiles per repeat with a thin grout line (sRGB)."""
    light, dark, grout = (214, 206, 188), (78, 92, 112), (40, 40, 44)
    rows = []
    half = size // 2
    for y in range(size):
        row = bytearray()
        for x in range(size):
            gx, gy = x % half, y % half
            if gx == 0 or gy == 0:
                c = grout
            else:
                c = light if ((x // half) + (y // half)) % 2 == 0 else dark
                # Subtle bevel so the tiles read as tiles, not as a flat print.
                if gx == 1 or gy == 1:
                    c = tuple(min(255, v + 18) for v in c)
                elif gx == half - 1 or gy == half - 1:
                    c = tuple(max(0, v - 18) for v in c)
            row += bytes(c)
        rows.append(row)
    return png(size, size, rows, 3)


def grille_texture(size=64):
    """One cell of a perforated metal sheet: round hole (alpha 0) in a bronze plate with a bright
    rim around the hole. Alpha is 0 or 255 so the MASK cut-out is crisp."""
    rows = []
    c = (size - 1) / 2.0
    hole = 0.34 * size
    rim = 0.42 * size
    for y in range(size):
        row = bytearray()
        for x in range(size):
            d = math.hypot(x - c, y - c)
            if d < hole:
                row += bytes((0, 0, 0, 0))
            elif d < rim:
                t = (d - hole) / (rim - hole)
                v = int(round(235 - 80 * t))
                row += bytes((v, int(v * 0.78), int(v * 0.45), 255))
            else:
                row += bytes((150, 104, 52, 255))
        rows.append(row)
    return png(size, size, rows, 4)


# ----------------------------------------------------------------------------------------------
# glTF / GLB writer
# ----------------------------------------------------------------------------------------------

ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125
LINEAR, LINEAR_MIPMAP_LINEAR, REPEAT = 9729, 9987, 10497


class Gltf:
    def __init__(self):
        self.bin = bytearray()
        self.buffer_views, self.accessors = [], []
        self.meshes, self.materials, self.nodes = [], [], []
        self.images, self.textures, self.samplers = [], [], []
        self.total_triangles = 0  # counted over node instances

    def view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        bv = {'buffer': 0, 'byteOffset': len(self.bin), 'byteLength': len(data)}
        if target is not None:
            bv['target'] = target
        self.bin += data
        self.buffer_views.append(bv)
        return len(self.buffer_views) - 1

    def float_accessor(self, rows, kind, with_bounds=False):
        comps = len(rows[0])
        data = struct.pack('<%df' % (comps * len(rows)), *[v for r in rows for v in r])
        acc = {'bufferView': self.view(data, ARRAY_BUFFER), 'componentType': FLOAT,
               'count': len(rows), 'type': kind}
        if with_bounds:
            acc['min'] = [min(f32(r[k]) for r in rows) for k in range(comps)]
            acc['max'] = [max(f32(r[k]) for r in rows) for k in range(comps)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def index_accessor(self, tris, vertex_count):
        flat = [i for t in tris for i in t]
        if vertex_count < 65536:
            data, ctype = struct.pack('<%dH' % len(flat), *flat), UNSIGNED_SHORT
        else:
            data, ctype = struct.pack('<%dI' % len(flat), *flat), UNSIGNED_INT
        self.accessors.append({'bufferView': self.view(data, ELEMENT_ARRAY_BUFFER),
                               'componentType': ctype, 'count': len(flat), 'type': 'SCALAR'})
        return len(self.accessors) - 1

    def geometry(self, m):
        """Write a MeshData's arrays once; returns (attributes, index accessor, triangles)."""
        check_mesh(m)
        attrs = {'POSITION': self.float_accessor(m.pos, 'VEC3', with_bounds=True),
                 'NORMAL': self.float_accessor(m.nrm, 'VEC3')}
        if m.uv is not None:
            attrs['TEXCOORD_0'] = self.float_accessor(m.uv, 'VEC2')
        if m.col is not None:
            attrs['COLOR_0'] = self.float_accessor(m.col, 'VEC3')
        return (attrs, self.index_accessor(m.tris, len(m.pos)), len(m.tris))

    def mesh(self, name, geometry, material):
        attrs, indices, ntri = geometry
        self.meshes.append({'name': name, 'primitives': [
            {'attributes': dict(attrs), 'indices': indices, 'material': material, 'mode': 4}]})
        return (len(self.meshes) - 1, ntri)

    def material(self, name, rgba, roughness=0.5, metallic=0.0, **extra):
        mat = {'name': name, 'pbrMetallicRoughness': {
            'baseColorFactor': clean(rgba), 'metallicFactor': f32(metallic),
            'roughnessFactor': f32(roughness)}}
        if 'texture' in extra:
            mat['pbrMetallicRoughness']['baseColorTexture'] = {'index': extra.pop('texture')}
        mat.update(extra)
        self.materials.append(mat)
        return len(self.materials) - 1

    def texture(self, name, png_bytes, sampler):
        self.images.append({'name': name, 'bufferView': self.view(png_bytes),
                            'mimeType': 'image/png'})
        self.textures.append({'sampler': sampler, 'source': len(self.images) - 1})
        return len(self.textures) - 1

    def node(self, name, mesh=None, children=None, translation=None, rotation=None, scale=None,
             matrix=None):
        n = {'name': name}
        if mesh is not None:
            n['mesh'] = mesh[0]
            self.total_triangles += mesh[1]
        if children:
            n['children'] = children
        if matrix is not None:
            n['matrix'] = clean(matrix)
        if translation is not None:
            n['translation'] = clean(translation)
        if rotation is not None:
            n['rotation'] = clean(rotation)
        if scale is not None:
            n['scale'] = clean(scale)
        self.nodes.append(n)
        return len(self.nodes) - 1

    def glb(self, root_nodes):
        doc = {
            'asset': {'version': '2.0',
                      'generator': 'pmr scripts/make_default_scene.py'},
            'scene': 0,
            'scenes': [{'name': 'DefaultScene', 'nodes': root_nodes}],
            'nodes': self.nodes,
            'meshes': self.meshes,
            'materials': self.materials,
            'textures': self.textures,
            'images': self.images,
            'samplers': self.samplers,
            'accessors': self.accessors,
            'bufferViews': self.buffer_views,
            'buffers': [{'byteLength': 0}],
        }
        while len(self.bin) % 4:
            self.bin.append(0)
        doc['buffers'][0]['byteLength'] = len(self.bin)
        js = json.dumps(doc, separators=(',', ':'), ensure_ascii=True).encode('ascii')
        js += b' ' * ((4 - len(js) % 4) % 4)
        body = (struct.pack('<II', len(js), 0x4E4F534A) + js +
                struct.pack('<II', len(self.bin), 0x004E4942) + bytes(self.bin))
        return struct.pack('<III', 0x46546C67, 2, 12 + len(body)) + body


def check_mesh(m):
    """Self-checks before writing: index range, unit normals, winding agrees with normals."""
    n = len(m.pos)
    assert n > 0 and m.tris, m.name
    for t in m.tris:
        assert all(0 <= i < n for i in t), m.name
    for v in m.nrm:
        assert abs(length(v) - 1.0) < 1e-6, m.name
    for a, b, c in m.tris:
        g = cross(sub(m.pos[b], m.pos[a]), sub(m.pos[c], m.pos[a]))
        assert dot(g, add(add(m.nrm[a], m.nrm[b]), m.nrm[c])) > 0.0, m.name


# ----------------------------------------------------------------------------------------------
# The scene
# ----------------------------------------------------------------------------------------------


def build():
    g = Gltf()
    g.samplers.append({'magFilter': LINEAR, 'minFilter': LINEAR_MIPMAP_LINEAR,
                       'wrapS': REPEAT, 'wrapT': REPEAT})
    tex_floor = g.texture('floor_tiles', checker_texture(), 0)
    tex_grille = g.texture('grille_cell', grille_texture(), 0)

    # Materials (baseColorFactor in linear RGB).
    m_floor = g.material('FloorTiles', (1.0, 1.0, 1.0, 1.0), 0.9, texture=tex_floor)
    m_red = g.material('Red', (0.80, 0.05, 0.04, 1.0), 0.35)
    m_gold = g.material('Gold', (0.95, 0.58, 0.10, 1.0), 0.3, metallic=1.0)
    m_rainbow = g.material('VertexRainbow', (1.0, 1.0, 1.0, 1.0), 0.4)
    m_cyan = g.material('Cyan', (0.05, 0.55, 0.75, 1.0), 0.4)
    m_flag = g.material('FlagMagenta', (0.75, 0.06, 0.45, 1.0), 0.8, doubleSided=True)
    m_grille = g.material('GrilleBronze', (1.0, 1.0, 1.0, 1.0), 0.45, texture=tex_grille,
                          alphaMode='MASK', alphaCutoff=0.5)
    m_steel = g.material('Steel', (0.55, 0.56, 0.58, 1.0), 0.3, metallic=1.0)
    m_green = g.material('Green', (0.10, 0.60, 0.12, 1.0), 0.5)
    m_blue = g.material('Blue', (0.06, 0.16, 0.80, 1.0), 0.45)
    m_orange = g.material('Orange', (0.95, 0.30, 0.02, 1.0), 0.5)
    m_purple = g.material('Purple', (0.35, 0.08, 0.65, 1.0), 0.5)
    m_white = g.material('Ivory', (0.85, 0.82, 0.72, 1.0), 0.6)
    m_yellow = g.material('Yellow', (0.90, 0.80, 0.05, 1.0), 0.5)

    # Geometry (each written once; meshes with different materials share accessors).
    geo_ground = g.geometry(ground('ground', 4.0, 3.0, 16, 12, 0.5))
    geo_sphere_big = g.geometry(uv_sphere('sphere_big', 1.0, 64, 32))
    geo_sphere_small = g.geometry(uv_sphere('sphere_small', 1.0, 32, 16))
    geo_torus = g.geometry(torus('torus', 1.0, 0.28, 96, 32))
    geo_knot = g.geometry(torus_knot('knot', 2, 3, 0.17, 0.075, 384, 20))
    geo_helix = g.geometry(helix('helix', 0.28, 2.0, 5.5, 0.045, 440, 12))
    geo_box = g.geometry(unit_box('box'))
    geo_pole = g.geometry(cylinder('pole', 0.025, 1.0, 24))
    geo_flag = g.geometry(flag('flag', 0.85, 0.5, 40, 20))
    geo_grille = g.geometry(panel('grille', 1.0, 0.8, 5, 4))

    ground_mesh = g.mesh('Ground', geo_ground, m_floor)
    nodes = []
    nodes.append(g.node('Ground', ground_mesh))

    # Behind the screen plane: the big red sphere (back left) and a cyan spring (back right).
    nodes.append(g.node('RedSphere', g.mesh('RedSphere', geo_sphere_big, m_red),
                        translation=(-1.15, 0.62, -0.85), scale=(0.62, 0.62, 0.62)))
    nodes.append(g.node('CyanSpring', g.mesh('CyanSpring', geo_helix, m_cyan),
                        translation=(1.45, 0.0, -1.05)))
    nodes.append(g.node('IvoryColumn', g.mesh('IvoryColumn', geo_box, m_white),
                        translation=(0.35, 0.8, -1.2), scale=(0.3, 1.6, 0.3),
                        rotation=quat_axis_angle((0, 1, 0), 30.0)))

    # Middle: a standing gold ring (node TRS: rotation and uniform scale) ...
    ring_q = quat_mul(quat_axis_angle((0, 1, 0), 35.0), quat_axis_angle((1, 0, 0), 90.0))
    nodes.append(g.node('GoldRing', g.mesh('GoldRing', geo_torus, m_gold),
                        translation=(-0.15, 0.72, -0.15), rotation=ring_q,
                        scale=(0.55, 0.55, 0.55)))

    # ... the rainbow trefoil knot on a steel pedestal (node matrix: rotation + translation) ...
    knot_q = quat_mul(quat_axis_angle((0, 0, 1), 20.0), quat_axis_angle((1, 0, 0), 70.0))
    r = quat_to_mat3(knot_q)
    t = (0.95, 1.2, 0.0)
    knot_matrix = [r[0][0], r[1][0], r[2][0], 0.0,
                   r[0][1], r[1][1], r[2][1], 0.0,
                   r[0][2], r[1][2], r[2][2], 0.0,
                   t[0], t[1], t[2], 1.0]
    nodes.append(g.node('RainbowKnot', g.mesh('RainbowKnot', geo_knot, m_rainbow),
                        matrix=knot_matrix))
    nodes.append(g.node('KnotPedestal', g.mesh('KnotPedestal', geo_box, m_steel),
                        translation=(0.95, 0.3, 0.0), scale=(0.45, 0.6, 0.45),
                        rotation=quat_axis_angle((0, 1, 0), 15.0)))

    # ... and a flag on a pole (2-level hierarchy: parent node with three children).
    flag_children = [
        g.node('FlagPole', g.mesh('FlagPole', geo_pole, m_steel), scale=(1.0, 2.1, 1.0)),
        g.node('FlagFinial', g.mesh('FlagFinial', geo_sphere_small, m_yellow),
               translation=(0.0, 2.13, 0.0), scale=(0.05, 0.05, 0.05)),
        g.node('FlagCloth', g.mesh('FlagCloth', geo_flag, m_flag), translation=(0.02, 1.5, 0.0)),
    ]
    # The cloth streams away to the back left, so from the viewer's side mostly its back face
    # shows: it disappears if doubleSided is ignored.
    nodes.append(g.node('FlagAssembly', children=flag_children, translation=(-0.55, 0.0, 0.45),
                        rotation=quat_axis_angle((0, 1, 0), 140.0)))

    # In front of the screen plane: a perforated grille (MASK) with the red sphere behind it, a
    # cluster of coloured orbs (hierarchy again, one squashed by non-uniform scale) and a box stack.
    nodes.append(g.node('Grille', g.mesh('Grille', geo_grille, m_grille),
                        translation=(-1.3, 0.0, 0.75), rotation=quat_axis_angle((0, 1, 0), 25.0)))
    orbs = [
        ('OrbBlue', m_blue, (0.0, 0.28, 0.0), (0.28, 0.28, 0.28)),
        ('OrbGreen', m_green, (0.42, 0.18, 0.22), (0.18, 0.18, 0.18)),
        ('OrbOrange', m_orange, (-0.38, 0.14, 0.3), (0.14, 0.14, 0.14)),
        ('OrbPurple', m_purple, (0.12, 0.11, 0.52), (0.11, 0.11, 0.11)),
        ('OrbEllipsoid', m_yellow, (-0.1, 0.66, 0.08), (0.32, 0.12, 0.2)),
    ]
    orb_nodes = [g.node(name, g.mesh(name, geo_sphere_small, mat), translation=tr, scale=sc)
                 for name, mat, tr, sc in orbs]
    nodes.append(g.node('OrbCluster', children=orb_nodes, translation=(0.2, 0.0, 0.75),
                        rotation=quat_axis_angle((0, 1, 0), 10.0)))

    stack = [('BoxBlue', m_blue, (1.45, 0.2, 1.0), (0.4, 0.4, 0.4), 10.0),
             ('BoxOrange', m_orange, (1.42, 0.55, 0.98), (0.3, 0.3, 0.3), 40.0),
             ('BoxGreen', m_green, (1.47, 0.81, 1.02), (0.22, 0.22, 0.22), 70.0),
             ('BoxPurple', m_purple, (1.0, 0.15, 1.25), (0.3, 0.3, 0.3), -20.0)]
    for name, mat, tr, sc, yaw in stack:
        nodes.append(g.node(name, g.mesh(name, geo_box, mat), translation=tr, scale=sc,
                            rotation=quat_axis_angle((0, 1, 0), yaw)))
    return g, nodes


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default = os.path.normpath(os.path.join(here, '..', 'data', 'default_scene.glb'))
    out = sys.argv[1] if len(sys.argv) > 1 else default
    g, roots = build()
    data = g.glb(roots)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, 'wb') as f:
        f.write(data)
    print('%s: %d bytes, %d triangles, %d nodes, %d meshes, %d materials' % (
        out, len(data), g.total_triangles, len(g.nodes), len(g.meshes), len(g.materials)))


if __name__ == '__main__':
    main()
