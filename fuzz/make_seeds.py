#!/usr/bin/env python3
"""Writes the small seed files in fuzz/corpus/<target>/ (run from anywhere; deterministic).

Each seed is a tiny valid file of its format, built byte by byte here so that the fuzzers start
from inputs that reach deep into the parsers: sidecars (animorder_runtime.h's format), glTF 2.0
(.glb and .gltf with an embedded buffer: static, morph-target and translation animation, one-joint
skin), MD2 (one triangle, two frames), IQM v2 (static, and one-joint skinned with an animation) and
the HTTP request heads `animorder view` reads (a browser's GET, HEAD over HTTP/1.0 without Host, a
foreign Host, a URL with control bytes, half a request).
"""
import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def write(target, name, data):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def u32(*v):
    return struct.pack("<%dI" % len(v), *v)


def f32(*v):
    return struct.pack("<%df" % len(v), *v)


# --- Sidecars ----------------------------------------------------------------------------------
def sidecar(index_count, buffers, clips):
    """clips: list of (keyframes, theta, phi, rate, base, cells bytes, centres floats)."""
    out = b"AOR1" + u32(1, len(buffers), index_count, len(clips))
    offset = 20 + 32 * len(clips) + 4 * index_count * len(buffers)
    tables = b""
    for k, t, p, rate, base, cells, centres in clips:
        assert len(cells) == k * t * p and len(centres) == 3 * k
        out += u32(k, t, p) + f32(rate) + u32(base, offset, offset + len(cells), 0)
        offset += len(cells) + 12 * k
        tables += cells + f32(*centres)
    for b in buffers:
        out += u32(*b)
    return out + tables


cells = bytearray(24)
cells[4], cells[5], cells[6], cells[20] = 3, 1, 2, 3
write("runtime", "tiny.aor", sidecar(3, [[0, 1, 2], [10, 11, 12], [20, 21, 22], [30, 31, 32]],
                                     [(2, 3, 4, 10.0, 0, bytes(cells), [0, 0, 0, 10, 0, 0])]))
write("runtime", "two_clips.aor", sidecar(6, [[0, 1, 2, 2, 1, 3], [2, 1, 3, 0, 1, 2], [0, 1, 2, 2, 1, 3]],
                                          [(1, 2, 8, 30.0, 0, bytes([0, 1] * 8), [0, 1, 0]),
                                           (3, 5, 2, 24.0, 1, bytes([1, 0, 1, 1, 0] * 6), [0, 0, 0, 1, 0, 0, 2, 0, 0])]))

# --- glTF ---------------------------------------------------------------------------------------
def pad4(b, fill=b"\0"):
    return b + fill * (-len(b) % 4)


class Gltf:
    def __init__(self):
        self.bin = b""
        self.doc = {"asset": {"version": "2.0"}, "buffers": [], "bufferViews": [], "accessors": []}

    def accessor(self, data, component, count, type_, minmax=None):
        self.bin = pad4(self.bin)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        a = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component, "count": count, "type": type_}
        if minmax:
            a["min"], a["max"] = minmax
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def glb(self):
        self.doc["buffers"] = [{"byteLength": len(self.bin)}]
        js = pad4(json.dumps(self.doc, separators=(",", ":")).encode(), b" ")
        binary = pad4(self.bin)
        body = u32(len(js), 0x4E4F534A) + js + u32(len(binary), 0x004E4942) + binary
        return b"glTF" + u32(2, 12 + len(body)) + body

    def gltf(self):
        uri = "data:application/octet-stream;base64," + base64.b64encode(self.bin).decode()
        self.doc["buffers"] = [{"byteLength": len(self.bin), "uri": uri}]
        return json.dumps(self.doc, indent=1).encode()


FLOAT, USHORT, UBYTE = 5126, 5123, 5121
tri = f32(0, 0, 0, 1, 0, 0, 0, 1, 0)
box = ([0, 0, 0], [1, 1, 0])

g = Gltf()
pos = g.accessor(tri, FLOAT, 3, "VEC3", box)
idx = g.accessor(struct.pack("<3H", 0, 1, 2), USHORT, 3, "SCALAR")
g.doc.update(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
             meshes=[{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}])
write("gltf", "triangle.glb", g.glb())

# Morph target weights and the node's translation, animated over 1 s.
g = Gltf()
pos = g.accessor(tri, FLOAT, 3, "VEC3", box)
idx = g.accessor(struct.pack("<3H", 0, 1, 2), USHORT, 3, "SCALAR")
morph = g.accessor(f32(0, 0, 1, 0, 0, 1, 0, 0, 1), FLOAT, 3, "VEC3", ([0, 0, 1], [0, 0, 1]))
times = g.accessor(f32(0, 1), FLOAT, 2, "SCALAR", ([0], [1]))
weights = g.accessor(f32(0, 1), FLOAT, 2, "SCALAR")
moves = g.accessor(f32(0, 0, 0, 2, 0, 0), FLOAT, 2, "VEC3")
g.doc.update(scene=0, scenes=[{"nodes": [0]}], nodes=[{"mesh": 0}],
             meshes=[{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "targets": [{"POSITION": morph}]}],
                      "weights": [0]}],
             animations=[{"name": "wave",
                          "samplers": [{"input": times, "output": weights, "interpolation": "LINEAR"},
                                       {"input": times, "output": moves, "interpolation": "STEP"}],
                          "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}},
                                       {"sampler": 1, "target": {"node": 0, "path": "translation"}}]}])
write("gltf", "morph_translation.gltf", g.gltf())

# One joint rotating a quarter turn about Y; every vertex fully weighted to it.
g = Gltf()
pos = g.accessor(tri, FLOAT, 3, "VEC3", box)
idx = g.accessor(struct.pack("<3H", 0, 1, 2), USHORT, 3, "SCALAR")
joints = g.accessor(bytes(12), UBYTE, 3, "VEC4")
wts = g.accessor(f32(1, 0, 0, 0) * 3, FLOAT, 3, "VEC4")
ibm = g.accessor(f32(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1), FLOAT, 1, "MAT4")
times = g.accessor(f32(0, 0.5), FLOAT, 2, "SCALAR", ([0], [0.5]))
rot = g.accessor(f32(0, 0, 0, 1, 0, 0.70710677, 0, 0.70710677), FLOAT, 2, "VEC4")
g.doc.update(scene=0, scenes=[{"nodes": [0, 1]}], nodes=[{"mesh": 0, "skin": 0}, {"name": "bone"}],
             skins=[{"joints": [1], "inverseBindMatrices": ibm}],
             meshes=[{"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": joints, "WEIGHTS_0": wts},
                                      "indices": idx}]}],
             animations=[{"name": "turn", "samplers": [{"input": times, "output": rot}],
                          "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}])
write("gltf", "skinned.glb", g.glb())

# --- MD2: one triangle, 3 vertices, frames "run1" and "run2" -------------------------------------
vertices, frame_size = 3, 40 + 4 * 3
tris = struct.pack("<6H", 0, 1, 2, 0, 0, 0)
frames = b""
for f in range(2):
    frames += f32(0.1, 0.1, 0.1) + f32(0, 0, f) + (b"run%d" % (f + 1)).ljust(16, b"\0")
    frames += bytes([0, 0, 0, 0, 10, 0, 0, 0, 0, 10, 0, 0])
ofs_tris, ofs_frames = 68, 68 + len(tris)
end = ofs_frames + len(frames)
header = b"IDP2" + struct.pack("<16i", 8, 8, 8, frame_size, 0, vertices, 0, 1, 0, 2, 68, 68, ofs_tris, ofs_frames, end, end)
write("md2", "triangle.md2", header + tris + frames)


# --- IQM v2 ------------------------------------------------------------------------------------
def iqm(text, arrays, triangles, joints=b"", poses=b"", anims=b"", frames=b"", counts=(0, 0, 0, 0, 0)):
    """arrays: list of (type, format, size, data); counts: joints, poses, anims, frames, channels."""
    num_joints, num_poses, num_anims, num_frames, num_channels = counts
    body = b""
    ofs = 124

    def place(data):
        nonlocal body
        at = ofs + len(body)
        body += pad4(data)
        return at

    ofs_text = place(text)
    array_data = [(t, fmt, size, place(data)) for t, fmt, size, data in arrays]
    ofs_arrays = place(b"".join(u32(t, 0, fmt, size, at) for t, fmt, size, at in array_data))
    ofs_triangles = place(triangles)
    ofs_joints = place(joints) if joints else 0
    ofs_poses = place(poses) if poses else 0
    ofs_anims = place(anims) if anims else 0
    ofs_frames = place(frames) if frames else 0
    num_vertexes = len(arrays[0][3]) // 12
    header = b"INTERQUAKEMODEL\0" + u32(2, 124 + len(body), 0, len(text), ofs_text, 0, 0, len(arrays), num_vertexes,
                                        ofs_arrays, len(triangles) // 12, ofs_triangles, 0, num_joints, ofs_joints,
                                        num_poses, ofs_poses, num_anims, ofs_anims, num_frames, num_channels, ofs_frames,
                                        0, 0, 0, 0, 0)
    assert len(header) == 124
    return header + body


write("iqm", "static.iqm", iqm(b"\0", [(0, 7, 3, tri)], u32(0, 1, 2)))
joint = u32(1) + struct.pack("<i", -1) + f32(0, 0, 0) + f32(0, 0, 0, 1) + f32(1, 1, 1)
pose = struct.pack("<i", -1) + u32(1) + f32(0, 0, 0, 0, 0, 0, 1, 1, 1, 1) + f32(0.01, 0, 0, 0, 0, 0, 0, 0, 0, 0)
anim = u32(6, 0, 2) + f32(10) + u32(0)
write("iqm", "skinned.iqm",
      iqm(b"\0bone\0walk\0", [(0, 7, 3, tri), (4, 1, 4, bytes(12)), (5, 1, 4, bytes([255, 0, 0, 0]) * 3)], u32(0, 1, 2),
          joint, pose, anim, struct.pack("<2H", 0, 100), counts=(1, 1, 1, 2, 1)))

# --- HTTP request heads (animorder view) ---------------------------------------------------------
write("http_request", "browser_get.txt",
      b"GET /viewer/node_modules/three/build/three.module.js?v=1 HTTP/1.1\r\nHost: 127.0.0.1:8417\r\n"
      b"User-Agent: Mozilla/5.0\r\nAccept: */*\r\nConnection: keep-alive\r\n\r\n")
write("http_request", "head_http10.txt", b"HEAD /model.glb HTTP/1.0\r\n\r\n")
write("http_request", "foreign_host.txt", b"GET /model.glb HTTP/1.1\r\nhost:  evil.example:8417 \t\r\n\r\n")
write("http_request", "control_bytes.txt", b"GET /viewer/a\x1b[2J\xff\\b HTTP/1.1\r\nHost: [::1]:8417\r\n\r\n")
write("http_request", "half.txt", b"GET /viewer/ HTTP/1.1\r\nHost: localhost:84")
