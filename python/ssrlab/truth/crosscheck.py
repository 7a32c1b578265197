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
"""

from __future__ import annotations

import glob
import inspect
import os
from dataclasses import dataclass, field

import numpy as np

from ..settings import Settings

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


# ---------------------------------------------------------------------------------------------
# ssrlab's material model as a Mitsuba BSDF
# ---------------------------------------------------------------------------------------------

MIRROR_ROUGHNESS2 = 1e-4   # reference.comp: roughness^2 below this reflects one mirror ray
ALPHA_FLOOR = 0.03         # brdf.glsl ggx_alpha: perceptual roughness floor for punctual lights

_BSDF_VARIANT = None


def _register():
    """Defines SsrlabBSDF for the current variant (Mitsuba's classes depend on it)."""
    global _BSDF_VARIANT, SsrlabBSDF
    mi = _mi
    import drjit as dr

    class _SsrlabBSDF(mi.BSDF):
        """ssrlab's lighting BRDF (shading.glsl) as a Mitsuba BSDF. Set ``base``, ``metallic``
        and ``roughness`` with :meth:`configure` after construction."""

        def __init__(self, props=None):
            mi.BSDF.__init__(self, props if props is not None else mi.Properties())
            self.configure((0.8, 0.8, 0.8), 0.0, 0.5)

        def configure(self, base, metallic: float, roughness: float, dielectric_f0=(0.04, 0.04, 0.04),
                      vertex_colors: bool = False):
            self.base = [float(c) for c in base[:3]]
            # glTF COLOR_0: the mesh's "vertex_color" attribute multiplies the base colour per point.
            self.vertex_colors = bool(vertex_colors)
            self.dielectric_f0 = [float(d) for d in dielectric_f0]
            self.metallic = float(np.clip(metallic, 0.0, 1.0))
            self.roughness = float(np.clip(roughness, 0.0, 1.0))
            self.mirror = self.roughness * self.roughness < MIRROR_ROUGHNESS2
            r = max(self.roughness, ALPHA_FLOOR)
            self.alpha = r * r
            self.f0 = [float(d) + (b - float(d)) * self.metallic for b, d in zip(self.base, dielectric_f0)]
            self.diffuse = [b * (1.0 - self.metallic) for b in self.base]
            self.has_diffuse = max(self.diffuse) > 0.0
            # Probability of sampling the specular lobe (the diffuse lobe gets the rest).
            self.p_spec = 1.0 if not self.has_diffuse else 0.5
            spec = mi.BSDFFlags.DeltaReflection if self.mirror else mi.BSDFFlags.GlossyReflection
            comps = [spec | mi.BSDFFlags.FrontSide]
            if self.has_diffuse:
                comps.append(mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide)
            self.m_components = comps
            flags = comps[0]
            for c in comps[1:]:
                flags = flags | c
            self.m_flags = flags
            return self

        # -- shading.glsl, term by term ------------------------------------------------------
        def _surface(self, si, active=True):
            """(F0, diffuse colour) at the interaction: the factors', or with vertex colours the
            base colour times the mesh's interpolated colour (material.glsl, then mixed by metalness)."""
            if not self.vertex_colors:
                return mi.Color3f(*self.f0), mi.Color3f(*self.diffuse)
            base = mi.Color3f(*self.base) * si.shape.eval_attribute_3("vertex_color", si, active)
            d = mi.Color3f(*self.dielectric_f0)
            return d + (base - d) * self.metallic, base * (1.0 - self.metallic)

        def _fresnel(self, c, f0):
            f = dr.power(dr.clip(1.0 - c, 0.0, 1.0), 5.0)
            return f0 + (1.0 - f0) * f

        def _g1(self, c):
            c2 = dr.maximum(c * c, 1e-8)
            tan2 = dr.maximum(1.0 - c2, 0.0) / c2
            return 2.0 / (1.0 + dr.sqrt(1.0 + self.alpha * self.alpha * tan2))

        def _d(self, noh):
            a2 = self.alpha * self.alpha
            d = noh * noh * (a2 - 1.0) + 1.0
            return a2 / dr.maximum(dr.pi * d * d, 1e-12)

        def _eval_smooth(self, wi, wo, f0, diffuse):
            """f(wi, wo) cos(wo) of the non-delta lobes; wi toward the viewer, wo toward the light."""
            nov = dr.maximum(mi.Frame3f.cos_theta(wi), 1e-4)
            nol = mi.Frame3f.cos_theta(wo)
            h = dr.normalize(wi + wo)
            noh = dr.maximum(h.z, 0.0)
            voh = dr.maximum(dr.dot(wi, h), 0.0)
            F = self._fresnel(voh, f0)
            value = mi.Color3f(0.0)
            if not self.mirror:
                value += F * (self._d(noh) * self._g1(nol) * self._g1(nov) / (4.0 * dr.maximum(nol, 1e-8) * nov))
            if self.has_diffuse:
                value += (1.0 - F) * diffuse / dr.pi
            return value * dr.maximum(nol, 0.0)

        def _distribution(self):
            return mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)

        def _pdf_smooth(self, wi, wo):
            pdf = mi.Float(0.0)
            if not self.mirror:
                m = dr.normalize(wi + wo)
                pdf += self.p_spec * self._distribution().pdf(wi, m) / (4.0 * dr.maximum(dr.abs(dr.dot(wo, m)), 1e-8))
            if self.has_diffuse:
                pdf += (1.0 - self.p_spec) * mi.warp.square_to_cosine_hemisphere_pdf(wo)
            return pdf

        def _valid(self, si, wo, active):
            return active & (mi.Frame3f.cos_theta(si.wi) > 0.0) & (mi.Frame3f.cos_theta(wo) > 0.0)

        def eval(self, ctx, si, wo, active=True):
            ok = self._valid(si, wo, active)
            return dr.select(ok, self._eval_smooth(si.wi, wo, *self._surface(si, ok)), mi.Color3f(0.0))

        def pdf(self, ctx, si, wo, active=True):
            ok = self._valid(si, wo, active)
            return dr.select(ok, self._pdf_smooth(si.wi, wo), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            wi = si.wi
            front = active & (mi.Frame3f.cos_theta(wi) > 0.0)
            f0, diffuse = self._surface(si, front)
            bs = mi.BSDFSample3f()
            bs.eta = 1.0
            pick_spec = sample1 < self.p_spec
            if self.mirror:
                wo_spec = mi.reflect(wi)
            else:
                m, _ = self._distribution().sample(wi, sample2)
                wo_spec = mi.reflect(wi, m)
            if self.has_diffuse:
                wo_diff = mi.warp.square_to_cosine_hemisphere(sample2)
                wo = dr.select(pick_spec, wo_spec, wo_diff)
            else:
                wo = wo_spec
            bs.wo = wo
            if self.mirror:
                # The delta lobe: Schlick's F at the mirror angle, chosen with probability p_spec.
                spec_weight = self._fresnel(mi.Frame3f.cos_theta(wi), f0) / self.p_spec
                if self.has_diffuse:
                    diff_value = self._eval_smooth(wi, wo, f0, diffuse)
                    diff_pdf = (1.0 - self.p_spec) * mi.warp.square_to_cosine_hemisphere_pdf(wo)
                    weight = dr.select(pick_spec, spec_weight, diff_value / dr.maximum(diff_pdf, 1e-12))
                    bs.pdf = dr.select(pick_spec, self.p_spec, diff_pdf)
                    bs.sampled_type = dr.select(pick_spec, mi.UInt32(+mi.BSDFFlags.DeltaReflection),
                                                mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
                    bs.sampled_component = dr.select(pick_spec, mi.UInt32(0), mi.UInt32(1))
                else:
                    weight = spec_weight
                    bs.pdf = mi.Float(1.0)
                    bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DeltaReflection)
                    bs.sampled_component = mi.UInt32(0)
            else:
                pdf = self._pdf_smooth(wi, wo)
                weight = self._eval_smooth(wi, wo, f0, diffuse) / dr.maximum(pdf, 1e-12)
                bs.pdf = pdf
                if self.has_diffuse:
                    bs.sampled_type = dr.select(pick_spec, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                                mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
                    bs.sampled_component = dr.select(pick_spec, mi.UInt32(0), mi.UInt32(1))
                else:
                    bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
                    bs.sampled_component = mi.UInt32(0)
            ok = front & (mi.Frame3f.cos_theta(wo) > 0.0) & (bs.pdf > 0.0)
            return bs, dr.select(ok, weight, mi.Color3f(0.0))

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return (f"SsrlabBSDF[base={self.base}, metallic={self.metallic}, roughness={self.roughness}, "
                    f"mirror={self.mirror}]")

    _BSDF_VARIANT = mi.variant()
    SsrlabBSDF = _SsrlabBSDF


SsrlabBSDF = None  # defined by load_mitsuba() for the chosen variant

BSDFS = ("mitsuba", "ssrlab")  # mitsuba_scene's bsdf=: Mitsuba's own where exact, or the port everywhere


def own_bsdf(base, metallic: float, roughness: float, vertex_colors: bool = False) -> dict | None:
    """The Mitsuba BSDF (a load_dict dictionary) that computes exactly what ssrlab's model does
    for a material of linear base colour `base`, `metallic` and perceptual `roughness`, or None
    where Mitsuba has none.

    That is a metal whose F0 = mix(dielectric_f0, base, metallic) is 1: metallic 1 and a white
    base colour (without vertex colours, which would scale it per point). ssrlab's Schlick F is
    then F0 + (1 - F0) (1 - cos)^5 = 1 at every angle and its diffuse colour (1 - metallic) base
    is 0; Mitsuba's conductor with material="none" (eta 0, k 1) has a Fresnel factor of exactly 1
    too, times its specular_reflectance, F0. An ideal mirror (roughness^2 < MIRROR_ROUGHNESS2) is
    ``conductor``; a rough one ``roughconductor``, GGX, visible-normal sampling, alpha =
    roughness^2, which is ssrlab's alpha both for its reflection rays (ray_generation.glsl) and,
    from roughness ALPHA_FLOOR up, for its punctual lights (brdf.glsl ggx_alpha). Between the two
    (0.01 <= roughness < 0.03) ssrlab's lights and rays see different alphas, which no single
    Mitsuba BSDF has: None. Both BSDFs use separable Smith masking with the same G1 as
    brdf.glsl's."""
    f0 = [float(c) for c in base[:3]]
    if vertex_colors or float(metallic) != 1.0 or any(c != 1.0 for c in f0):
        return None
    r = float(np.clip(roughness, 0.0, 1.0))
    reflectance = {"type": "rgb", "value": f0}
    if r * r < MIRROR_ROUGHNESS2:
        return {"type": "conductor", "material": "none", "specular_reflectance": reflectance}
    if r < ALPHA_FLOOR:
        return None
    return {"type": "roughconductor", "material": "none", "distribution": "ggx", "alpha": r * r,
            "sample_visible": True, "specular_reflectance": reflectance}


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


# ---------------------------------------------------------------------------------------------
# The comparison
# ---------------------------------------------------------------------------------------------

def crosscheck_scene(floor_roughness: float = 0.0, floor_color=(1.0, 1.0, 1.0), *, sun_irradiance: float = 3.0,
                     shadows: bool = True):
    """The cross-check's scene: a metallic floor (reflectivity 1, `floor_roughness`, F0 =
    `floor_color`) with a back wall, boxes and spheres of ssrlab's dielectric material on it,
    lit by a shadow-casting sun; no ambient, black environment. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = f"crosscheck_floor_r{floor_roughness:g}"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=tuple(floor_color), metallic=1.0, roughness=floor_roughness, reflectivity=1.0))
    s.add_box((0, 1.5, -6.0), (10, 3, 0.2), name="wall", material=Material(
        base_color=(0.75, 0.72, 0.65), roughness=0.8, reflectivity=0.0))
    s.add_box((-1.6, 0.5, -2.5), (1.0, 1.0, 1.0), rotation_y=25.0, name="red_box", material=Material(
        base_color=(0.8, 0.15, 0.1), roughness=0.5, reflectivity=0.0))
    s.add_box((1.8, 0.75, -3.4), (0.8, 1.5, 0.8), rotation_y=-15.0, name="blue_box", material=Material(
        base_color=(0.15, 0.3, 0.8), roughness=0.6, reflectivity=0.0))
    s.add_sphere((0.3, 0.6, -1.6), 0.6, segments=64, name="green_sphere", material=Material(
        base_color=(0.2, 0.7, 0.25), roughness=0.4, reflectivity=0.0))
    s.add_sphere((-0.2, 0.35, -4.2), 0.35, segments=48, name="yellow_sphere", material=Material(
        base_color=(0.85, 0.75, 0.2), roughness=0.3, reflectivity=0.0))
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=sun_irradiance, cast_shadow=shadows))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.35, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def masked_crosscheck_scene(cells: int = 4, texels_per_cell: int = 4):
    """glTF alphaMode MASK: a mirror floor, a sun-lit matte wall and between them a red quad
    whose alpha mask is a `cells` x `cells` checkerboard (even cells opaque), casting a holed
    shadow on the wall. No surface sees another diffuse one that the sun lights (the quad's
    front faces away from the wall, the floor is a mirror), so the one bounce ``volpath`` adds
    for stepping through a hole brings no light that ssrlab leaves out. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_masked"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    s.add_plane((0, 2.0, -5.0), (12, 4), normal=(0, 0, 1), name="wall", material=Material(
        base_color=(0.2, 0.6, 0.25), roughness=0.9, reflectivity=0.0))
    n = cells * texels_per_cell
    c = np.arange(n) // texels_per_cell
    img = np.zeros((n, n, 4), np.uint8)
    img[..., :3] = (200, 40, 30)
    img[..., 3] = np.where((c[:, None] + c[None, :]) % 2 == 0, 255, 0)
    tex = s.add_image(img, name="checker_mask")
    y0, y1, z = 0.4, 2.0, -2.5
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               uvs=[(0, 1), (1, 1), (1, 0), (0, 0)], name="masked_quad", material=Material(
                   base_color=(1.0, 1.0, 1.0), roughness=0.7, reflectivity=0.0, base_color_texture=tex,
                   double_sided=True, alpha_mode="MASK", alpha_cutoff=0.5))
    s.add_light(directional_light((0.3, -0.55, -0.8), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def emissive_crosscheck_scene(emission=(4.0, 2.0, 0.8)):
    """Emission: a mirror floor and an emissive box (black base colour, so what it shows is its
    emission plus the sun's highlight on its dielectric specular) lit by the sun. Mitsuba makes the
    box an area emitter; the floor, an ideal metallic mirror, receives from it only what it
    reflects, as in ssrlab (whose emission lights nothing). Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_emissive"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    lamp = Material(base_color=(0.0, 0.0, 0.0), roughness=0.6, reflectivity=0.0)
    lamp.emissive = tuple(float(e) for e in emission)
    s.add_box((0.2, 0.8, -3.0), (1.6, 1.6, 1.2), rotation_y=20.0, name="lamp", material=lamp)
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.35, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def emissive_texture_crosscheck_scene(factor=(4.0, 2.0, 1.0), cells: int = 4, texels_per_cell: int = 8):
    """glTF emissiveTexture: a mirror floor and a black quad facing the camera whose emission is
    `factor` x a `cells` x `cells` checkerboard (sRGB 255 and 64), lit by the sun. Mitsuba makes
    the quad an area emitter with that bitmap radiance; the floor, an ideal metallic mirror,
    receives from it only what it reflects, as in ssrlab. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_emissive_texture"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    n = cells * texels_per_cell
    c = np.arange(n) // texels_per_cell
    img = np.zeros((n, n, 3), np.uint8)
    img[...] = np.where((c[:, None] + c[None, :]) % 2 == 0, 255, 64)[..., None]
    tex = s.add_image(img, name="checker_emission")
    lamp = Material(base_color=(0.0, 0.0, 0.0), roughness=0.6, reflectivity=0.0, emissive_texture=tex)
    lamp.emissive = tuple(float(e) for e in factor)
    y0, y1, z = 0.3, 1.9, -3.0
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               uvs=[(0, 1), (1, 1), (1, 0), (0, 0)], name="emissive_quad", material=lamp)
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def point_shadow_crosscheck_scene(intensity: float = 6.0):
    """Point-light shadows: crosscheck_scene's mirror floor, wall, boxes and spheres lit by a
    shadow-casting point light between them and the wall instead of the sun (ssrlab's shadow
    cube; traced shadows in the reference), so that the floor reflects the objects' shadows on
    the wall and on one another, cast in several directions from the light. Object 0 is the floor;
    object 1 the wall."""
    from ..scene import point_light

    s = crosscheck_scene(0.0)
    s.name = "crosscheck_point_shadow"
    s.clear_lights()
    s.add_light(point_light((0.0, 1.2, -0.9), intensity=intensity, cast_shadow=True))
    return s


def vertex_color_crosscheck_scene():
    """glTF COLOR_0: a mirror floor and a matte quad facing the camera whose vertex colours run
    red to green across it and dark to bright up it, lit by the sun. Mitsuba's quad carries them
    as its "vertex_color" attribute, which SsrlabBSDF multiplies into the base colour. Object 0 is
    the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_vertex_colors"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    y0, y1, z = 0.3, 1.9, -3.0
    colors = [(0.9, 0.1, 0.1), (0.1, 0.9, 0.1), (0.3, 0.9, 0.9), (0.9, 0.3, 0.9)]
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               colors=colors, name="coloured_quad", material=Material(
                   base_color=(1.0, 1.0, 1.0), roughness=0.7, reflectivity=0.0))
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


FLOOR = 0  # crosscheck_scene's floor object


def floor_pixels(frame, floor_object: int = FLOOR, *, interior: bool = True) -> np.ndarray:
    """(H, W) bool: pixels whose layer 0 shows the floor; with interior=True also every
    8-neighbour (silhouette pixels, where a pixel-centre sample lands on either side, are left
    out)."""
    g = frame.gbuffer
    m = g.coverage[0] & (g.object_id[0] == floor_object)
    if interior:
        p = np.pad(m, 1, constant_values=False)
        H, W = m.shape
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                m = m & p[1 + dy:1 + dy + H, 1 + dx:1 + dx + W]
    return m


def _setting_names() -> set:
    return {f for f in Settings.__dataclass_fields__}


def exact_options(settings: Settings) -> tuple[Settings, dict, list[str]]:
    """`settings` with the most exact reference options this ssrlab has (detected, so the same
    code runs before and after they exist), the matching keyword arguments of
    ``frame.reference`` and a list of what was turned on."""
    names = _setting_names()
    changes, used = {}, []
    if "reference_shadows" in names:
        changes["reference_shadows"] = "traced"
        used.append("reference_shadows='traced'")
    s = settings.replace(**changes) if changes else settings
    kwargs = {}
    from ..renderer import Frame

    viewer = inspect.signature(Frame.reference).parameters.get("viewer")
    if viewer is not None and viewer.default != "ray":
        # The physical view of the reflected surface: its specular seen from the floor point.
        kwargs["viewer"] = "ray"
        used.append("viewer='ray'")
    return s, kwargs, used


def ssrlab_reference(renderer, scene, settings: Settings, *, rays: int = 256, seed: int = 0, **reference_kwargs):
    """The frame (method off) and its converged reference: (frame, truth)."""
    frame = renderer.render(scene, settings=settings.replace(method="off"))
    truth = frame.reference("converged", rays=rays, seed=seed, **reference_kwargs)
    return frame, truth


# The moved-frame case: between two frames of a sequence, objects of crosscheck_scene move (by name:
# a translation, a turn about +y and a lift), so that the second frame's converged reference is made
# from the scene's new transforms: the objects' GPU entries, their BVH trees and the shadow maps
# updated per object, not rebuilt (docs/guide/scenes.md). Mitsuba renders the moved scene afresh.
MOVES = {
    "green_sphere": ((0.6, 0.0, -0.4), 0.0),
    "red_box": ((0.3, 0.0, 0.5), 35.0),
    "yellow_sphere": ((-0.5, 0.25, 0.0), 0.0),
}


def move_objects(scene, moves=None) -> list[int]:
    """Moves crosscheck_scene's objects named in `moves` ({name: (translation, degrees about +y
    through the object's centre)}, MOVES by default) from where they are; returns their indices."""
    from .. import transforms as T

    names = [scene.object_name(i) for i in range(scene.object_count)]
    moved = []
    for name, (offset, degrees) in (moves or MOVES).items():
        if name not in names:
            raise KeyError(f"move_objects: the scene has no object named {name!r} (it has {', '.join(names)})")
        i = names.index(name)
        m = np.asarray(scene.object_transform(i), np.float64)
        centre = m[:3, 3].copy()
        turn = T.translate(tuple(centre)) @ T.rotate((0.0, 1.0, 0.0), degrees) @ T.translate(tuple(-centre))
        scene.set_object_transform(i, T.translate(offset) @ turn @ m)
        moved.append(i)
    return moved


def moved_reference(renderer, scene, settings: Settings, *, rays: int = 256, seed: int = 0, moves=None,
                    **reference_kwargs):
    """The second frame of a two-frame sequence (method off, one camera) whose objects `moves`
    moved after the first (move_objects), and its converged reference: (frame, truth). The scene
    is left moved, as mitsuba_scene must see it."""
    frames = renderer.render_sequence(scene, [scene.camera, scene.camera], settings.replace(method="off"))
    next(frames)
    move_objects(scene, moves)
    frame = next(frames)
    frames.close()
    return frame, frame.reference("converged", rays=rays, seed=seed, **reference_kwargs)


def floor_psnr(image, reference, mask) -> float:
    from .metrics import psnr

    return psnr(image, reference, mask)


def noise_split(ssr_a, ssr_b, mit_a, mit_b, mask) -> dict:
    """Separates bias from Monte-Carlo noise, for two independent ssrlab references (seeds a, b)
    and two independent Mitsuba images: with independent noise,
    E|s - m|^2 = var_s + var_m + bias^2, var_s = E|s_a - s_b|^2 / 2, var_m likewise. Returns the
    MSEs (per channel value over `mask`) and the bias estimate (may come out slightly negative)."""
    def mse(a, b):
        return float(np.mean((a[mask] - b[mask]) ** 2))

    cross = mse(ssr_a, mit_a)
    var_s = mse(ssr_a, ssr_b) / 2.0
    var_m = mse(mit_a, mit_b) / 2.0
    return {"mse": cross, "noise_ssrlab": var_s, "noise_mitsuba": var_m, "bias2": cross - var_s - var_m,
            "ratio": cross / max(var_s + var_m, 1e-30)}


def mean_ratio(ssr_a, ssr_b, mit_a, mit_b, mask) -> tuple[float, float]:
    """Mean floor radiance of ssrlab over Mitsuba (each the mean of its two images) and the
    ratio's standard error from the per-pixel spread of the differences (pixels' noise is
    independent): a brightness bias shows as a ratio many standard errors away from 1."""
    s = (ssr_a[mask] + ssr_b[mask]) / 2.0
    m = (mit_a[mask] + mit_b[mask]) / 2.0
    d = (s - m).mean(axis=1)  # per pixel, over RGB
    mean_m = float(m.mean())
    ratio = float(s.mean()) / max(mean_m, 1e-30)
    err = float(d.std(ddof=1) / np.sqrt(max(len(d), 1))) / max(mean_m, 1e-30)
    return ratio, err


def noise_agreement(ssr_a, ssr_b, mit_a, mit_b, mask) -> dict:
    """Whether two renderers agree to their Monte-Carlo noise, for two independent ssrlab
    references (seeds a, b) and two independent Mitsuba images, in standard errors measured from
    the images themselves. Per pixel of `mask` (RGB averaged: a pixel's channels share its
    paths), d = (s_a + s_b) / 2 - (m_a + m_b) / 2 and v = ((s_a - s_b)^2 + (m_a - m_b)^2) / 4,
    whose expectation is d's variance when the noise is independent; so E[d^2 - v] is the squared
    bias. Pixels' noise is independent, so over N pixels:

    * ``z_mean``: mean(d) / (std(d) / sqrt(N)), a brightness bias (a Fresnel factor, a missing
      energy term) in standard errors;
    * ``z_bias2``: mean(d^2 - v) / (std(d^2 - v) / sqrt(N)), any per-pixel bias (a lobe of the
      wrong shape or width moves light between pixels without changing the mean) in standard
      errors.

    With ``mean_relative`` (mean(d) over Mitsuba's mean) and ``mse_over_noise`` (mean(d^2) /
    mean(v), 1 for unbiased images)."""
    s_a, s_b, m_a, m_b = (np.asarray(x, np.float64)[mask].mean(axis=-1) for x in (ssr_a, ssr_b, mit_a, mit_b))
    d = (s_a + s_b) / 2.0 - (m_a + m_b) / 2.0
    v = ((s_a - s_b) ** 2 + (m_a - m_b) ** 2) / 4.0
    t = d * d - v
    n = max(len(d), 2)
    se_mean = float(d.std(ddof=1)) / np.sqrt(n)
    se_bias2 = float(t.std(ddof=1)) / np.sqrt(n)
    mean_m = float(((m_a + m_b) / 2.0).mean())
    return {"pixels": int(len(d)), "z_mean": float(d.mean()) / max(se_mean, 1e-30),
            "z_bias2": float(t.mean()) / max(se_bias2, 1e-30), "bias2": float(t.mean()), "se_bias2": se_bias2,
            "mean_relative": float(d.mean()) / max(mean_m, 1e-30),
            "se_mean_relative": se_mean / max(mean_m, 1e-30),
            "mse_over_noise": float(np.mean(d * d)) / max(float(np.mean(v)), 1e-30), "noise": float(np.mean(v))}


def reference_ignores_origin_bias(renderer, width: int = 48, height: int = 32) -> bool:
    """Whether this ssrlab's converged reference offsets its ray origins independently of
    `origin_bias` (the reference's robust offset): two tiny references of the mirror scene with
    origin_bias 0.002 and 0.05 come out identical."""
    scene = crosscheck_scene(0.0)
    s = Settings(width=width, height=height)
    _, a = ssrlab_reference(renderer, scene, s.replace(origin_bias=0.002), rays=1)
    a = a.color.copy()
    _, b = ssrlab_reference(renderer, scene, s.replace(origin_bias=0.05), rays=1)
    return bool(np.array_equal(a, b.color))
