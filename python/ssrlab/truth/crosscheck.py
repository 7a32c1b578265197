"""An independent cross-check of the converged reference against Mitsuba 3.

The same scene is rendered by ssrlab's converged reference (``frame.reference("converged")``)
and by Mitsuba 3's ``path`` integrator, and the two are compared on the floor's pixels.

What is the same in both:

* **triangles**: every object's mesh (``Scene.object_mesh``, the float32 arrays the renderer
  uploads and ``Scene.save`` writes) moved to world space by its transform, with its
  interpolated vertex normals as shading normals;
* **camera**: position, target, up and vertical field of view (Mitsuba's ``look_at`` and
  ``fov_axis="y"``); Mitsuba's camera rays go through the *pixel centres*, as ssrlab's
  G-buffer samples them, so nothing is averaged over a pixel's footprint;
* **lights**: a directional light's irradiance (W/m^2, light travelling along ``direction``)
  is Mitsuba's ``directional`` emitter's ``irradiance``; a point light's W/sr its ``intensity``;
* **BSDF** (``mitsuba_scene(..., bsdf=)``): with ``bsdf="mitsuba"`` (the default) every
  material that one of Mitsuba's own BSDFs computes exactly is rendered by that BSDF
  (:func:`own_bsdf`): a metal whose F0 is 1 (white base colour, metallic 1, no vertex colours),
  for which Schlick's F is 1 at every angle, as is the Fresnel factor of Mitsuba's ``conductor``
  and ``roughconductor`` with ``material="none"`` (eta 0, k 1) and a specular reflectance of F0
  = 1. An ideal mirror (``roughness^2 < 1e-4``, where the reference traces one mirror ray) is
  ``conductor``; a rough one is ``roughconductor`` with ``distribution="ggx"``,
  ``sample_visible=True`` and ``alpha = roughness^2`` (ssrlab's GGX alpha for its reflection
  rays and, from roughness 0.03 up, its punctual lights). ssrlab's diffuse term,
  ``(1 - metallic) base``, is 0 for such a metal. So the cross-check's white metallic floor
  tests ssrlab's microfacet BRDF, its Fresnel and its sampling against Mitsuba's own
  implementations, not against a copy of them. Every other material (ssrlab's dielectric:
  Lambert diffuse under Schlick's F with F0 0.04, which no Mitsuba BSDF computes; a tinted
  metal's Schlick F; vertex colours) and, with ``bsdf="ssrlab"``, every material, is ssrlab's
  model written out again in Dr.Jit as a Mitsuba BSDF plugin (:class:`SsrlabBSDF`, from
  ``shaders/lib/shading.glsl`` and ``brdf.glsl``): Lambert diffuse
  ``(1 - F) (1 - metallic) base / pi`` plus GGX specular ``F D G / (4 NoL NoV)`` with
  separable Smith G, Schlick's F from ``F0 = mix(dielectric_f0, base, metallic)`` (0.04
  unless the material's ``ior``/``specular``/``specular_color`` say otherwise) and
  ``alpha = max(roughness, 0.03)^2``; surfaces with ``roughness^2 < 1e-4`` are ideal mirrors
  with Schlick's F. ``MitsubaScene.own_bsdf`` says which objects got Mitsuba's own BSDF.

* **alpha masks** (glTF MASK/BLEND with a base colour texture of one colour whose alphas are 0
  or 255, :func:`mask_rgb`): Mitsuba's ``mask`` BSDF with a nearest-neighbour opacity bitmap,
  rendered with ``volpath`` (see :func:`render_mitsuba`);
* **emission**: an ``area`` emitter of the material's radiance, accepted only beside ideal
  metallic mirrors (ssrlab's emission lights nothing; see :func:`check_comparable`); an
  emissive texture is a bilinear ``bitmap`` radiance of factor x the sRGB-decoded texels, with
  glTF's wrap modes (the reference's BVH hits sample it so: level 0, bilinear, decoded before
  filtering).

What ssrlab has and physics has not, so the comparable scene leaves it out (checked by
:func:`check_comparable`): the **ambient** term (``ambient * albedo`` added to every surface)
must be 0, and the **environment** black: ssrlab shows its environment in reflections and
the background but lights no surface with it, while a Mitsuba ``constant`` emitter would light
everything. Light transport is Mitsuba's ``path`` integrator with ``max_depth=3``: camera ->
floor -> object -> light, i.e. the floor's direct light and its reflection of directly lit
surfaces, which is exactly what ``frame.reference("converged")`` composites.

Mitsuba 3.7.1 with Dr.Jit 1.2.0 (``pip install ssrlab[mitsuba]``) runs its ``llvm_ad_rgb``
variant on Debian 12's LLVM 15 (newer Mitsuba releases need a newer LLVM); the tests skip where
it does not load.

This module is the bridge: it loads Mitsuba, builds the Mitsuba scene and renders and queries it.
The port of ssrlab's BRDF is :mod:`ssrlab.truth.mitsuba_bsdf`, the scenes
:mod:`ssrlab.truth.crosscheck_scenes` and the comparisons :mod:`ssrlab.truth.crosscheck_compare`;
their names are reached from here as well.
"""

from __future__ import annotations

import glob
import os
from dataclasses import dataclass, field

import numpy as np

# The cross-check's parts, reached from here under their old names as well.
from .crosscheck_compare import (exact_options, floor_pixels, floor_psnr, mean_ratio,  # noqa: F401
                                 moved_reference, noise_agreement, noise_split,
                                 reference_ignores_origin_bias, ssrlab_reference)
from .crosscheck_scenes import (FLOOR, MOVES, crosscheck_scene, emissive_crosscheck_scene,  # noqa: F401
                                emissive_texture_crosscheck_scene, masked_crosscheck_scene, move_objects,
                                point_shadow_crosscheck_scene, vertex_color_crosscheck_scene)
from .mitsuba_bsdf import ALPHA_FLOOR, MIRROR_ROUGHNESS2, define_bsdf, own_bsdf  # noqa: F401

# The harness renders whole images of rays at once (Dr.Jit arrays), so it needs a JIT variant:
# the LLVM one runs on any CPU with libLLVM (Mesa's llvmpipe brings it). scalar_rgb would work
# ray by ray from Python, far too slowly to be worth it.
VARIANTS = ("llvm_ad_rgb",)

# Dr.Jit's worker pool (nanothread) runs the harness's kernels with no worker threads: on this
# project's 2-core machines its lock-free task queue aborts the whole process ("Assertion failed
# in .../nanothread/src/queue.cpp: remain == 1", mitsuba-renderer/mitsuba3#849, open) in 10 of
# 12 runs of a 30-scene load-and-render loop, CI's test run among them; with no workers, in 0 of
# 16. The harness's images are small (the tests' 64x48), so running serially costs little.
# load_mitsuba() sets it; None leaves Dr.Jit's own default.
JIT_THREADS: int | None = 0

_mi = None  # the mitsuba module once a variant is set


def _find_libllvm() -> str | None:
    for pattern in ("/usr/lib/x86_64-linux-gnu/libLLVM-1[5-9]*.so*", "/usr/lib/llvm-1[5-9]/lib/libLLVM*.so*",
                    "/usr/lib/*/libLLVM*.so*"):
        found = sorted(glob.glob(pattern))
        if found:
            return found[0]
    return None


def load_mitsuba(variant: str | None = None):
    """Imports mitsuba and sets a variant: `variant`, else the first of VARIANTS that loads,
    and Dr.Jit's worker-thread count to JIT_THREADS. Raises ImportError naming what failed."""
    global _mi
    try:
        import mitsuba as mi
    except Exception as e:  # pragma: no cover - depends on the machine
        raise ImportError(f"mitsuba cannot be imported ({e}); pip install 'ssrlab[mitsuba]'") from e
    if variant is None and mi.variant() in VARIANTS:
        _mi = mi
        if _BSDF_VARIANT != mi.variant():
            _register()
        _set_jit_threads()
        return mi
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        lib = _find_libllvm()
        if lib:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
    errors = []
    for v in ([variant] if variant else VARIANTS):
        try:
            mi.set_variant(v)
            _mi = mi
            _register()
            _set_jit_threads()
            return mi
        except Exception as e:
            errors.append(f"{v}: {e}")
    raise ImportError("no usable mitsuba variant: " + "; ".join(errors))


def _set_jit_threads() -> None:
    if JIT_THREADS is not None:
        import drjit as dr

        dr.set_thread_count(int(JIT_THREADS))


def mitsuba_version() -> str:
    mi = _mi or load_mitsuba()
    import drjit as dr

    return f"mitsuba {mi.__version__} ({mi.variant()}), drjit {dr.__version__}"


_BSDF_VARIANT = None


def _register():
    """Defines SsrlabBSDF for the current variant (Mitsuba's classes depend on it)."""
    global _BSDF_VARIANT, SsrlabBSDF
    SsrlabBSDF = define_bsdf(_mi)
    _BSDF_VARIANT = _mi.variant()


SsrlabBSDF = None  # defined by load_mitsuba() for the chosen variant

BSDFS = ("mitsuba", "ssrlab")  # mitsuba_scene's bsdf=: Mitsuba's own where exact, or the port everywhere


# ---------------------------------------------------------------------------------------------
# The scene in Mitsuba
# ---------------------------------------------------------------------------------------------

def check_comparable(scene) -> None:
    """Raises ValueError when `scene` has something ssrlab's lighting model and a path tracer
    treat differently (so no exact comparison is possible)."""
    amb = np.asarray(scene.ambient, dtype=float)
    if np.any(amb > 0):
        raise ValueError(f"crosscheck: scene.ambient is {tuple(amb)}; ssrlab's ambient term (ambient * albedo on "
                         "every surface) has no physical counterpart: set scene.ambient = (0, 0, 0)")
    env = scene.environment
    black = env.type == "constant" and (np.all(np.asarray(env.color, float) == 0) or env.intensity == 0)
    if not black:
        raise ValueError(f"crosscheck: scene.environment is {env!r}; ssrlab shows the environment in reflections "
                         "but lights no surface with it, a Mitsuba emitter would light every surface: use "
                         "Environment.constant((0, 0, 0))")
    emissive = [i for i in range(scene.object_count) if any(float(c) > 0 for c in scene.material(i).emissive)]
    for i in range(scene.object_count):
        m = scene.material(i)
        if (m.metallic_roughness_texture >= 0 or m.normal_texture >= 0 or m.specular_texture >= 0
                or m.specular_color_texture >= 0):
            raise ValueError(f"crosscheck: object {i} ({scene.object_name(i)!r}) has textures; the Mitsuba "
                             "cross-check supports untextured materials only (and a base colour texture "
                             "that holds an alpha mask)")
        if m.base_color_texture >= 0:
            mask_rgb(scene, i)  # raises unless it is an alpha mask of one colour
        colors = scene.object_mesh(i).get("colors")
        if colors is not None and m.alpha_mode != "OPAQUE" and np.any(colors[:, 3] < 1.0):
            raise ValueError(f"crosscheck: object {i} ({scene.object_name(i)!r}) has vertex alphas below 1 on an "
                             "alpha-tested material; the Mitsuba cross-check takes holes from an alpha mask "
                             "texture only")
        if emissive and i not in emissive and not (m.metallic == 1.0 and m.roughness ** 2 < MIRROR_ROUGHNESS2):
            # ssrlab's emission is seen (in the lit colour and in reflections) but lights nothing;
            # a Mitsuba area emitter lights every surface it sees. Only an ideal metallic mirror
            # (a delta lobe: no light sampling, nothing diffuse) receives the same from both.
            raise ValueError(f"crosscheck: object {i} ({scene.object_name(i)!r}) would be lit by the emissive "
                             f"object(s) {emissive} in Mitsuba but not in ssrlab (emission lights nothing "
                             "there): beside emitters, only ideal metallic mirrors are comparable")
    for k, light in enumerate(scene.lights):
        if light.type == "spot" or light.range > 0:
            raise ValueError(f"crosscheck: light {k} is a spot light or has a range; the Mitsuba scene has "
                             "point and directional emitters without either yet")


def mask_rgb(scene, i) -> tuple:
    """The one texel colour (linear RGB) of object `i`'s base colour texture, which the
    cross-check accepts only as an alpha mask: a MASK or BLEND material whose texture has one
    RGB value everywhere and alphas of 0 or 255 only. Where alpha only jumps between 0 and 1,
    ssrlab's bilinear filtering thresholded at any cutoff in (0, 1) puts the edge halfway between
    texel centres, exactly where Mitsuba's nearest-neighbour opacity puts it. Raises ValueError."""
    m = scene.material(i)
    img = scene.image(m.base_color_texture)
    name = f"crosscheck: object {i} ({scene.object_name(i)!r})"
    if m.alpha_mode == "OPAQUE":
        raise ValueError(f"{name} has a base colour texture; the Mitsuba cross-check supports one only as an "
                         "alpha mask (alpha_mode 'MASK' or 'BLEND')")
    rgb = img[..., :3].reshape(-1, 3)
    if np.any(rgb != rgb[0]):
        raise ValueError(f"{name}: its base colour texture varies in colour; the Mitsuba cross-check supports one "
                         "only as an alpha mask of one colour")
    if not np.all((img[..., 3] == 0) | (img[..., 3] == 255)):
        raise ValueError(f"{name}: its alpha mask holds values other than 0 and 255 (filtered edges threshold "
                         "differently from Mitsuba's opacity)")
    cutoff = m.alpha_cutoff if m.alpha_mode == "MASK" else 0.5
    a = m.base_color[3]
    if not (0.0 < cutoff <= a):
        raise ValueError(f"{name}: base_color alpha {a} and cutoff {cutoff} make every texel a hole or none")
    c = rgb[0] / 255.0
    return tuple(np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4))


def _alpha_opacity(scene, i):
    """Object i's alpha mask as a Mitsuba opacity bitmap (0 or 1, nearest texel, glTF's wrap)."""
    m = scene.material(i)
    img = scene.image(m.base_color_texture)
    opaque = np.ascontiguousarray((img[..., 3:4] == 255).astype(np.float32))
    return {"type": "bitmap", "bitmap": _mi.Bitmap(opaque), "filter_type": "nearest", "raw": True,
            "wrap_mode": "repeat"}


def _world_mesh(scene, i):
    d = scene.object_mesh(i)
    M = np.asarray(scene.object_transform(i), dtype=np.float64)
    p = d["positions"].astype(np.float64)
    p = p @ M[:3, :3].T + M[:3, 3]
    n = d["normals"].astype(np.float64)
    if len(n) == len(p):
        N = np.linalg.inv(M[:3, :3]).T
        n = n @ N.T
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    else:
        n = None
    return p.astype(np.float32), (None if n is None else n.astype(np.float32)), d["indices"].astype(np.uint32)


def _emission_bitmap(scene, i):
    """Object i's emission, factor x its emissive texture's sRGB-decoded texels, as a Mitsuba
    bitmap (linear values, bilinear, glTF's REPEAT wrap, as ssrlab's scene_textures.glsl)."""
    m = scene.material(i)
    c = scene.image(m.emissive_texture)[..., :3].astype(np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    radiance = np.ascontiguousarray((linear * np.asarray(m.emissive, np.float64)).astype(np.float32))
    return {"type": "bitmap", "bitmap": _mi.Bitmap(radiance), "filter_type": "bilinear", "raw": True,
            "wrap_mode": "repeat"}


@dataclass
class MitsubaScene:
    """A Mitsuba scene built from an ssrlab scene and camera, with the objects' order kept
    (``shape_object[k]`` is the ssrlab object index of Mitsuba shape k)."""
    scene: object
    sensor: object
    width: int
    height: int
    shape_object: dict = field(default_factory=dict)
    bsdfs: list = field(default_factory=list)  # keeps the Python BSDFs alive
    masked: bool = False  # some object has an alpha mask (render_mitsuba then uses volpath)
    bsdf: str = "mitsuba"  # mitsuba_scene's bsdf=
    own_bsdf: dict = field(default_factory=dict)  # ssrlab object index -> Mitsuba's own BSDF plugin that renders it


def mitsuba_scene(scene, camera=None, width: int = 640, height: int = 360, *, bsdf: str = "mitsuba") -> MitsubaScene:
    """The ssrlab `scene` seen by `camera` (default: the scene's) as a Mitsuba scene.

    bsdf="mitsuba" (default): every material Mitsuba's own BSDFs compute exactly (own_bsdf: a
    white metal, the cross-check's floor) is rendered by them, the others by SsrlabBSDF, the
    port of ssrlab's model; bsdf="ssrlab": every material by SsrlabBSDF."""
    mi = _mi or load_mitsuba()
    import drjit as dr

    if bsdf not in BSDFS:
        raise ValueError(f"crosscheck: bsdf must be one of {BSDFS}, got {bsdf!r}")
    check_comparable(scene)
    camera = camera if camera is not None else scene.camera
    if camera is None:
        raise ValueError("crosscheck: the scene has no default camera; pass camera=")
    d = {"type": "scene"}
    bsdfs = []
    own = {}
    any_mask = False
    for i in range(scene.object_count):
        p, n, idx = _world_mesh(scene, i)
        if len(idx) == 0:
            continue
        m = scene.material(i)
        base = tuple(m.base_color)
        if m.base_color_texture >= 0:
            base = tuple(float(b) * float(c) for b, c in zip(base, mask_rgb(scene, i)))
        colors = scene.object_mesh(i).get("colors")
        native = own_bsdf(base, m.metallic, m.roughness, colors is not None) if bsdf == "mitsuba" else None
        if native is not None:
            surface = mi.load_dict(native)
            own[i] = native["type"]
        else:
            surface = SsrlabBSDF().configure(base, m.metallic, m.roughness, tuple(m.dielectric_f0),
                                             vertex_colors=colors is not None)
        bsdfs.append(surface)
        props = mi.Properties()
        masked = m.base_color_texture >= 0
        any_mask = any_mask or masked
        if masked:
            # glTF MASK: Mitsuba's mask BSDF, a null (pass-through) interaction where the opacity is 0.
            props["bsdf"] = mi.load_dict({"type": "mask", "opacity": _alpha_opacity(scene, i), "bsdf": surface})
        else:
            props["bsdf"] = surface
        if any(float(c) > 0 for c in m.emissive):
            props["emitter"] = mi.load_dict({"type": "area", "radiance": {
                "type": "rgb", "value": [float(c) for c in m.emissive]}})
        if m.emissive_texture >= 0 and any(float(c) > 0 for c in m.emissive):
            props["emitter"] = mi.load_dict({"type": "area", "radiance": _emission_bitmap(scene, i)})
        uv = scene.object_mesh(i).get("uvs") if masked or m.emissive_texture >= 0 else None
        has_uv = uv is not None and len(uv) == len(p)
        mesh = mi.Mesh(f"object{i:05d}", len(p), len(idx), props=props, has_vertex_normals=n is not None,
                       has_vertex_texcoords=has_uv)
        params = mi.traverse(mesh)
        params["vertex_positions"] = dr.ravel(mi.Point3f(p[:, 0], p[:, 1], p[:, 2]))
        if n is not None:
            params["vertex_normals"] = dr.ravel(mi.Normal3f(n[:, 0], n[:, 1], n[:, 2]))
        if has_uv:
            uv = np.asarray(uv, np.float32)
            params["vertex_texcoords"] = dr.ravel(mi.Point2f(uv[:, 0], uv[:, 1]))
        if colors is not None:
            # Mitsuba interpolates a mesh attribute barycentrically, as ssrlab's passes do.
            mesh.add_attribute("vertex_color", 3, np.ascontiguousarray(colors[:, :3], np.float32).ravel())
        params["faces"] = dr.ravel(mi.Vector3u(idx[:, 0], idx[:, 1], idx[:, 2]))
        params.update()
        d[f"object{i:05d}"] = mesh
    for k, light in enumerate(scene.lights):
        rgb = [float(c) * float(light.intensity) for c in light.color]
        if light.type == "directional":
            d[f"light{k}"] = {"type": "directional", "direction": [float(x) for x in light.direction],
                              "irradiance": {"type": "rgb", "value": rgb}}
        else:
            d[f"light{k}"] = {"type": "point", "position": [float(x) for x in light.position],
                              "intensity": {"type": "rgb", "value": rgb}}
    d["sensor"] = {
        "type": "perspective", "fov_axis": "y", "fov": float(camera.fov_y),
        "near_clip": float(camera.near), "far_clip": float(camera.far),
        "to_world": mi.ScalarTransform4f().look_at(origin=[float(x) for x in camera.position],
                                                   target=[float(x) for x in camera.target],
                                                   up=[float(x) for x in camera.up]),
        "film": {"type": "hdrfilm", "width": int(width), "height": int(height), "rfilter": {"type": "box"},
                 "pixel_format": "rgb"},
    }
    ms = mi.load_dict(d)
    shape_object = {}
    for k, shape in enumerate(ms.shapes()):
        shape_object[k] = int(shape.id()[len("object"):]) if shape.id().startswith("object") else -1
    return MitsubaScene(ms, ms.sensors()[0], int(width), int(height), shape_object, bsdfs, any_mask, bsdf, own)


def _pixel_centre_rays(ms: MitsubaScene, spp: int):
    """Camera rays through every pixel centre, `spp` times each (row-major, top row first)."""
    mi = _mi
    import drjit as dr

    W, H = ms.width, ms.height
    idx = dr.arange(mi.UInt32, W * H * spp) // spp
    x = mi.Float(idx % W) + 0.5
    y = mi.Float(idx // W) + 0.5
    pos = mi.Point2f(x / W, y / H)
    ray, _ = ms.sensor.sample_ray_differential(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    return ray


def render_mitsuba(ms: MitsubaScene, spp: int = 1, seed: int = 0, max_depth: int = 3,
                   batch_paths: int = 1 << 22) -> np.ndarray:
    """(H, W, 3) float32: Mitsuba's path integrator (max_depth 3: camera, floor, object,
    light) on rays through every pixel centre, `spp` of them averaged per pixel.

    With an alpha mask in the scene (``ms.masked``) it is ``volpath`` with one more bounce:
    ``path`` tests its shadow rays against the masked triangles as opaque, where ``volpath``
    multiplies in the mask's null transmission (so holes let the light through, as ssrlab's
    traced shadows do), and stepping through a hole is a bounce of its own in either. The extra
    bounce also admits paths with two diffuse bounces, which ssrlab does not trace: a masked
    comparison needs a scene without them (``masked_crosscheck_scene``)."""
    mi = _mi
    import drjit as dr

    if spp < 1:
        raise ValueError(f"render_mitsuba: spp must be >= 1, got {spp}")
    W, H = ms.width, ms.height
    integrator = mi.load_dict({"type": "volpath" if ms.masked else "path",
                               "max_depth": int(max_depth) + (1 if ms.masked else 0), "hide_emitters": False})
    out = np.zeros((H * W, 3), np.float32)
    rows_per_batch = max(1, batch_paths // max(W * spp, 1))
    for y0 in range(0, H, rows_per_batch):
        y1 = min(H, y0 + rows_per_batch)
        n = (y1 - y0) * W * spp
        idx = dr.arange(mi.UInt32, n) // spp
        x = mi.Float(idx % W) + 0.5
        y = mi.Float(idx // W + y0) + 0.5
        ray, _ = ms.sensor.sample_ray_differential(0.0, 0.5, mi.Point2f(x / W, y / H), mi.Point2f(0.5, 0.5))
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(seed * 7919 + y0, n)
        L, _, _ = integrator.sample(ms.scene, sampler, ray, None, True)
        c = np.stack([np.asarray(L[k]) for k in range(3)], -1).reshape(-1, spp, 3).mean(1)
        out[y0 * W:y1 * W] = c
    return out.reshape(H, W, 3)


def _object_of(ms: MitsubaScene, si) -> np.ndarray:
    mi = _mi
    import drjit as dr

    ptr = np.asarray(dr.reinterpret_array(mi.UInt32, si.shape))
    valid = np.asarray(si.is_valid())
    obj = np.full(len(valid), -1, np.int32)
    for k, s in enumerate(ms.scene.shapes()):
        sid = np.asarray(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(s)))[0]
        obj[(ptr == sid) & valid] = ms.shape_object.get(k, -1)
    return obj


def first_hit_objects(ms: MitsubaScene) -> np.ndarray:
    """(H, W) int32: the ssrlab object index each pixel-centre camera ray hits in Mitsuba, -1 for none
    (to check that the two scenes and cameras line up)."""
    ray = _pixel_centre_rays(ms, 1)
    return _object_of(ms, ms.scene.ray_intersect(ray)).reshape(ms.height, ms.width)


def mirror_objects(ms: MitsubaScene, offset: float = 1e-5) -> np.ndarray:
    """(H, W) int32: the object the mirror reflection of every pixel-centre camera ray hits (its
    origin `offset` off the surface along the geometric normal), -1 for none or no first hit."""
    mi = _mi
    import drjit as dr

    ray = _pixel_centre_rays(ms, 1)
    si = ms.scene.ray_intersect(ray)
    n = mi.Vector3f(si.n)
    n = dr.select(dr.dot(n, ray.d) > 0, -n, n)
    d = ray.d - 2.0 * dr.dot(ray.d, n) * n
    second = ms.scene.ray_intersect(mi.Ray3f(si.p + offset * n, d), si.is_valid())
    obj = _object_of(ms, second)
    obj[~np.asarray(si.is_valid())] = -1
    return obj.reshape(ms.height, ms.width)


def reflected_silhouettes(ms: MitsubaScene) -> np.ndarray:
    """(H, W) bool: pixels whose mirror reflection lands on a silhouette: the reflected object
    differs within the 3x3 neighbourhood, or with Mitsuba's own ray-origin offset
    (~1e-4 x (1 + |p|), larger than ssrlab's) instead of a 1e-5 one. There the two renderers
    may legitimately see different objects."""
    a = mirror_objects(ms, 1e-5)
    b = mirror_objects(ms, 1e-3)
    edge = a != b
    H, W = a.shape
    p = np.pad(a, 1, mode="edge")
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            edge |= p[1 + dy:1 + dy + H, 1 + dx:1 + dx + W] != a
    return edge

