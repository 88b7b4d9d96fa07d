#!/usr/bin/env python3
"""Writes a benchmark glTF: a tube of RINGS x SEGMENTS vertices (default 1000 x 100 = 100k vertices,
~200k triangles) skinned to a chain of 4 joints (JOINTS_0 / WEIGHTS_0, inverse bind matrices) with two
morph targets (POSITION and NORMAL deltas: a bulge and a ripple), animated for 2 s: the joints bend
about +Z and the morph weights swing (LINEAR). Every vertex is morphed and skinned in every frame, so
`pmr bench tube.gltf --animation 0` shows what deforming 100k vertices costs.

usage: make_skinned_tube.py OUT.gltf [RINGS SEGMENTS]   (standard library only; data embedded)
"""
import base64
import json
import math
import struct
import sys


def main():
    out = sys.argv[1]
    rings = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    segs = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    height, radius, joints = 4.0, 0.3, 4
    pos, nrm, jnt, wgt, bulge_p, bulge_n, ripple_p, ripple_n = [], [], [], [], [], [], [], []
    for r in range(rings):
        y = height * r / (rings - 1)
        # weights: linear between the two joints around y (joint k sits at y = k * height / joints)
        f = min(y / (height / joints), joints - 1.0)
        k = min(int(f), joints - 2)
        t = f - k
        for s in range(segs):
            a = 2 * math.pi * s / segs
            c, si = math.cos(a), math.sin(a)
            pos += [radius * c, y, radius * si]
            nrm += [c, 0.0, si]
            jnt += [k, k + 1, 0, 0]
            wgt += [1.0 - t, t, 0.0, 0.0]
            b = 0.15 * math.sin(math.pi * y / height)
            bulge_p += [b * c, 0.0, b * si]
            bulge_n += [0.0, 0.0, 0.0]
            w = 0.05 * math.sin(6 * a + 3 * y)
            ripple_p += [w * c, 0.0, w * si]
            ripple_n += [0.0, -0.1 * math.cos(3 * y), 0.0]
    idx = []
    for r in range(rings - 1):
        for s in range(segs):
            a, b = r * segs + s, r * segs + (s + 1) % segs
            c, d = a + segs, b + segs
            idx += [a, c, b, b, c, d]
    ibm = []
    for k in range(joints):  # inverse of translate(0, k h / joints, 0), column-major
        ibm += [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -k * height / joints, 0, 1]
    times = [0.0, 0.5, 1.0, 1.5, 2.0]
    rot = []
    for tt in times:
        ang = 0.35 * math.sin(math.pi * tt)
        rot += [0.0, 0.0, math.sin(ang / 2), math.cos(ang / 2)]
    weights = []
    for tt in times:
        weights += [0.5 + 0.5 * math.sin(math.pi * tt), 0.5 - 0.5 * math.cos(math.pi * tt)]

    blob = bytearray()
    views, accessors = [], []

    def add(fmt, values, comp, typ, count, minmax=False):
        while len(blob) % 4:
            blob.append(0)
        off = len(blob)
        blob.extend(struct.pack("<%d%s" % (len(values), fmt), *values))
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(blob) - off})
        acc = {"bufferView": len(views) - 1, "componentType": comp, "type": typ, "count": count}
        if minmax:
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        accessors.append(acc)
        return len(accessors) - 1

    n = rings * segs
    a_pos = add("f", pos, 5126, "VEC3", n, True)
    a_nrm = add("f", nrm, 5126, "VEC3", n)
    a_jnt = add("H", jnt, 5123, "VEC4", n)
    a_wgt = add("f", wgt, 5126, "VEC4", n)
    a_bp = add("f", bulge_p, 5126, "VEC3", n, True)
    a_bn = add("f", bulge_n, 5126, "VEC3", n)
    a_rp = add("f", ripple_p, 5126, "VEC3", n, True)
    a_rn = add("f", ripple_n, 5126, "VEC3", n)
    a_idx = add("I", idx, 5125, "SCALAR", len(idx))
    a_ibm = add("f", ibm, 5126, "MAT4", joints)
    a_t = add("f", times, 5126, "SCALAR", len(times))
    accessors[a_t]["min"], accessors[a_t]["max"] = [times[0]], [times[-1]]
    a_rot = add("f", rot, 5126, "VEC4", len(times))
    a_w = add("f", weights, 5126, "SCALAR", 2 * len(times))

    nodes = [{"mesh": 0, "skin": 0}]
    for k in range(joints):
        node = {"translation": [0.0, 0.0 if k == 0 else height / joints, 0.0]}
        if k + 1 < joints:
            node["children"] = [len(nodes) + 1]
        nodes.append(node)
    doc = {
        "asset": {"version": "2.0", "generator": "pmr scripts/make_skinned_tube.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": a_pos, "NORMAL": a_nrm, "JOINTS_0": a_jnt,
                                                   "WEIGHTS_0": a_wgt},
                                    "indices": a_idx,
                                    "targets": [{"POSITION": a_bp, "NORMAL": a_bn},
                                                {"POSITION": a_rp, "NORMAL": a_rn}]}],
                    "weights": [0.0, 0.0]}],
        "skins": [{"joints": list(range(1, joints + 1)), "inverseBindMatrices": a_ibm, "skeleton": 1}],
        "animations": [{"name": "bend", "samplers": [
            {"input": a_t, "output": a_rot, "interpolation": "LINEAR"},
            {"input": a_t, "output": a_w, "interpolation": "LINEAR"}],
            "channels": [{"sampler": 0, "target": {"node": k, "path": "rotation"}} for k in range(2, joints + 1)]
            + [{"sampler": 1, "target": {"node": 0, "path": "weights"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    with open(out, "w") as f:
        json.dump(doc, f)
    print("wrote %s: %d vertices, %d triangles" % (out, n, len(idx) // 3))


if __name__ == "__main__":
    main()
