"""Closed-form references: the geometry of camera rays and of mirror_test's mirror image, and
the documented shading model in numpy. Used by the tests and benchmarks/accuracy/accuracy.py to check
the tracers and the ground truth against something no renderer computed."""

from __future__ import annotations

import numpy as np

from ..scenes import MIRROR_TILE, MIRROR_TILES, MIRROR_WALL_Z


def pixel_rays(frame):
    """Camera position and unit world-space view ray of every pixel centre (rows top-first)."""
    s = frame.settings
    V = frame.view_matrix.astype(np.float64)
    P = frame.projection_matrix.astype(np.float64)
    inv_vp = np.linalg.inv(P @ V)
    cam = np.linalg.inv(V)[:3, 3]
    j, i = np.meshgrid(np.arange(s.width) + 0.5, np.arange(s.height) + 0.5)
    ndc = np.stack([j / s.width * 2 - 1, 1 - i / s.height * 2, np.ones_like(j), np.ones_like(j)], -1)
    far = ndc @ inv_vp.T
    d = far[..., :3] / far[..., 3:] - cam
    return cam, d / np.linalg.norm(d, axis=-1, keepdims=True)


def project(frame, points):
    """Pixel position (x = column, y = row from the top) of world points."""
    s = frame.settings
    M = frame.projection_matrix.astype(np.float64) @ frame.view_matrix.astype(np.float64)
    clip = np.concatenate([points, np.ones_like(points[..., :1])], -1) @ M.T
    ndc = clip[..., :2] / clip[..., 3:]
    return np.stack([(ndc[..., 0] + 1) / 2 * s.width, (1 - ndc[..., 1]) / 2 * s.height], -1)


def mirror_test_hits(frame):
    """For mirror_test: the analytic hit pixel of every floor pixel's mirror ray, and where
    that hit is on the checkerboard wall and on screen."""
    cam, d = pixel_rays(frame)
    t = -cam[1] / d[..., 1]
    on_floor = d[..., 1] < 0
    p = cam + d * t[..., None]
    r = d * np.array([1.0, -1.0, 1.0])  # reflection about the plane y = 0
    tw = (MIRROR_WALL_Z - p[..., 2]) / r[..., 2]
    h = p + r * tw[..., None]
    half = MIRROR_TILES * MIRROR_TILE / 2
    ok = on_floor & (r[..., 2] < 0) & (np.abs(h[..., 0]) < half) & (h[..., 1] > 0) & (h[..., 1] < 2 * half)
    px = project(frame, h)
    s = frame.settings
    ok &= (px[..., 0] >= 0) & (px[..., 0] < s.width) & (px[..., 1] >= 0) & (px[..., 1] < s.height)
    return px, ok


def ray_box_entry(origin, direction, lo, hi):
    """Ray parameter where rays enter an axis-aligned box (inf for misses), and the axis of the face."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (lo - origin) / direction
        t1 = (hi - origin) / direction
    tmin = np.minimum(t0, t1)
    tmax = np.maximum(t0, t1)
    t_enter = tmin.max(axis=-1)
    t_exit = tmax.min(axis=-1)
    hit = (t_enter <= t_exit) & (t_exit > 0)
    return np.where(hit, t_enter, np.inf), tmin.argmax(axis=-1)


def ggx_shade(albedo, metallic, roughness, n, v, lights, ambient):
    """The documented shading model (shaders/lib/shading.glsl) in numpy: ambient * albedo plus,
    per directional light, (Lambert diffuse + GGX specular) * irradiance * n.l, with Schlick's
    Fresnel, GGX D, separable Smith G, alpha = max(roughness, 0.03)^2. No shadows.
    `lights`: list of (direction the light travels, rgb irradiance). Arrays broadcast over (..., 3)."""
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    alpha = max(roughness, 0.03) ** 2
    f0 = 0.04 * (1 - metallic) + np.asarray(albedo) * metallic
    out = np.asarray(ambient) * np.asarray(albedo) + np.zeros_like(n)
    nv = np.maximum(np.sum(n * v, -1), 1e-4)

    def g1(c):
        c2 = np.maximum(c * c, 1e-8)
        return 2 / (1 + np.sqrt(1 + alpha * alpha * np.maximum(1 - c2, 0) / c2))

    for direction, irradiance in lights:
        l = -np.asarray(direction, float) / np.linalg.norm(direction)
        nl = np.sum(n * l, -1)
        h = l + v
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        nh = np.maximum(np.sum(n * h, -1), 0)
        vh = np.maximum(np.sum(v * h, -1), 0)
        F = f0 + (1 - f0) * ((1 - vh) ** 5)[..., None]
        d = nh * nh * (alpha * alpha - 1) + 1
        D = alpha * alpha / np.maximum(np.pi * d * d, 1e-12)
        spec = F * (D * g1(nl) * g1(nv) / (4 * np.maximum(nl, 1e-8) * nv))[..., None]
        diffuse = (1 - F) * np.asarray(albedo) / np.pi
        out = out + np.where((nl > 0)[..., None], (diffuse + spec) * np.asarray(irradiance) * nl[..., None], 0)
    return out


def specular_albedo_lookup(table: np.ndarray, nov, roughness) -> np.ndarray:
    """(..., 2) entries (A, B) of Renderer.specular_albedo_table() at n.v and perceptual
    roughness, interpolated bilinearly between cells as the shaders do
    (shaders/lib/specular_albedo.glsl: cell centres at both ends of each range)."""
    nov, roughness = np.asarray(nov, np.float64), np.asarray(roughness, np.float64)
    n = table.shape[0] - 1
    x, y = np.clip(nov, 0, 1) * n, np.clip(roughness, 0, 1) * n
    x0 = np.minimum(np.floor(x).astype(int), n - 1)
    y0 = np.minimum(np.floor(y).astype(int), n - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    t = table.astype(np.float64)
    return ((t[y0, x0] * (1 - fx) + t[y0, x0 + 1] * fx) * (1 - fy) +
            (t[y0 + 1, x0] * (1 - fx) + t[y0 + 1, x0 + 1] * fx) * fy)
