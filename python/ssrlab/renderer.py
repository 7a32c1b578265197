"""The renderer and its frames.

``Renderer`` owns a headless OpenGL 4.5 context (EGL): the GPU's EGL device when there is
one, Mesa's llvmpipe otherwise. ``Renderer.render`` runs the frame's chain of passes and
returns a ``Frame`` whose images stay on the GPU until a property reads them (then they
are cached as float32 numpy arrays, row 0 at the top of the image).
"""

from __future__ import annotations

import functools
import os
import warnings
import weakref
from pathlib import Path

import numpy as np

from . import _core, workload
from .animation import seconds_array
# The frame, its views and the chain live in modules of their own; their names stay importable from here.
from .chain import Chain, ChainPass, RasterFloor  # noqa: F401
from .frame import TRACE_SUMS, Frame, FrameStats  # noqa: F401
from .frame_views import GBuffer, RayResults, Reprojection  # noqa: F401
from .settings import Settings


class NoReflectionWarning(UserWarning):
    """A render that asked for reflections traced none: nothing in the scene reflects."""


from ._package import shader_dir  # noqa: E402  (re-exported: ssrlab.shader_dir)


DEVICE_ENV = "SSRLAB_DEVICE"
# The construction deep_gbuffer 'auto' takes from its measurements ({method: {median, min, max}}),
# decided natively with every other 'auto' (cpp/render/auto_choice.h).
choose_deep_gbuffer = _core.choose_deep_gbuffer


def check_device(device, name: str = "Renderer.device") -> str:
    """`device` if it is "auto", "gpu", "gpu:N" or "cpu"; ValueError naming `name` otherwise."""
    if isinstance(device, str) and (device in ("auto", "gpu", "cpu") or
                                    (device.startswith("gpu:") and device[4:].isdigit() and device[4:].isascii())):
        return device
    raise ValueError(f"{name} must be 'auto', 'gpu', 'gpu:N' (N = 0, 1, ...) or 'cpu', got {device!r}")


def resolve_device(device) -> str:
    """The device a Renderer opens: `device`, or for "auto" the one $SSRLAB_DEVICE pins this
    process to (where set and not empty)."""
    device = check_device(device)
    pinned = os.environ.get(DEVICE_ENV, "").strip()
    if device == "auto" and pinned:
        return check_device(pinned, f"${DEVICE_ENV}")
    return device


def devices(probe: bool = True) -> list[dict]:
    """Every EGL device: index (N of device="gpu:N"; None for a software device), device
    ("gpu:N" or "cpu"), vendor, renderer and gl_version (from an OpenGL 4.5 context made and
    closed on it, with probe; error says why none could be made), egl_device_extensions,
    drm_device (the /dev/dri file, EGL_EXT_device_drm) and cuda_device (EGL_NV_device_cuda:
    the CUDA device number, which may differ from the EGL order)."""
    return list(_core.devices(probe))


class Renderer:
    """A headless renderer.

    device: "auto" (the GPU's EGL device when there is one, else llvmpipe), "gpu" (raise
    DeviceError when there is no GPU), "gpu:N" (the N-th hardware EGL device, as ssrlab.devices()
    and `ssrlab info` number them; DeviceError naming the devices found where there is none) or
    "cpu" (Mesa's llvmpipe). "auto" takes $SSRLAB_DEVICE where that is set, which is how a
    process (a sweep worker) is pinned to one GPU of several: SSRLAB_DEVICE=gpu:3.
    input_fetch: how the passes read their float inputs (shaders/lib/input_fetch.glsl):
    "auto" (imageLoad on the CPU device, where llvmpipe's texelFetch of a float format is a call to
    a generic sampling function; texelFetch on a GPU, the path measured there), "imageLoad" or
    "texelFetch". The images are the same either way (tests/test_input_fetch.py); info["input_fetch"]
    says which is used.
    It renders any number of scenes, cameras and settings, and may be used from any thread, one
    call at a time (its GL context is current only during a call).

    Long work says so before it starts (ssrlab.workload): before render, render_sequence and
    prepare draw anything, the renderer estimates the work from the scene's drawn triangles
    (Scene.triangle_count, an instanced mesh once per instance), the geometry passes the settings
    make over them and the device's rates (Renderer.estimate). Where the estimate reaches
    ssrlab.workload.LONG_SECONDS, a SceneWarning names the scene, the triangle count and the
    estimate. max_triangles: a budget of drawn triangles; a scene beyond it is refused with a
    SceneError naming the scene, the count and the budget, before anything is drawn. None (the
    default) takes $SSRLAB_MAX_TRIANGLES where it is set (20000000 or 2e7), else no budget; 0: no
    budget whatever the variable says. Renderer.max_triangles reads and changes it, and
    triangle_rates sets the rates the estimate assumes ({"draw": triangles a second a geometry pass,
    "bvh": triangles a second into the BVH}; None: ssrlab.workload.RATES, measured on llvmpipe and
    used as an upper bound on a GPU).
    """

    def __init__(self, device: str = "auto", *, shader_dir: str | Path | None = None, input_fetch: str = "auto",
                 max_triangles: int | None = None):
        device = resolve_device(device)
        folder = Path(shader_dir) if shader_dir is not None else globals()["shader_dir"]()
        self._native = _core.Renderer(device=device, shader_dir=str(folder), input_fetch=input_fetch)
        self.device = device
        # What a second renderer of the same device and shaders is made with (the live viewer
        # makes one when a shader file changes: its shader library reads every file again).
        self._shader_dir, self._input_fetch = folder, input_fetch
        self._frames: "weakref.WeakSet[Frame]" = weakref.WeakSet()
        # Settings.deep_gbuffer 'auto': the method measured faster, per scene, size and layers.
        self._deep_gbuffer_auto: dict[tuple, str] = {}
        self.deep_gbuffer_measurements: dict[tuple, dict[str, dict[str, float]]] = {}
        # The work a render will be (ssrlab.workload): the triangle budget, the rates, and the
        # scene geometries whose BVH this renderer has built.
        self._max_triangles = (workload.budget_from_env() if max_triangles is None else
                               workload.check_budget(max_triangles, "Renderer(max_triangles=...)"))
        self.triangle_rates: dict | None = None
        self._bvh_built: set[tuple] = set()

    @property
    def max_triangles(self) -> int | None:
        """The budget of drawn triangles (instances included) beyond which a render is refused
        with a SceneError before anything is drawn; None: no budget. Set it to an int >= 1, or None
        (or 0) for no budget."""
        return self._max_triangles

    @max_triangles.setter
    def max_triangles(self, value: int | None) -> None:
        self._max_triangles = workload.check_budget(value)

    def estimate(self, scene: _core.Scene, settings: Settings | None = None, *, frames: int = 1,
                 **overrides) -> "workload.Estimate":
        """What rendering `scene` with `settings` (`frames` frames of a sequence) will cost on this
        renderer's device, without rendering: its drawn triangles, geometry passes, whether a BVH is
        built first and the seconds (ssrlab.workload.Estimate). This is what render and
        render_sequence check before they start: a long estimate warns, a scene beyond
        max_triangles is refused."""
        settings = settings if settings is not None else Settings()
        if overrides:
            settings = settings.replace(**overrides)
        if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
            raise ValueError(f"Renderer.estimate: frames must be an int >= 1, got {frames!r}")
        device = self.info["device"]
        return workload.estimate(
            scene, settings, device=device, frames=frames,
            measures_auto=self._deep_gbuffer_key(scene, settings) not in self._deep_gbuffer_auto,
            builds_bvh=(id(scene), scene.geometry_revision) not in self._bvh_built, rates=self.triangle_rates)

    def _check_workload(self, scene, settings: Settings, what: str, frames: int = 1) -> None:
        """Before a render draws anything: refuses a scene beyond max_triangles (SceneError), warns
        where the work will be long (SceneWarning, pointing at the caller of `what`)."""
        workload.check(self.estimate(scene, settings, frames=frames), self._max_triangles, what, stacklevel=3)

    def _drew(self, scene, settings: Settings) -> None:
        """Records what a render left built: the scene's BVH where the settings trace it."""
        if workload.needs_bvh(settings):
            self._bvh_built.add((id(scene), scene.geometry_revision))

    @property
    def live_frames(self) -> list["Frame"]:
        """The frames of this renderer still alive and not released (each holds its textures)."""
        return [f for f in list(self._frames) if not f.released]

    @property
    def gpu_bytes(self) -> int:
        """Bytes of GPU textures held: every live frame's, the pool of idle texture sets kept
        for reuse (at most 4) and the scratch shared by all frames (shadow map, Hi-Z)."""
        return int(self._native.gpu_bytes)

    @property
    def scratch_bytes(self) -> int:
        """Bytes of the GPU scratch that every frame of this renderer shares (shadow map, Hi-Z)."""
        return int(self._native.scratch_bytes)

    @property
    def stats(self) -> dict[str, float]:
        """What this renderer did outside the frames' chains, counted since it was made:
        scene_uploads (GPU copies of a scene built, its geometry uploaded: a new scene or new
        geometry, images or objects; a new camera or new settings reuse the copy),
        scene_updates (a copy brought up to date after Scene.set_object_transform,
        set_material or a lights' change: object_updates and material_updates entries
        rewritten, no geometry uploaded), bvh_builds (the BVH of method "bvh", the fallbacks and
        the references, once per scene geometry), bvh_updates (after moves: the moved objects'
        trees rebuilt, bvh_updated_triangles in all; bvh_update_ms the last update's wall
        milliseconds and bvh_update_last_triangles its triangles), readbacks and readback_bytes
        (textures copied to host memory: only when a Frame property or read() asks, once per
        texture and level). Counts are ints, bvh_update_ms a float."""
        return {k: float(v) if k.endswith("_ms") else int(v) for k, v in self._native.stats.items()}

    @property
    def readback_path(self) -> str:
        """How textures reach numpy: "auto" (staged on a GPU, download on the CPU device),
        "download" (the driver's download of float formats; a copy pass decodes the others) or
        "staged" (every format through the copy pass into a buffer, copied by the GPU into pinned
        client memory and from there into the array by several threads). The values are the same
        whichever path (tests/test_readback.py); benchmarks/timing/readback.py times them."""
        return self._native.readback_path

    @readback_path.setter
    def readback_path(self, path: str) -> None:
        self._native.readback_path = path  # the native side checks the name
        self.__dict__.pop("info", None)  # info["readback_path"] follows

    @property
    def clear_path(self) -> str:
        """How the passes clear textures: "auto" (image stores on a GPU, GL clears on the CPU
        device), "gl" (glClearTexSubImage and framebuffer clears) or "compute" (image stores of a
        compute shader; a GPU built for compute, such as NVIDIA's H100 and H200, has few raster
        units, and its GL clears ran at a tenth of its memory bandwidth: benchmarks/timing/peel_profile.py).
        The G-buffer's layers, which are render targets, keep framebuffer clears on every path (the
        first image store into a new render target cost far more there). The images are the same
        either way (tests/test_clear_path.py)."""
        return self._native.clear_path

    @clear_path.setter
    def clear_path(self, path: str) -> None:
        self._native.clear_path = path  # the native side checks the name
        self.__dict__.pop("info", None)

    @property
    def visibility_tiles(self) -> str:
        """Whether the visibility constructions of the deep G-buffer (Settings.deep_gbuffer
        'visibility', 'visibility_lists') mark each layer's covered 8x8 tiles as they build them, and
        the attribute pass classifies the deeper layers over those tiles only: "auto" (on the CPU
        device, where llvmpipe shades every pixel a dispatch covers; a GPU is not stalled to read the
        tiles back), "on" or "off". The images are the same either way
        (tests/test_visibility_buffer.py)."""
        return self._native.visibility_tiles

    @visibility_tiles.setter
    def visibility_tiles(self, mode: str) -> None:
        self._native.visibility_tiles = mode  # the native side checks the name
        self.__dict__.pop("info", None)

    @functools.cached_property
    def info(self) -> dict:
        """Vendor, renderer, GL version and the device chosen."""
        return dict(self._native.info())

    def render(self, scene: _core.Scene, camera: _core.Camera | None = None,
               settings: Settings | None = None, **overrides) -> "Frame":
        """Renders `scene` seen by `camera` (default: the scene's own camera).

        `overrides` change single settings: ``render(scene, layers=4)``.
        """
        settings = settings if settings is not None else Settings()
        if not isinstance(settings, Settings):
            raise TypeError(f"settings must be an ssrlab.Settings, got {type(settings).__name__}")
        if overrides:
            settings = settings.replace(**overrides)
        if camera is None:
            camera = scene.camera
            if camera is None:
                raise ValueError("render: the scene has no default camera; pass camera=ssrlab.Camera(...)")
        self._check_workload(scene, settings, "Renderer.render")
        _warn_depth_precision(camera, settings)
        self._register_modules(settings)
        settings = self._decide_deep_gbuffer(scene, camera, settings)
        settings = settings.resolved(self.info["device"])  # 'auto' decided for this device
        native = self._native.render(scene, camera, settings.to_native())
        self._drew(scene, settings)
        frame = Frame(native, settings, renderer=self, scene=scene)
        if settings.method != "off" and not frame.traced:
            warnings.warn(f"render traced no reflection rays: no surface of scene {scene.name!r} reflects "
                          "(every material has reflectivity 0; glTF materials reflect by default with "
                          "reflectivity='auto')", NoReflectionWarning, stacklevel=2)
        self._frames.add(frame)
        return frame

    def register_pass(self, user_pass) -> None:
        """Registers a user pass (ssrlab.UserPass) on this renderer: checked against its passes (a
        pass reads only what an earlier pass writes, writes only its stage's resources, or, placed
        without a stage, any declared texture an image store can write, and the textures it
        creates; a place no chain could give it is refused: ValueError naming the pass, the
        resource and its owner). A render runs it where Settings.user_passes names it
        (docs/guide/your-first-technique.md). It serves this renderer only: a pass that other
        processes (a sweep's workers) must run belongs in a module named by Settings.user_modules,
        whose passes every renderer rendering with those settings registers itself."""
        from .user_pass import UserPass, declare

        if not isinstance(user_pass, UserPass):
            raise TypeError(f"register_pass takes an ssrlab.UserPass, got {type(user_pass).__name__}")
        declare(user_pass, check_only=True)
        self._native.register_user_pass(*user_pass.native_args())
        declare(user_pass)
        self.__dict__.setdefault("_user_passes", {})[user_pass.name] = user_pass

    @property
    def user_passes(self) -> dict:
        """The user passes registered on this renderer, by name."""
        return dict(self.__dict__.get("_user_passes", {}))

    def _register_modules(self, settings: Settings) -> None:
        """Registers the passes of every module Settings.user_modules names that this renderer has
        not registered yet (the modules were loaded, once per process, when the settings were made)."""
        from .user_pass import load_module

        for spec in settings.user_modules:
            for p in load_module(spec):
                have = self.user_passes.get(p.name)
                if have is None or have.native_args() != p.native_args():
                    self.register_pass(p)  # a different pass of that name: refused, naming it

    def chain(self, settings: Settings | None = None, scene: _core.Scene | None = None, **overrides) -> "Chain":
        """The passes a render with `settings` runs, in order, each with the resources it reads and
        writes: what ``render(scene, settings=settings).passes`` lists, without rendering. Which
        passes run depends on the scene too (a shadow-casting light, surfaces that reflect); without
        one, ``ssrlab.scenes.stand_in()`` stands in: a mirror floor and a wall lit by a sun that casts
        a shadow, so that the chain is the one a render of that scene runs (``shadow_map`` in it).
        Nothing is uploaded and no GL call is made: the chain is a function of the settings, the
        scene's facts and the renderer's device (``ssrlab.chain.derive`` lists it without one)."""
        settings = settings if settings is not None else Settings()
        if overrides:
            settings = settings.replace(**overrides)
        if scene is None:
            from .scenes import stand_in

            scene = stand_in()
        self._register_modules(settings)
        settings = settings.resolved(self.info["device"])
        return Chain.from_native(self._native.chain(scene, settings.to_native()))

    def render_sequence(self, scene: _core.Scene, cameras, settings: Settings | None = None, *, times=None,
                        **overrides):
        """Renders the frames of a sequence and yields their Frames in order.

        `cameras`: a list of ssrlab.Camera, an ssrlab.CameraPath, or with `times` one Camera that
        every frame shares. `times`: the scene time of each frame in seconds (frame.time); before
        rendering frame i the scene is posed at times[i] (Scene.set_time: its glTF animations
        and the motions given with Scene.animate), so a fixed camera with moving objects works
        as well as a moving camera. Without `times` the scene is left as it is.

        Frame i is rendered with seed ``settings.seed + i`` (so every frame draws new rays) and,
        with a temporal technique on (Settings.temporal_reflections), reads the previous frame's
        textures: the renderer keeps them between the frames of this sequence and drops them at
        its end (when the generator is exhausted or closed). Each Frame reports its own timings,
        the temporal passes' included.
        """
        settings = settings if settings is not None else Settings()
        if not isinstance(settings, Settings):
            raise TypeError(f"settings must be an ssrlab.Settings, got {type(settings).__name__}")
        if overrides:
            settings = settings.replace(**overrides)
        if times is not None:
            times = [float(t) for t in seconds_array(times, "render_sequence: times")]
            if not hasattr(scene, "set_time"):
                raise TypeError("render_sequence: times needs an ssrlab.Scene (it poses the scene with Scene.set_time)")
            if isinstance(cameras, _core.Camera):
                cameras = [cameras] * len(times)
        cameras = list(cameras)
        if not cameras:
            raise ValueError("render_sequence: cameras is empty")
        for i, c in enumerate(cameras):
            if not isinstance(c, _core.Camera):
                raise TypeError(f"render_sequence: cameras[{i}] must be an ssrlab.Camera, got {type(c).__name__}")
        if times is not None and len(times) != len(cameras):
            raise ValueError(f"render_sequence: {len(times)} times for {len(cameras)} cameras; give one time per "
                             "camera, or one Camera for every time")
        # At the call, not at the first frame the generator is asked for: the whole sequence's work.
        self._check_workload(scene, settings, "Renderer.render_sequence", frames=len(cameras))
        return self._sequence(scene, cameras, settings, times)

    def _sequence(self, scene, cameras, settings, times=None):
        self._register_modules(settings)
        if times is not None:
            scene.set_time(times[0])  # the state 'auto' measures below
        # deep_gbuffer 'auto' is measured before the sequence starts, on its first camera.
        settings = self._decide_deep_gbuffer(scene, cameras[0], settings)
        sequence = self._native.begin_sequence()
        try:
            for i, camera in enumerate(cameras):
                if times is not None:
                    scene.set_time(times[i])
                s = settings.replace(seed=(settings.seed + i) % 2**31).resolved(self.info["device"])
                _warn_depth_precision(camera, s)
                native = self._native.render(scene, camera, s.to_native(), sequence)
                self._drew(scene, s)
                frame = Frame(native, s, renderer=self, scene=scene)
                frame.time = None if times is None else times[i]
                self._frames.add(frame)
                yield frame
        finally:
            del sequence  # the history's textures go with it

    def _decide_deep_gbuffer(self, scene, camera, settings: Settings) -> Settings:
        """Settings.deep_gbuffer 'auto' made one exact construction: the one that builds this
        scene's layers fastest on this device, measured once per renderer, scene (and its geometry:
        Scene.geometry_revision; moving an object or editing a material measures nothing again),
        image size, layer count, culling, depth mode and minimum separation: the G-buffer alone
        (no shadow map, no reflections) is built 3 times with each after a warm-up render
        (recorded in deep_gbuffer_measurements: median, min and max GPU ms). Which constructions
        are measured on this device for this layer count, and which measurement wins (peeling, the
        reference construction, unless another is faster beyond the spread), is decided natively
        with every other 'auto' (_core.deep_gbuffer_candidates and _core.choose_deep_gbuffer,
        cpp/render/auto_choice.cpp). The constructions keep the same layers, depths and object ids
        bit for bit; the visibility ones' attributes differ from peeling's within the tolerance
        docs/deep_gbuffer.md states, so a script that needs bit-identical reruns names its
        construction."""
        if settings.deep_gbuffer != "auto":
            return settings
        candidates = _core.deep_gbuffer_candidates(self.info["device"] == "cpu", settings.layers)
        if len(candidates) == 1:
            return settings.replace(deep_gbuffer=candidates[0])
        key = self._deep_gbuffer_key(scene, settings)
        if key not in self._deep_gbuffer_auto:
            # With a minimum separation the lists' selection walks each list once per layer.
            base = Settings(width=settings.width, height=settings.height, layers=settings.layers,
                            backface_culling=settings.backface_culling, depth_mode=settings.depth_mode,
                            min_separation=settings.min_separation, method="off", shadow_map_size=0)
            try:
                measured = self._measure_deep_gbuffer(scene, camera, base, candidates)
            except ValueError:
                # Settings this device refuses (a frame beyond its memory, ...): the render
                # itself raises its own error, naming the settings as given.
                return settings.replace(deep_gbuffer="peel")
            self.deep_gbuffer_measurements[key] = measured
            self._deep_gbuffer_auto[key] = choose_deep_gbuffer(measured)
        return settings.replace(deep_gbuffer=self._deep_gbuffer_auto[key])

    @staticmethod
    def _deep_gbuffer_key(scene, settings: Settings) -> tuple:
        """What deep_gbuffer 'auto''s measurement is kept for: the scene and its geometry, the size,
        layers, culling, depth mode and minimum separation."""
        return (id(scene), scene.geometry_revision, settings.width, settings.height, settings.layers,
                settings.backface_culling, settings.depth_mode, settings.min_separation)

    def _measure_deep_gbuffer(self, scene, camera, base: Settings, methods) -> dict[str, dict[str, float]]:
        """GPU milliseconds of the G-buffer's construction with each exact method: median, min, max."""
        measured = {}
        for method in methods:
            s = base.replace(deep_gbuffer=method).resolved(self.info["device"])
            times = []
            for run in range(4):
                f = Frame(self._native.render(scene, camera, s.to_native()), s, renderer=self, scene=scene)
                if run > 0:  # the first render compiles and sizes the lists' store
                    times.append(f.timings["deep_gbuffer"])
                # A frame that fell back to peeling is no measurement of the lists.
                if method.endswith("lists") and f.stats.get("deep_gbuffer_method") != method:
                    times = [float("inf")]
                    f.release()
                    break
                f.release()
            measured[method] = {"median": float(np.median(times)), "min": float(min(times)), "max": float(max(times))}
        return measured

    def prepare(self, settings: Settings | None = None, scene=None, camera=None) -> None:
        """Compiles and warms up every program the frame chain of `settings` uses, so that the
        first timed render pays no compilation (render() also does this by itself: the first
        render of a new variant runs the chain once untimed, see Frame.warmup_runs). Without a
        scene, ``ssrlab.scenes.stand_in()`` stands in (a mirror floor and a wall lit by a sun that
        casts a shadow: what Renderer.chain lists without a scene)."""
        if scene is None:
            from .scenes import stand_in

            scene = stand_in()
        self.render(scene, camera, settings)

    @property
    def compiled_programs(self) -> int:
        """Shader programs compiled so far (each once per variant)."""
        return self._native.compiled_programs

    def specular_albedo_table(self) -> np.ndarray:
        """(32, 32, 2) split-sum table (A, B) of the GGX directional albedo E = F0 A + B, rows
        perceptual roughness 0..1, columns n.v 0..1 (see shaders/lib/specular_albedo.glsl)."""
        return np.asarray(self._native.specular_albedo_table())

    def sample_reflections(self, sampling: str, alpha: float, view, count: int, *, seed: int = 0,
                           stratified: bool = False) -> dict[str, np.ndarray]:
        """Reflection directions drawn by the very GLSL the tracers use, for a view direction
        in the local frame where the surface normal is +z (view.z > 0) and GGX alpha.

        Returns l (count, 3), weight (count,), pdf (count,) and u (count, 2), the uniform
        numbers used; with stratified=True they form a randomly offset Hammersley set. reuse
        (count,) is the resolve's BRDF reuse weight f_r(v, l)(n.l) / pdf for each direction
        (brdf.glsl's brdf_cosine_over_pdf; 0 where pdf or weight is 0), which for a sample's
        own view must equal its weight.
        """
        a = self._native.sample_reflections(sampling, float(alpha), tuple(map(float, view)), int(count),
                                            int(seed), bool(stratified))
        return {"l": a[:, :3], "weight": a[:, 3], "pdf": a[:, 4], "u": a[:, 5:7], "reuse": a[:, 7]}

    def microbenchmark(self, kernel: str, width: int, height: int, iterations: int, repeats: int = 5) -> list[float]:
        """GPU milliseconds of each of `repeats` runs of a device-peak kernel (the roofline,
        shaders/tools/microbench.comp, benchmarks/timing/roofline.py), after one untimed run: 'coherent'
        (RG32F texelFetch, neighbours fetching neighbours), 'dependent' (each fetch's address is
        the previous fetch's result), 'dependent_image' (the same chain by imageLoad, the path the
        passes read float inputs by on the CPU device: info["input_fetch"]), 'store' (RGBA16F
        imageStore), 'bandwidth' (RGBA32F texels each
        read once), 'copy' (one RGBA16F fetch and one RGBA32F store per texel) or 'copy_image' (the
        same by imageLoad), one invocation per
        texel of width x height and `iterations` operations each (1 for 'copy'; at most 16 for
        'store' and 'bandwidth')."""
        return list(self._native.microbenchmark(kernel, int(width), int(height), int(iterations), int(repeats)))

    def raster_floor(self, scene: _core.Scene, camera: _core.Camera | None = None, settings: Settings | None = None,
                     *, repeats: int = 7, **overrides) -> "RasterFloor":
        """The device's floors under the deep G-buffer's constructions, on `scene`'s own triangles
        seen by `camera` (default: the scene's) at the settings' size, depth mode and culling
        (``overrides`` change single settings: ``raster_floor(scene, width=1920, height=1080)``):
        the scene drawn with its own vertex and index buffers through the G-buffer's vertex shader
        (passes/depth_peel.vert) by fragment stages that only write (shaders/tools/raster_floor.*).
        Every floor runs once untimed (compilation, first use), then `repeats` times, each in turn
        (interleaved) and each timed alone by GPU timer queries. Floors (RasterFloor.ms):

        - ``depth``: a depth-only draw (what each layer's depth pass of peeling does at least);
        - ``gbuffer``: depth and constants into the G-buffer's three colour targets (sRGB RGBA8,
          RGBA16F, RGBA8) through the raster outputs, one layer the way peeling writes it;
        - ``id``: depth and a 32-bit triangle id (R32UI), one layer of a visibility buffer;
        - ``append``: every fragment's 8 bytes (depth, id) into per-pixel arrays at offsets from an
          untimed count, without a depth test (one atomic and one store a fragment);
          ``append_list``: the same into linked lists (global slot counter, link, head exchange:
          12 bytes a fragment, the structure deep_gbuffer 'visibility_lists' builds); both left
          out where the fragments exceed the device's largest storage block;
        - ``stores``: compute image stores of one layer's bytes (R32F, RGBA8, RGBA16F, RGBA8) over
          the frame;
        - clears: ``clear.depth`` and ``clear.gbuffer`` (framebuffer clears of the depth, of the
          depth and the three colour targets), ``clear.compute_colour`` (the three colour targets
          by the passes' compute clear, passes/clear_layers.comp), ``clear.id_texture``
          (glClearTexImage) and ``clear.id_compute`` (image stores) of the R32UI id target,
          ``clear.counters`` and ``clear.heads`` (the appends' per-pixel buffers).

        RasterFloor.counts, counted untimed: ``fragments`` (every fragment the raster produces,
        summed from per-pixel counters), ``fragments_rasterised`` (the same by an occlusion query
        without depth test), ``fragments_appended`` and ``fragments_listed`` (what the last
        append and list stored), ``samples_depth`` and ``samples_id`` (the depth-tested draws'
        occlusion queries), ``pixels_depth`` (pixels whose depth the depth draw wrote),
        ``pixels_id`` (pixels the id draw gave an id), ``pixels_with_fragments``,
        ``max_fragments_per_pixel`` and ``triangles``. Materials' alpha holes are not cut: the
        floors are the raster's work, not the material's."""
        settings = settings if settings is not None else Settings()
        if not isinstance(settings, Settings):
            raise TypeError(f"raster_floor: settings must be an ssrlab.Settings, got {type(settings).__name__}")
        if overrides:
            settings = settings.replace(**overrides)
        if isinstance(repeats, bool) or not isinstance(repeats, int) or not 1 <= repeats <= 1000:
            raise ValueError(f"raster_floor: repeats must be an int in [1, 1000], got {repeats!r}")
        if camera is None:
            camera = scene.camera
            if camera is None:
                raise ValueError("raster_floor: the scene has no default camera; pass camera=ssrlab.Camera(...)")
        s = settings.resolved(self.info["device"])
        out = self._native.raster_floor(scene, camera, s.to_native(), int(repeats))
        return RasterFloor(width=s.width, height=s.height,
                           ms={k: list(v) for k, v in out.items() if not k.startswith("count.")},
                           counts={k[len("count."):]: int(v[0]) for k, v in out.items() if k.startswith("count.")})

    def compile(self, *stages: str, defines: dict | None = None) -> int:
        """Compiles shader stages (paths under the shader folder); raises ShaderError."""
        return self._native.compile(list(stages), {k: str(v) for k, v in (defines or {}).items()})

    def block_layout(self, program: int, block: str) -> dict:
        """A compiled program's uniform or storage block as the driver laid it out: storage (True for a
        storage block), data_size and members, {driver's member name: {offset, top_level_stride}}."""
        return self._native.block_layout(program, block)

    def __repr__(self) -> str:
        i = self.info
        return f"Renderer(device={i['device']!r}, renderer={i['renderer']!r}, gl={i['gl_version']!r})"


# The largest far/near ratio at which depth_mode="standard" keeps SSR hit positions within a
# pixel of the per-ray reference for both tracers, as measured by benchmarks/accuracy/depth_precision.py
# on llvmpipe at 320x180 (README, "Depth precision": Hi-Z up to 1e6, linear up to 1e7 with
# 0.87 px). Beyond it the float depth buffer's few distinct values near 1 (seed 000 2.3.4;
# seed 002 4.6.3) show as acne and false hits; reversed-Z held to 1e8.
STANDARD_DEPTH_SAFE_RATIO = 1e6


class DepthPrecisionWarning(UserWarning):
    """A camera's near/far ratio is beyond what the chosen depth convention resolves."""


def _warn_depth_precision(camera, settings: Settings) -> None:
    if settings.depth_mode != "standard":
        return
    near, far = float(camera.near), float(camera.far)
    # (1 + 1e-6): a ratio of exactly the safe one, after float32 rounding of near and far, is safe
    if near > 0 and far / near > STANDARD_DEPTH_SAFE_RATIO * (1 + 1e-6):
        warnings.warn(
            f"the camera's far/near ratio is {far / near:.3g} (near {near:g}, far {far:g}), beyond the "
            f"{STANDARD_DEPTH_SAFE_RATIO:.0e} up to which depth_mode='standard' keeps reflection hits within a "
            "pixel; expect depth acne and false hits. Use Settings(depth_mode=\"reversed_z\"), or move the "
            "near plane out.", DepthPrecisionWarning, stacklevel=3)

