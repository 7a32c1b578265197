"""Structure-aware fuzzer for ssrlab's glTF loader.

    python benchmarks/fuzzing/fuzz_gltf.py --minutes 10 --out fuzz-findings [--seed 1]

Mutants are made from a seed corpus (the sample models and the hostile reproducers of
ssrlab.lab.hostile_gltf, the files of tests/data/hostile/) by changing the glTF's structure,
not its bytes alone: numbers become huge, negative, 2^64-ish, NaN-strings or the wrong type;
keys and array entries are deleted or duplicated; indices point past their arrays; values get nested thousands deep; uris point
at /dev/zero, a FIFO, a folder, '..', absolute paths and a symlink leading out of the folder;
primitive modes, component types and sampler enums get invalid values; GLB chunk headers
are rewritten; animation samplers get keyframes that are NaN, negative, out of order, too few or
too many, interpolations and target paths that do not exist; a few byte-level edits (truncation,
invalid UTF-8) on top.

Each batch of mutants is loaded by a child process (`Scene.load`), and every scene that
loads is rendered at 32x24 and its image checked to be finite; a scene with animations plays
them all, posed (`Scene.set_time`) at a few times, looped or clamped, before it is rendered (a
pose that cannot be drawn must be a SceneError too). A finding is anything else
than a SceneError (or FileNotFoundError) or a finite image: another exception type, a crash
(the child's signal is recorded, with the Python stack from faulthandler), a hang (no answer
within --timeout seconds), or a non-finite image. Each finding is saved under --out as the
mutant plus info.json (kind, exception, stack, exit status). Same --seed, same mutants.

Why not atheris: it installs on CPython 3.11, but its coverage feedback only sees Python code,
and all of the loader is C++ not built with libFuzzer instrumentation, so it would mutate
blind; an in-process fuzzer would also die with the first SIGSEGV. This mutator knows glTF's
structure, and running mutants in child processes turns crashes and hangs into findings.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

from ssrlab.lab import animated_gltf, hostile_gltf

# Numbers that broke (or could break) size arithmetic, float conversion and ranges.
HOSTILE_NUMBERS = [0, -1, 1, 2, 3, 4, 255, 256, 65535, 65536, 2 ** 31 - 1, 2 ** 31, 2 ** 32 - 1, 2 ** 32,
                   2 ** 53, 2 ** 63 - 1, 2 ** 63, 2 ** 64 - 4096, 2 ** 64 - 1, 2 ** 64, 10 ** 30,
                   -2 ** 31, -2 ** 63, 1e39, -1e39, 3.4e38, 1e-45, -0.0, 0.5, 1e308, -1e308, 1e-320]
WEIRD_VALUES = ["NaN", "Infinity", "-inf", "", "\u00ff\u0000x", None, True, False, [], {}, [None], {"a": 1}]
# File references to aim uris at (the trap files are made in every work folder).
HOSTILE_URIS = ["/dev/zero", "/dev/urandom", "/etc/passwd", "/", "../" * 12 + "etc/passwd",
                "%2e%2e/" * 12 + "etc/passwd", "trap.fifo", "trapdir", "trapdir/", "escape.bin",
                "huge.bin", ".", "..", "", "missing.bin", "data:", "data:application/octet-stream;base64,@@@",
                "data:image/png;base64,AAAA", "file:///etc/passwd", "sub/../../etc/passwd", "a" * 5000]
ENUM_FIELDS = {
    "mode": [-1, 0, 1, 2, 3, 4, 5, 6, 7, 255, 2 ** 31],
    "componentType": [5120, 5121, 5122, 5123, 5125, 5126, 5124, 0, 1, 99999],
    "type": ["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "VEC5", "", 3],
    "wrapS": [33071, 33648, 10497, 0, 9728, -1, 12345],
    "wrapT": [33071, 33648, 10497, 0, 9728, -1, 12345],
    "magFilter": [9728, 9729, 9984, 0, -1],
    "minFilter": [9728, 9729, 9984, 9985, 9986, 9987, 0, -1],
    "target": [34962, 34963, 0, 1],
    "mimeType": ["image/png", "image/jpeg", "image/ktx2", "text/plain", ""],
    "interpolation": ["LINEAR", "STEP", "CUBICSPLINE", "SMOOTH", "", 3],
    "path": ["translation", "rotation", "scale", "weights", "pointer", "", 7],
}
# Keyframe data an animation sampler's input or output is pointed at (times, or values).
HOSTILE_KEYFRAMES = [[0.0, 0.0, 1.0], [1.0, 0.5], [-1.0, 1.0], [float("nan"), 1.0], [float("inf")], [0.0],
                     [3.4e38, -3.4e38, 1e-45], [0.0] * 16, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0],
                     [1e30, 0.0, 0.0, 1.0] * 4, [0.0, 0.0, 0.0, 0.0] * 3]
# Scene times the child poses animations at (seconds).
HOSTILE_TIMES = [0.0, 0.25, 1.0, 2.9, -3.0, 1e30, -1e30, 1e-30, 7.5]
ARRAYS = ["accessors", "bufferViews", "buffers", "images", "textures", "samplers", "materials", "meshes",
          "nodes", "scenes", "cameras", "skins", "animations"]


# ---------------------------------------------------------------------------------------
# Seeds
# ---------------------------------------------------------------------------------------

def models_folders() -> list[Path]:
    """Where ssrlab.models looks for the sample models: $SSRLAB_MODELS, then the package's own."""
    from ssrlab import models

    return models.search_path()


def read_glb(data: bytes):
    """(json dict, bin bytes or None) of a well-formed GLB, else None."""
    try:
        magic, version, length = struct.unpack_from("<4sII", data, 0)
        jlen, jtype = struct.unpack_from("<I4s", data, 12)
        if magic != b"glTF" or jtype != b"JSON":
            return None
        doc = json.loads(data[20:20 + jlen])
        rest = 20 + jlen
        binary = None
        if rest + 8 <= len(data):
            blen, btype = struct.unpack_from("<I4s", data, rest)
            binary = data[rest + 8:rest + 8 + blen]
        return doc, binary
    except Exception:
        return None


def write_glb_text(j: bytes, binary: bytes | None) -> bytes:
    j += b" " * (-len(j) % 4)
    out = struct.pack("<I4s", len(j), b"JSON") + j
    if binary is not None:
        binary = binary + b"\0" * (-len(binary) % 4)
        out += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(out)) + out


class Seed:
    def __init__(self, path: Path):
        self.path = path
        self.glb = path.suffix == ".glb"
        data = path.read_bytes()
        self.raw = data
        self.doc, self.binary = None, None
        if self.glb:
            parsed = read_glb(data)
            if parsed:
                self.doc, self.binary = parsed
        else:
            try:
                self.doc = json.loads(data)
            except Exception:
                pass
        # Files the model refers to, copied next to each mutant.
        self.resources = [p for p in path.parent.iterdir()
                          if p.is_file() and p.suffix.lower() in (".bin", ".png", ".jpg", ".jpeg", ".exr", ".hdr")]


def seed_corpus(extra: list[Path], work: Path) -> list[Seed]:
    paths: list[Path] = []
    # The valid triangle the reproducers are made from, and the reproducers themselves.
    work.mkdir(parents=True, exist_ok=True)
    (work / "base.gltf").write_text(json.dumps(hostile_gltf.base()))
    hostile = work / "hostile"
    manifest = hostile_gltf.write(hostile)
    paths.append(work / "base.gltf")
    # An animated model: node trees and every interpolation of every path, for the animation edits.
    paths.append(animated_gltf.write_stage(work / "stage.gltf"))
    for folder in models_folders():
        if folder.is_dir():
            paths += sorted(p for p in folder.rglob("*") if p.suffix in (".gltf", ".glb"))
            break
    paths += sorted(p for p in hostile.glob("*") if p.suffix in (".gltf", ".glb") and p.stat().st_size < 100_000)
    for e in extra:
        paths += sorted(e.rglob("*.gl[tb]*")) if e.is_dir() else [e]
    seeds = [Seed(p) for p in paths]
    for s in seeds:
        s.valid = s.path.parent != hostile or "warning" in manifest.get(s.path.name, {})
    return seeds


# ---------------------------------------------------------------------------------------
# Mutations
# ---------------------------------------------------------------------------------------

def all_paths(doc, prefix=(), out=None, limit=20000):
    """Every (container, key) pair in the JSON tree, breadth-limited for big models."""
    out = [] if out is None else out
    stack = [(doc, prefix)]
    while stack and len(out) < limit:
        node, path = stack.pop()
        items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
        for k, v in items:
            out.append((node, k, path + (k,)))
            if isinstance(v, (dict, list)):
                stack.append((v, path + (k,)))
    return out


def mutate_doc(rng: random.Random, doc: dict) -> list[str]:
    """Applies 1-4 structure-aware edits in place; returns what was done."""
    done = []
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        paths = all_paths(doc)
        op = rng.randrange(13)
        if op == 0 and paths:  # a number becomes a hostile number
            nums = [p for p in paths if isinstance(p[0][p[1]], (int, float)) and not isinstance(p[0][p[1]], bool)]
            if nums:
                c, k, path = rng.choice(nums)
                c[k] = rng.choice(HOSTILE_NUMBERS)
                done.append(f"number {path} -> {c[k]!r}")
        elif op == 1 and paths:  # delete a key or element
            c, k, path = rng.choice(paths)
            del c[k]
            done.append(f"delete {path}")
        elif op == 2 and paths:  # swap a value's type
            c, k, path = rng.choice(paths)
            c[k] = copy.deepcopy(rng.choice(WEIRD_VALUES + HOSTILE_NUMBERS[:6]))
            done.append(f"type {path} -> {c[k]!r}")
        elif op == 3 and paths:  # deep nesting of a value (spliced in as text: json.dumps recurses)
            c, k, path = rng.choice(paths)
            depth = rng.choice((8, 40, 63, 65, 200, 5000, 40000))
            marker = f"\u0001nest{len(_NESTS)}"
            _NESTS[marker] = (depth, rng.random() < 0.5, c[k])
            c[k] = marker
            done.append(f"nest {path} x{depth}")
        elif op == 4:  # uris at hostile targets
            uris = [p for p in paths if p[1] == "uri"]
            target = rng.choice(HOSTILE_URIS)
            if uris:
                c, k, path = rng.choice(uris)
                c[k] = target
                done.append(f"uri {path} -> {target!r}")
            else:
                doc.setdefault("images", []).append({"uri": target})
                done.append(f"add image uri {target!r}")
        elif op == 5:  # an environment map, ambient or camera in ssrlab's extras
            scenes = doc.get("scenes")
            if isinstance(scenes, list) and scenes and isinstance(scenes[0], dict):
                x = scenes[0].setdefault("extras", {})
                if isinstance(x, dict):
                    s = x.setdefault("ssrlab", {})
                    if isinstance(s, dict):
                        what = rng.randrange(3)
                        if what == 0:
                            s["environment"] = {"type": rng.choice(("map", "sky", "constant", "x")),
                                                "map": rng.choice(HOSTILE_URIS),
                                                "color": [rng.choice(HOSTILE_NUMBERS) for _ in range(3)],
                                                "intensity": rng.choice(HOSTILE_NUMBERS)}
                        elif what == 1:
                            s["ambient"] = [rng.choice(HOSTILE_NUMBERS) for _ in range(rng.choice((2, 3, 3, 4)))]
                        else:
                            s["camera"] = {"position": [rng.choice(HOSTILE_NUMBERS) for _ in range(3)],
                                           "target": [0, 0, 0], "fov_y": rng.choice(HOSTILE_NUMBERS),
                                           "near": rng.choice(HOSTILE_NUMBERS), "far": rng.choice(HOSTILE_NUMBERS)}
                        done.append(f"ssrlab extras {sorted(s)}")
        elif op == 6 and paths:  # an enum field gets a (possibly invalid) value
            enums = [p for p in paths if p[1] in ENUM_FIELDS]
            if enums:
                c, k, path = rng.choice(enums)
                c[k] = rng.choice(ENUM_FIELDS[k])
                done.append(f"enum {path} -> {c[k]!r}")
        elif op == 7:  # an index points past its array, or a node graph gets a cycle
            nodes = doc.get("nodes")
            if isinstance(nodes, list) and nodes and rng.random() < 0.5:
                a, b = rng.randrange(len(nodes)), rng.randrange(len(nodes))
                if isinstance(nodes[a], dict):
                    nodes[a].setdefault("children", [])
                    if isinstance(nodes[a]["children"], list):
                        nodes[a]["children"].append(b)
                        done.append(f"node {a} child {b}")
            else:
                idx = [p for p in paths if p[1] in ("bufferView", "buffer", "source", "sampler", "index", "material",
                                                    "mesh", "camera", "light", "indices", "POSITION", "NORMAL",
                                                    "TEXCOORD_0", "scene", "skin", "input", "output", "node")]
                if idx:
                    c, k, path = rng.choice(idx)
                    c[k] = rng.choice((-1, -2, 1, 2 ** 31 - 1, 2 ** 31, 10 ** 6, 2 ** 64 - 1)) + (
                        c[k] if isinstance(c[k], int) and not isinstance(c[k], bool) else 0) * rng.choice((0, 1))
                    done.append(f"index {path} -> {c[k]!r}")
        elif op == 8:  # required extensions, empty or missing top-level arrays
            key = rng.choice(ARRAYS + ["extensionsRequired", "scene", "asset"])
            if key == "extensionsRequired":
                doc[key] = rng.choice((["KHR_draco_mesh_compression"], ["KHR_lights_punctual"], [3], "x"))
            elif rng.random() < 0.5:
                doc.pop(key, None)
            else:
                doc[key] = rng.choice(([], {}, [{}], [[]], "x", 0))
            done.append(f"top-level {key}")
        elif op == 9 and paths:  # duplicate an array element
            arrays = [p for p in paths if isinstance(p[0][p[1]], list) and p[0][p[1]]]
            if arrays:
                c, k, path = rng.choice(arrays)
                arr = c[k]
                arr.append(copy.deepcopy(arr[rng.randrange(len(arr))]))
                done.append(f"duplicate in {path}")
        elif op == 10:  # light values
            ext = doc.setdefault("extensions", {})
            if isinstance(ext, dict):
                lp = ext.setdefault("KHR_lights_punctual", {"lights": []})
                if isinstance(lp, dict) and isinstance(lp.get("lights"), list):
                    lp["lights"].append({"type": rng.choice(("directional", "point", "spot", "area")),
                                         "color": [rng.choice(HOSTILE_NUMBERS) for _ in range(3)],
                                         "intensity": rng.choice(HOSTILE_NUMBERS),
                                         "extras": {"direction": [rng.choice((0, 1, 1e39)) for _ in range(3)]}})
                    nodes = doc.setdefault("nodes", [])
                    if isinstance(nodes, list):
                        nodes.append({"scale": [rng.choice((0, 1, 1e-30, 1e30)) for _ in range(3)],
                                      "extensions": {"KHR_lights_punctual": {"light": len(lp["lights"]) - 1}}})
                        scenes = doc.get("scenes")
                        if isinstance(scenes, list) and scenes and isinstance(scenes[0], dict) and \
                                isinstance(scenes[0].get("nodes"), list):
                            scenes[0]["nodes"].append(len(nodes) - 1)
                    done.append("add light")
        elif op == 11 and paths:  # a node transform
            nodes = doc.get("nodes")
            if isinstance(nodes, list) and nodes and isinstance(nodes[0], dict):
                n = nodes[rng.randrange(len(nodes))]
                if isinstance(n, dict):
                    key = rng.choice(("matrix", "translation", "rotation", "scale"))
                    size = {"matrix": 16, "translation": 3, "rotation": 4, "scale": 3}[key]
                    n[key] = [rng.choice(HOSTILE_NUMBERS) for _ in range(size + rng.choice((0, 0, 0, -1, 1)))]
                    done.append(f"node transform {key}")
        elif op == 12:  # an animation sampler's keyframes: new data for its input or output
            anims = doc.get("animations")
            samplers = [s for a in anims if isinstance(a, dict) and isinstance(a.get("samplers"), list)
                        for s in a["samplers"] if isinstance(s, dict)] if isinstance(anims, list) else []
            if samplers:
                sampler = rng.choice(samplers)
                key = rng.choice(("input", "output"))
                values = rng.choice(HOSTILE_KEYFRAMES)
                width = rng.choice((1, 1, 3, 4)) if key == "output" else 1
                count = max(1, len(values) // width)
                data = struct.pack(f"<{count * width}f", *(values * width)[:count * width])
                doc.setdefault("buffers", []).append({"byteLength": len(data),
                                                      "uri": hostile_gltf.data_uri(data)})
                doc.setdefault("bufferViews", []).append({"buffer": len(doc["buffers"]) - 1, "byteLength": len(data)})
                doc.setdefault("accessors", []).append(
                    {"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": count,
                     "type": {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[width]})
                sampler[key] = len(doc["accessors"]) - 1
                done.append(f"animation {key} -> {values[:4]!r} x{width}")
    return done


_NESTS: dict[str, tuple] = {}  # marker -> (depth, arrays or objects, the value nested)


def json_text(doc) -> bytes:
    """The mutant's JSON, with deep nestings spliced in where their markers stand."""
    text = json.dumps(doc, separators=(",", ":"))
    for _ in range(4):  # a nesting can hold another one
        if "\\u0001nest" not in text:
            break
        for marker, (depth, arrays, inner) in _NESTS.items():
            quoted = json.dumps(marker)
            if quoted in text:
                body = json.dumps(inner, separators=(",", ":"))
                nested = ("[" * depth + body + "]" * depth) if arrays else ('{"x":' * depth + body + "}" * depth)
                text = text.replace(quoted, nested)
    return text.encode("utf-8", "surrogatepass")


def mutate_bytes(rng: random.Random, data: bytes, glb: bool) -> tuple[bytes, str]:
    b = bytearray(data)
    op = rng.randrange(5)
    if op == 0 and b:
        cut = rng.randrange(len(b))
        return bytes(b[:cut]), f"truncate at {cut}"
    if op == 1 and b:
        i = rng.randrange(len(b))
        b[i:i] = rng.choice((b"\xff", b"\xc0\xaf", b"\xed\xa0\x80", b"\x00", b"\xf4\x90\x80\x80"))
        return bytes(b), f"invalid UTF-8 at {i}"
    if op == 2 and glb and len(b) >= 28:
        field = rng.choice((4, 8, 12, 16))
        val = rng.choice((0, 1, 3, 19, 20, 0x7FFFFFFF, 0xFFFFFFFF, 0xFFFFFFF8, len(b), len(b) + 1, 0x4E4F534A))
        b[field:field + 4] = struct.pack("<I", val)
        return bytes(b), f"GLB header u32 at {field} -> {val:#x}"
    if op == 3 and glb and len(b) >= 28:
        j = struct.unpack_from("<I", b, 12)[0]
        at = 20 + j
        if at + 8 <= len(b):
            val = rng.choice((0, 1, 0xFFFFFFFF, 0xFFFFFFF0, len(b)))
            b[at:at + 4] = struct.pack("<I", val)
            return bytes(b), f"GLB BIN chunk length -> {val:#x}"
    if b:
        i = rng.randrange(len(b))
        b[i] ^= 1 << rng.randrange(8)
        return bytes(b), f"bit flip at {i}"
    return bytes(b), "none"


def make_mutant(rng: random.Random, seed: Seed) -> tuple[bytes, list[str]]:
    if not isinstance(seed.doc, dict) or rng.random() < 0.12:
        data, what = mutate_bytes(rng, seed.raw, seed.glb)
        return data, [what]
    doc = copy.deepcopy(seed.doc)
    try:
        done = mutate_doc(rng, doc)
    except (TypeError, KeyError, IndexError, ValueError, AttributeError) as e:  # an edit that met an odd shape
        doc, done = copy.deepcopy(seed.doc), [f"mutator skipped an edit ({type(e).__name__})"]
    if seed.glb:
        data = write_glb_text(json_text(doc), seed.binary)
    else:
        data = json_text(doc)
    if rng.random() < 0.08:
        data, what = mutate_bytes(rng, data, seed.glb)
        done.append(what)
    return data, done


def prepare_folder(folder: Path, seed: Seed) -> None:
    """A work folder per seed: the seed's resource files and the traps uris are aimed at."""
    folder.mkdir(parents=True, exist_ok=True)
    for r in seed.resources:
        if not (folder / r.name).exists():
            shutil.copy2(r, folder / r.name)
    if not (folder / "trap.fifo").exists():
        os.mkfifo(folder / "trap.fifo")
    (folder / "trapdir").mkdir(exist_ok=True)
    if not (folder / "escape.bin").is_symlink():
        (folder / "escape.bin").symlink_to("/etc/passwd")
    if not (folder / "huge.bin").exists():
        with open(folder / "huge.bin", "wb") as f:  # sparse: takes no disk space
            f.truncate(3 << 30)


# ---------------------------------------------------------------------------------------
# Child: loads and renders the mutants it is given, one JSON line per mutant
# ---------------------------------------------------------------------------------------

def child_main() -> None:
    import faulthandler
    import resource
    import traceback
    import warnings

    faulthandler.enable()
    try:  # a runaway allocation becomes MemoryError/bad_alloc, not the OOM killer
        limit = int(os.environ.get("FUZZ_MEMORY_LIMIT", str(8 << 30)))
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (ValueError, OSError):
        pass
    import numpy as np

    import ssrlab

    warnings.simplefilter("ignore")
    renderer = ssrlab.Renderer(os.environ.get("FUZZ_DEVICE", "auto"))
    settings = ssrlab.Settings(width=32, height=24)
    print("READY", flush=True)
    for line in sys.stdin:
        job = json.loads(line)
        print("BEGIN " + str(job["id"]), flush=True)
        if job.get("selftest") == "crash":  # --selftest: the parent must record these
            os.kill(os.getpid(), signal.SIGSEGV)
        if job.get("selftest") == "hang":
            time.sleep(3600)
        result = {"id": job["id"], "outcome": "refused"}
        try:
            scene = ssrlab.Scene.load(job["path"], allow_external_files=job["external"])
        except (ssrlab.SceneError, FileNotFoundError) as e:
            result["message"] = str(e)[:300]
        except BaseException as e:  # noqa: BLE001 - every other type is a finding
            result.update(outcome="exception", exception=type(e).__name__, message=str(e)[:2000],
                          stack=traceback.format_exc())
        else:
            result["outcome"] = "loaded"
            if scene.object_count:
                try:
                    camera = scene.camera
                    if camera is None:
                        lo, hi = (np.asarray(v, float) for v in scene.bounds)
                        c = (lo + hi) / 2
                        r = max(float(np.linalg.norm(hi - lo)) / 2, 1e-4 * float(np.abs(c).max()), 1e-3)
                        camera = ssrlab.Camera(position=tuple(c + [0, 0, 3 * r]), target=tuple(c),
                                               near=r * 0.01, far=r * 10)
                    if scene.animations:  # posed at the job's times first; the last pose is rendered
                        scene.play(loop=job.get("loop", False))
                        for t in job.get("times", []):
                            scene.set_time(t)
                    frame = renderer.render(scene, camera, settings)
                    color = np.asarray(frame.color)
                    result["outcome"] = "rendered"
                    if not np.isfinite(color).all():
                        result.update(outcome="nonfinite", message=f"{int((~np.isfinite(color)).sum())} non-finite values")
                except ssrlab.SceneError as e:  # a pose that cannot be drawn, refused by name
                    result.update(outcome="refused", message=str(e)[:300])
                except BaseException as e:  # noqa: BLE001
                    result.update(outcome="render-exception", exception=type(e).__name__, message=str(e)[:2000],
                                  stack=traceback.format_exc())
        print("RESULT " + json.dumps(result), flush=True)


# ---------------------------------------------------------------------------------------
# Parent: makes mutants, runs children, records findings
# ---------------------------------------------------------------------------------------

FINDINGS = {"exception", "render-exception", "nonfinite", "crash", "hang"}


class Child:
    def __init__(self, device: str):
        env = dict(os.environ, FUZZ_DEVICE=device, PYTHONFAULTHANDLER="1")
        self.stderr_path = Path(os.environ.get("TMPDIR", "/tmp")) / f"fuzz_gltf_child_{os.getpid()}.err"
        self.stderr = open(self.stderr_path, "w+b")
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--child"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=self.stderr, env=env, text=True, bufsize=1)
        os.set_blocking(self.proc.stdout.fileno(), False)
        self.buffer = ""

    def readline(self, timeout: float) -> str | None:
        """The next line, or None on timeout or end of output."""
        import select
        end = time.monotonic() + timeout
        while "\n" not in self.buffer:
            left = end - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([self.proc.stdout], [], [], left)
            if ready:
                chunk = self.proc.stdout.read()
                if not chunk:
                    if self.proc.poll() is not None:
                        return None
                    continue
                self.buffer += chunk
        line, self.buffer = self.buffer.split("\n", 1)
        return line

    def stderr_tail(self) -> str:
        self.stderr.flush()
        self.stderr.seek(0)
        return self.stderr.read()[-6000:].decode("utf-8", "replace")

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        self.stderr.close()
        self.stderr_path.unlink(missing_ok=True)


def save_finding(out: Path, n: int, mutant: Path, info: dict) -> Path:
    folder = out / f"finding_{n:04d}_{info['outcome']}"
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy2(mutant, folder / mutant.name)
    (folder / "info.json").write_text(json.dumps(info, indent=1))
    return folder


def run(args) -> dict:
    rng = random.Random(args.seed)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = out / "work"
    seeds = seed_corpus([Path(p) for p in args.corpus], work)
    for i, s in enumerate(seeds):
        prepare_folder(work / f"seed{i:02d}", s)
    valid = [i for i, s in enumerate(seeds) if s.valid]  # mutated more often: their mutants reach further
    deadline = time.monotonic() + args.minutes * 60
    stats = {"mutants": 0, "refused": 0, "loaded": 0, "rendered": 0, "findings": 0, "seeds": len(seeds),
             "seed": args.seed, "minutes": args.minutes, "by_outcome": {}}
    child: Child | None = None
    n = 0
    started = time.monotonic()
    while time.monotonic() < deadline and (args.max_mutants is None or n < args.max_mutants):
        si = rng.randrange(len(seeds)) if rng.random() < 0.4 or not valid else rng.choice(valid)
        seed = seeds[si]
        data, what = make_mutant(rng, seed)
        external = rng.random() < 0.25
        mutant = work / f"seed{si:02d}" / f"mutant{seed.path.suffix}"
        mutant.write_bytes(data)
        n += 1
        selftest = args.selftest[n - 1] if args.selftest and n <= len(args.selftest) else None
        if child is None:
            child = Child(args.device)
            if child.readline(120) != "READY":
                raise SystemExit("fuzz child did not start:\n" + child.stderr_tail())
        job = {"id": n, "path": str(mutant), "external": external, "selftest": selftest,
               "times": rng.sample(HOSTILE_TIMES, 3), "loop": rng.random() < 0.5}
        child.proc.stdin.write(json.dumps(job) + "\n")
        child.proc.stdin.flush()
        begin = child.readline(30)
        line = child.readline(args.timeout) if begin == f"BEGIN {n}" else None
        info = {"id": n, "seed_file": str(seed.path), "mutations": what, "allow_external_files": external}
        if line and line.startswith("RESULT "):
            info.update(json.loads(line[7:]))
        else:
            if child.proc.poll() is None:
                info.update(outcome="hang", message=f"no answer within {args.timeout} s")
                child.proc.send_signal(signal.SIGABRT)  # faulthandler prints the stack on SIGABRT
                try:
                    child.proc.wait(5)
                except subprocess.TimeoutExpired:
                    pass
            else:
                rc = child.proc.returncode
                info.update(outcome="crash", exit_status=rc,
                            message=f"child died with {'signal ' + signal.Signals(-rc).name if rc < 0 else 'exit ' + str(rc)}")
            info["stderr"] = child.stderr_tail()
            child.kill()
            child = None
        stats["mutants"] += 1
        outcome = info["outcome"]
        stats["by_outcome"][outcome] = stats["by_outcome"].get(outcome, 0) + 1
        if outcome == "refused":
            stats["refused"] += 1
        elif outcome in ("loaded", "rendered"):
            stats["loaded"] += 1
            stats["rendered"] += outcome == "rendered"
        if outcome in FINDINGS:
            stats["findings"] += 1
            folder = save_finding(out, stats["findings"], mutant, info)
            print(f"FINDING {outcome}: {info.get('exception', '')} {info.get('message', '')[:200]} -> {folder}",
                  flush=True)
        if args.verbose:
            print(f"{n}: {outcome} {what}", flush=True)
    if child is not None:
        child.proc.stdin.close()
        child.kill()
    stats["seconds"] = round(time.monotonic() - started, 1)
    (out / "summary.json").write_text(json.dumps(stats, indent=1))
    if not args.keep_work:
        shutil.rmtree(work, ignore_errors=True)
    return stats


def main(argv=None) -> int:
    if argv is None and sys.argv[1:2] == ["--child"]:
        child_main()
        return 0
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=1.0, help="time budget")
    ap.add_argument("--max-mutants", type=int, default=None, help="stop after this many mutants")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="fuzz-findings", help="folder for findings and summary.json")
    ap.add_argument("--corpus", nargs="*", default=[], help="extra seed files or folders")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds a mutant may take before it is a hang")
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    ap.add_argument("--keep-work", action="store_true", help="keep the work folder with the last mutants")
    ap.add_argument("--verbose", action="store_true")
    ap.add_argument("--selftest", nargs="*", choices=("crash", "hang", "none"), default=[],
                    help="make the first children crash or hang on purpose, to check that both are recorded")
    args = ap.parse_args(argv)
    stats = run(args)
    print(f"fuzz_gltf: {stats['mutants']} mutants in {stats['seconds']} s from {stats['seeds']} seeds (seed "
          f"{args.seed}): {stats['refused']} refused with SceneError/FileNotFoundError, {stats['loaded']} loaded "
          f"({stats['rendered']} rendered at 32x24, all finite unless listed), {stats['findings']} findings "
          f"-> {Path(args.out) / 'summary.json'}")
    return 1 if stats["findings"] else 0


if __name__ == "__main__":
    sys.exit(main())
