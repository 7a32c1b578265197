"""ssrlab's material model in Mitsuba: the BRDF of ``shaders/lib/shading.glsl`` and
``brdf.glsl`` written out again in Dr.Jit as a Mitsuba BSDF plugin (:func:`define_bsdf`), and the
materials for which one of Mitsuba's own BSDFs computes exactly the same (:func:`own_bsdf`).

The cross-check (:mod:`ssrlab.truth.crosscheck`) renders with one or the other; its docstring says
when each is used and why the own BSDFs are exact."""

from __future__ import annotations

import numpy as np

MIRROR_ROUGHNESS2 = 1e-4   # reference.comp: roughness^2 below this reflects one mirror ray
ALPHA_FLOOR = 0.03         # brdf.glsl ggx_alpha: perceptual roughness floor for punctual lights


def define_bsdf(mi):
    """SsrlabBSDF for mitsuba module `mi` with its variant set (Mitsuba's classes depend on the
    variant, so the class is made again for each)."""
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

    return _SsrlabBSDF


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

