"""Animated glTF files written from Python: a small builder of node trees, box meshes, lights and
keyframed channels (the tests' hand-made animations, the fuzzer's seeds), and ``stage()``, an
animated model on a stage with every kind of channel glTF has for nodes.

    python -m ssrlab.lab.animated_gltf stage.gltf      # writes the stage (.gltf or .glb)

The stage, 1 m across, seen by its camera: a floor (roughness 0.1, reflective), a red box
("Spinner") turning about +y by LINEAR rotation keys (slerp) and bobbing up and down on a
CUBICSPLINE translation, a blue box ("Satellite") and a point light ("Lamp") that are its
children (they circle with it), and a green box ("Hopper") whose scale changes in STEP keys and
that slides on LINEAR translation keys in a second animation. Animations: "Spin" (3 s, the
spinner, its bob and the hopper's steps) and "Hop" (2 s, the hopper's slide).
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

from ..transforms import quaternion

# A unit cube centred on the origin: 24 vertices (flat normals per face), 36 indices.
_FACES = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)),
          ((0, -1, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0)), ((0, 0, -1), (1, 0, 0))]


def cube() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    positions, normals, indices = [], [], []
    for n, u in _FACES:
        n, u = np.array(n, float), np.array(u, float)
        v = np.cross(n, u)
        base = len(positions)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            positions.append(0.5 * (n + su * u + sv * v))
            normals.append(n)
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return (np.array(positions, np.float32), np.array(normals, np.float32), np.array(indices, np.uint16))


class Builder:
    """A glTF 2.0 document with one buffer (embedded as a data URI, or a GLB's BIN chunk)."""

    def __init__(self):
        self.buffer = bytearray()
        self.doc: dict = {"asset": {"version": "2.0", "generator": "ssrlab.lab.animated_gltf"},
                          "buffers": [], "bufferViews": [], "accessors": [], "meshes": [], "materials": [],
                          "nodes": [], "scenes": [], "scene": 0}
        self._cube_mesh: dict[int, int] = {}

    def accessor(self, values, gltf_type: str, *, bounds: bool = False) -> int:
        """An accessor of float32 (or uint16 SCALAR indices) values; returns its index."""
        a = np.ascontiguousarray(values)
        component = 5123 if a.dtype == np.uint16 else 5126
        if component == 5126:
            a = a.astype(np.float32)
        while len(self.buffer) % 4:
            self.buffer.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.buffer), "byteLength": a.nbytes})
        self.buffer += a.tobytes()
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[gltf_type]
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component,
               "count": a.size // width, "type": gltf_type}
        if bounds:
            flat = a.reshape(-1, width).astype(np.float64)
            acc["min"], acc["max"] = flat.min(axis=0).tolist(), flat.max(axis=0).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name: str, base_color, *, metallic: float = 0.0, roughness: float = 0.5,
                 reflectivity: float | None = None) -> int:
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(base_color) + [1.0][:4 - len(base_color)],
                                                    "metallicFactor": metallic, "roughnessFactor": roughness}}
        if reflectivity is not None:
            m["extras"] = {"reflectivity": reflectivity}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def box(self, material: int) -> int:
        """A cube mesh (1 m, centred) with `material`; the cube's accessors are shared."""
        if not self._cube_mesh:
            p, n, i = cube()
            self._cube = (self.accessor(p, "VEC3", bounds=True), self.accessor(n, "VEC3"), self.accessor(i, "SCALAR"))
        if material not in self._cube_mesh:
            pos, nrm, idx = self._cube
            self.doc["meshes"].append({"name": f"box{material}", "primitives": [
                {"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx, "material": material}]})
            self._cube_mesh[material] = len(self.doc["meshes"]) - 1
        return self._cube_mesh[material]

    def node(self, name: str, *, mesh: int | None = None, translation=None, rotation=None, scale=None, matrix=None,
             children=(), light: int | None = None, camera: int | None = None) -> int:
        n: dict = {"name": name}
        for key, value in (("mesh", mesh), ("camera", camera)):
            if value is not None:
                n[key] = value
        for key, value in (("translation", translation), ("rotation", rotation), ("scale", scale), ("matrix", matrix)):
            if value is not None:
                n[key] = [float(x) for x in np.asarray(value, float).reshape(-1)]
        if children:
            n["children"] = list(children)
        if light is not None:
            n["extensions"] = {"KHR_lights_punctual": {"light": light}}
        self.doc["nodes"].append(n)
        return len(self.doc["nodes"]) - 1

    def light(self, kind: str, *, color=(1.0, 1.0, 1.0), intensity: float = 1.0, **extra) -> int:
        ext = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})
        used = self.doc.setdefault("extensionsUsed", [])
        if "KHR_lights_punctual" not in used:
            used.append("KHR_lights_punctual")
        ext["lights"].append({"type": kind, "color": list(color), "intensity": intensity, **extra})
        return len(ext["lights"]) - 1

    def camera(self, yfov: float = 0.8, znear: float = 0.05, zfar: float = 50.0) -> int:
        self.doc.setdefault("cameras", []).append(
            {"type": "perspective", "perspective": {"yfov": yfov, "znear": znear, "zfar": zfar}})
        return len(self.doc["cameras"]) - 1

    def animation(self, name: str, channels) -> int:
        """channels: (node, path, interpolation, times (k,), values (k, c), or for CUBICSPLINE
        (k, 3, c): in-tangent, value, out-tangent per keyframe)."""
        anim = {"name": name, "channels": [], "samplers": []}
        for node, path, interpolation, times, values in channels:
            values = np.asarray(values, np.float32)
            width = values.shape[-1]
            sampler = {"input": self.accessor(np.asarray(times, np.float32), "SCALAR", bounds=True),
                       "output": self.accessor(values.reshape(-1, width), {3: "VEC3", 4: "VEC4"}[width]),
                       "interpolation": interpolation}
            anim["samplers"].append(sampler)
            anim["channels"].append({"sampler": len(anim["samplers"]) - 1, "target": {"node": node, "path": path}})
        self.doc.setdefault("animations", []).append(anim)
        return len(self.doc["animations"]) - 1

    def document(self, roots) -> dict:
        """The finished glTF JSON, the buffer embedded as a data URI."""
        doc = json.loads(json.dumps(self.doc))
        doc["scenes"] = [{"nodes": list(roots)}]
        doc["buffers"] = [{"byteLength": len(self.buffer),
                           "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.buffer)).decode()}]
        for key in ("meshes", "materials"):
            if not doc[key]:
                del doc[key]
        return doc

    def write(self, path, roots) -> Path:
        """Writes .gltf (JSON, buffer embedded) or .glb (buffer in the BIN chunk)."""
        path = Path(path)
        doc = self.document(roots)
        if path.suffix == ".glb":
            doc["buffers"] = [{"byteLength": len(self.buffer)}]
            text = json.dumps(doc).encode()
            text += b" " * (-len(text) % 4)
            binary = bytes(self.buffer) + b"\0" * (-len(self.buffer) % 4)
            body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
            path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
        else:
            path.write_text(json.dumps(doc, indent=1))
        return path


def stage() -> Builder:
    """The animated stage described above; write it with ``stage().write(path, STAGE_ROOTS)``."""
    b = Builder()
    floor = b.box(b.material("floor", (0.6, 0.6, 0.62), roughness=0.1, reflectivity=0.5))
    red = b.box(b.material("red", (0.8, 0.1, 0.08), roughness=0.4))
    blue = b.box(b.material("blue", (0.1, 0.2, 0.8), roughness=0.3))
    green = b.box(b.material("green", (0.15, 0.7, 0.2), roughness=0.5))
    lamp = b.node("Lamp", translation=(0.0, 0.9, 0.0), light=b.light("point", color=(1.0, 0.9, 0.7), intensity=1.5))
    satellite = b.node("Satellite", mesh=blue, translation=(0.9, 0.0, 0.0), scale=(0.3, 0.3, 0.3))
    spinner = b.node("Spinner", mesh=red, translation=(0.0, 0.45, 0.0), scale=(0.5, 0.5, 0.5),
                     children=[satellite, lamp])
    hopper = b.node("Hopper", mesh=green, translation=(-1.0, 0.15, 0.7), scale=(0.3, 0.3, 0.3))
    b.node("Floor", mesh=floor, translation=(0.0, -0.05, 0.0), scale=(4.0, 0.1, 4.0))
    b.node("Sun", rotation=quaternion((1.0, 0.3, 0.0), -60.0), light=b.light("directional", intensity=2.5))
    b.node("Camera", camera=b.camera(), translation=(0.0, 1.6, 3.2), rotation=quaternion((1, 0, 0), -22.0))
    b.animation("Spin", [
        (spinner, "rotation", "LINEAR", [0.0, 1.0, 2.0, 3.0],
         [quaternion((0, 1, 0), a) for a in (0.0, 120.0, 240.0, 360.0)]),
        (spinner, "translation", "CUBICSPLINE", [0.0, 1.5, 3.0],
         [[(0, 0, 0), (0, 0.45, 0), (0, 0.3, 0)], [(0, -0.2, 0), (0, 0.75, 0), (0, -0.2, 0)],
          [(0, 0.3, 0), (0, 0.45, 0), (0, 0, 0)]]),
        (hopper, "scale", "STEP", [0.0, 1.0, 2.0], [(0.3, 0.3, 0.3), (0.3, 0.5, 0.3), (0.4, 0.2, 0.4)]),
    ])
    b.animation("Hop", [(hopper, "translation", "LINEAR", [0.0, 1.0, 2.0],
                         [(-1.0, 0.15, 0.7), (-0.3, 0.15, 1.0), (-1.0, 0.15, 0.7)])])
    return b


# The stage's roots: spinner, hopper, floor, sun, camera (node indices of stage()).
STAGE_ROOTS = (2, 3, 4, 5, 6)


def write_stage(path) -> Path:
    return stage().write(path, STAGE_ROOTS)


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description="Writes the animated stage glTF.")
    ap.add_argument("path", type=Path, help="the file to write (.gltf or .glb)")
    args = ap.parse_args(argv)
    print(f"wrote {write_stage(args.path)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
