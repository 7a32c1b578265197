"""The numerical stress suite: property-based over scenes, cameras and settings across
each field's documented range (hypothesis), plus named edge cases. Every output must be finite,
every hit must lie on the surface it claims, and results must not depend on the parity of the
image size.

CI size: few examples, images <= 64 px, derandomized. The full run:
    SSRLAB_STRESS_EXAMPLES=500 python -m pytest tests/test_stress.py
(each property then draws that many examples) or python benchmarks/fuzzing/stress.py.
"""

from __future__ import annotations

import functools
import math
import os

import numpy as np
import pytest

import ssrlab
from ssrlab.settings import _FIELDS

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, assume, given, settings as hsettings, strategies as st  # noqa: E402

FULL = int(os.environ.get("SSRLAB_STRESS_EXAMPLES", "0"))


def examples(ci: int):
    return hsettings(max_examples=FULL or ci, deadline=None, derandomize=True, database=None,
                     suppress_health_check=list(HealthCheck))


# Fields whose documented upper bound only costs time or memory, capped so a render stays a
# fraction of a second at <= 64 px (a 16384^2 shadow map alone is 1 GiB on llvmpipe).
CAPS = {"width": 64, "height": 64, "shadow_map_size": 1024, "rays_per_pixel": 8}


# -- checks ----------------------------------------------------------------------------------------

def assert_all_finite(f) -> None:
    """Every output of the frame, as Python can read it, is finite."""
    arrays = {"color": f.color, "reflection": f.reflection}
    g = f.gbuffer
    for name in ("depth", "window_depth", "normal", "albedo", "roughness", "metallic", "reflectivity", "lit"):
        arrays[f"gbuffer.{name}"] = getattr(g, name)
    if "rays.hit" in f.texture_names:
        for name in ("hit_uv", "weight", "pdf", "steps", "fade", "direction"):
            arrays[f"rays.{name}"] = getattr(f.rays, name)
        layer = f.rays.hit_layer
        assert layer.min() >= 0 and layer.max() <= f.settings.layers, "hit_layer outside [0, layers]"
        uv = f.rays.hit_uv
        assert uv.min() >= 0.0 and uv.max() <= 1.0, "hit_uv outside [0, 1]"
    for name, a in arrays.items():
        bad = ~np.isfinite(a)
        assert not bad.any(), f"{name}: {int(bad.sum())} NaN/Inf of {a.size} ({describe_settings(f.settings)})"


def describe_settings(s: ssrlab.Settings) -> str:
    d = ssrlab.Settings().to_dict()
    return ", ".join(f"{k}={v!r}" for k, v in s.to_dict().items() if d[k] != v)


def hits_off_surface(f, depth_error: float = 0.0) -> tuple[int, int]:
    """(hits checked, hits off the surface they claim). A hit claims layer k at hit_pixel: layer
    k must cover that pixel, and the ray, while it projects within a step (stride + 1 pixels) of
    hit_pixel, must reach depths in [depth_k, depth_k + thickness] of that pixel, up to the
    surface's own depth change across the pixel and 1e-3 relative; with `depth_error` (window
    depth units) also up to the view depths that the stored window depth +- depth_error stand for.

    The ray is rebuilt from the G-buffer: origin = layer 0's surface at the ray's pixel centre
    plus the origin bias along its normal, direction = rays.direction (view space); its depth
    range near hit_pixel comes from dense samples along it (exact where the ray runs almost
    along the line of sight, which a closest-point solution is not)."""
    s = f.settings
    if "rays.hit" not in f.texture_names or s.downscale != 1 or (s.method == "hiz" and s.hiz_stop_level > 0):
        return 0, 0  # a coarse stop level claims a cell, not a pixel; downscaled origins are not layer 0's pixels
    rays, g = f.rays, f.gbuffer
    P = f.projection_matrix.astype(np.float64)
    W, H = s.width, s.height
    hit = rays.hit & np.broadcast_to(rays.traced, rays.hit.shape)
    if not hit.any():
        return 0, 0
    r, i, j = np.nonzero(hit)
    z0 = g.depth[0][i, j].astype(np.float64)
    x_ndc, y_ndc = (j + 0.5) / W * 2 - 1, 1 - (i + 0.5) / H * 2
    pos = np.stack([x_ndc * z0 / P[0, 0], y_ndc * z0 / P[1, 1], -z0], -1)
    o = pos + g.normal[0][i, j].astype(np.float64) * (s.origin_bias * z0)[:, None]
    d = rays.direction[r, i, j].astype(np.float64)
    hp = rays.hit_pixel[r, i, j].astype(np.float64)
    step_px = s.stride if s.method == "linear" else 1.0
    window = step_px + 1.0
    near = float(f.camera.near)
    t = np.geomspace(min(1e-5 * z0.min(), 1e-3 * s.max_distance), s.max_distance, 5000)
    z_lo = np.full(len(r), np.inf)
    z_hi = np.full(len(r), -np.inf)
    for a in range(0, len(r), 256):
        b = slice(a, a + 256)
        pts = o[b, None, :] + t[None, :, None] * d[b, None, :]
        w = -pts[..., 2]
        front = w > near
        with np.errstate(divide="ignore", invalid="ignore"):
            px = np.stack([(pts[..., 0] * P[0, 0] / w + 1) / 2 * W, (1 - pts[..., 1] * P[1, 1] / w) / 2 * H], -1)
            inside = front & (np.linalg.norm(px - hp[b, None, :], axis=-1) <= window)
        z_lo[b] = np.where(inside, w, np.inf).min(axis=1)
        z_hi[b] = np.where(inside, w, -np.inf).max(axis=1)
    dz_step = np.where(np.isfinite(z_hi - z_lo), (z_hi - z_lo) / 2, 0.0)  # about one step's depth change
    k = rays.hit_layer[r, i, j] - 1
    col = np.clip(np.floor(hp[:, 0]).astype(int), 0, W - 1)
    row = np.clip(np.floor(hp[:, 1]).astype(int), 0, H - 1)
    dk = g.depth[k, row, col].astype(np.float64)
    # The surface's own depth change across its pixel: the hit may lie anywhere in it.
    nb = np.array([g.depth[k, np.clip(row + a, 0, H - 1), np.clip(col + c, 0, W - 1)]
                   for a in (-1, 0, 1) for c in (-1, 0, 1)], np.float64)
    cov = np.array([g.coverage[k, np.clip(row + a, 0, H - 1), np.clip(col + c, 0, W - 1)]
                    for a in (-1, 0, 1) for c in (-1, 0, 1)])
    surface_span = np.abs(np.where(cov, nb, dk) - dk).max(axis=0)
    thickness = s.thickness
    if s.thickness_mode == "ray_step" and s.method == "linear":
        thickness = np.maximum(s.thickness, s.thickness_scale * dz_step)
    eps = 1e-3 * dk + surface_span
    near_extra = far_extra = 0.0
    if depth_error > 0:
        # The view depths the stored window depth stands for, give or take the device's error.
        wk = g.window_depth[k, row, col].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            ends = [view_depth_of_window_depth(f, wk + e) for e in (-depth_error, depth_error)]
        z_a, z_b = np.nan_to_num(ends[0], nan=np.inf), np.nan_to_num(ends[1], nan=np.inf)
        near_extra = np.maximum(dk - np.minimum(z_a, z_b), 0.0)
        far_extra = np.maximum(np.maximum(z_a, z_b) - dk, 0.0)
    on = g.coverage[k, row, col] & (z_hi >= dk - eps - near_extra) & (z_lo <= dk + thickness + eps + far_extra)
    return int(len(on)), int((~on).sum())


def view_depth_of_window_depth(f, d):
    """Positive view depth of window depth d under the frame's projection and depth convention
    (standard: d = (ndc + 1) / 2; reversed-Z: d = ndc), in float64."""
    P = f.projection_matrix.astype(np.float64)
    ndc = d if f.settings.depth_mode == "reversed_z" else 2.0 * d - 1.0
    return P[2, 3] / (ndc + P[2, 2])


def stored_depth_error(f, scene) -> float:
    """The device's precision of its stored depths, measured on this frame: the largest difference
    between layer 0's window depth and the exact window depth of the surface the pixel centre's
    camera ray meets (Embree, float64 projection), over the pixels where both see the same object."""
    s, g = f.settings, f.gbuffer
    P, V = f.projection_matrix.astype(np.float64), f.view_matrix.astype(np.float64)
    j, i = np.meshgrid(np.arange(s.width) + 0.5, np.arange(s.height) + 0.5)
    x, y = j / s.width * 2 - 1, 1 - i / s.height * 2
    view_dir = np.stack([(x + P[0, 2]) / P[0, 0], (y + P[1, 2]) / P[1, 1], -np.ones_like(x)], -1)  # view depth 1
    to_world = np.linalg.inv(V)
    d = view_dir @ to_world[:3, :3].T
    length = np.linalg.norm(d, axis=-1)
    hit = ssrlab._core.embree_intersect(scene, np.broadcast_to(to_world[:3, 3], d.shape).reshape(-1, 3).astype(np.float32),
                                        (d / length[..., None]).reshape(-1, 3).astype(np.float32), 0.0, np.inf)
    t = hit["t"].reshape(length.shape)
    same = g.coverage[0] & np.isfinite(t) & (hit["object"].reshape(t.shape) == g.object_id[0])
    assert same.mean() > 0.5 * g.coverage[0].mean(), "the camera rays and the G-buffer see different scenes"
    z = t[same] / length[same]
    ndc = -P[2, 2] + P[2, 3] / z
    exact = ndc if s.depth_mode == "reversed_z" else (ndc + 1.0) / 2.0
    return float(np.abs(g.window_depth[0][same].astype(np.float64) - exact).max())


def check(f, *, surface: bool = True, max_off: float = 0.0, depth_error: float = 0.0) -> tuple[int, int]:
    assert_all_finite(f)
    checked, off = hits_off_surface(f, depth_error) if surface else (0, 0)
    assert off <= max_off * max(checked, 1), \
        f"{off} of {checked} hits are not on the surface they claim ({describe_settings(f.settings)})"
    return checked, off


# -- strategies ------------------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def procedural(name: str) -> ssrlab.Scene:
    return ssrlab.scenes.load(name)


def constructed(kind: str) -> ssrlab.Scene:
    return {"thin_poles": thin_poles, "mirror_box": mirror_box, "degenerate": degenerate_mesh_scene}[kind]()


SCENE_NAMES = list(ssrlab.scenes.SCENES) + ["thin_poles", "mirror_box", "degenerate"]


def scene_by_name(name: str) -> ssrlab.Scene:
    return procedural(name) if name in ssrlab.scenes.SCENES else _constructed_cached(name)


@functools.lru_cache(maxsize=None)
def _constructed_cached(name: str) -> ssrlab.Scene:
    return constructed(name)


def field_strategy(name: str):
    spec = _FIELDS[name]
    m, typ = spec.metadata, spec.type
    if m["choices"]:
        return st.sampled_from(m["choices"])
    if typ in ("bool", bool):
        return st.booleans()
    lo, hi = m["lo"], CAPS.get(name, m["hi"])
    if name == "downscale":
        return st.sampled_from((1, 2, 4))
    if typ in ("int", int):
        s = st.integers(lo, hi)
    elif lo > 0 and hi / lo >= 1e3:  # wide ranges: log-uniform, so small values are drawn too
        s = st.floats(math.log10(lo), math.log10(hi)).map(lambda e: float(min(max(10 ** e, lo), hi)))
    elif lo == 0 and hi >= 1e3:
        s = st.one_of(st.floats(-3, math.log10(hi)).map(lambda e: float(min(10 ** e, hi))), st.just(0.0))
    else:
        s = st.floats(lo, hi, allow_nan=False)
    s = st.one_of(st.sampled_from((lo, hi)), s)  # the documented bounds themselves, often
    if m["off"] is not None:
        s = st.one_of(st.just(m["off"]), s)
    return s


@st.composite
def any_settings(draw, **fixed):
    # (user_passes, user_params and user_modules name passes and the modules that declare them: none here)
    kw = {n: draw(field_strategy(n)) for n in _FIELDS if n not in fixed and n not in ("user_passes", "user_params", "user_modules")}
    kw.update(fixed)
    # Satisfy the cross-field constraints (Settings.describe(), [constraints]).
    kw["hiz_max_level"] = max(kw["hiz_max_level"], kw["hiz_stop_level"], kw["hiz_start_level"])
    if kw["fade_distance_start"] == 0.0:
        kw["fade_distance_end"] = 0.0
    elif kw["fade_distance_end"] <= kw["fade_distance_start"]:
        if kw["fade_distance_start"] >= 1e7:
            kw["fade_distance_start"] = 5e6
        kw["fade_distance_end"] = min(1e7, 2 * kw["fade_distance_start"])
    # method / fallback "bvh" and "probes" hand their radiance to the resolve.
    if kw["glossy"] != "stochastic" or kw["temporal_ray_reuse"]:
        kw["method"] = "linear" if kw["method"] == "bvh" else kw["method"]
        kw["fallback"] = "environment" if kw["fallback"] in ("bvh", "probes") else kw["fallback"]
    # variance_rays adds the rays adaptive_rays left out to the screen-space stochastic rays.
    if kw["variance_rays"]:
        kw["adaptive_rays"] = True
        if kw["method"] not in ("linear", "hiz") or kw["glossy"] != "stochastic":
            kw["variance_rays"] = False
    # SVGF accumulates its own history.
    if kw["denoise"] == "svgf" and "temporal_reflections" not in fixed:
        kw["temporal_reflections"] = False
    # A probe capture traces 6 * probe_size^2 rays per probe on the CPU here: kept small.
    kw["probe_size"] = min(kw["probe_size"], 32)
    kw["probe_grid"] = min(kw["probe_grid"], 2)
    # A fragment-list budget beyond the device's largest storage buffer is a ValueError by design
    # (tests/test_deep_gbuffer.py): drawn well within what every device holds (GL guarantees 128 MiB).
    kw["deep_gbuffer_budget"] = min(kw["deep_gbuffer_budget"], 16)
    return ssrlab.Settings(**kw)


@st.composite
def any_camera(draw, scene: ssrlab.Scene):
    lo, hi = (np.asarray(b, np.float64) for b in scene.bounds)
    c, r = (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    unit = st.floats(-1, 1)
    pos = c + r * np.array([draw(unit), draw(st.floats(-0.3, 1.5)), draw(unit)]) * draw(st.sampled_from((0.5, 1.2, 2.5)))
    tgt = c + r * 0.5 * np.array([draw(unit), draw(unit), draw(unit)])
    assume(np.linalg.norm(tgt - pos) > 1e-3 * r)
    fwd = (tgt - pos) / np.linalg.norm(tgt - pos)
    assume(abs(fwd[1]) < 0.999)
    near = draw(st.sampled_from((1e-4, 1e-3, 1e-2, 0.1))) * r
    ratio = 10 ** draw(st.floats(2, 8))
    fov = draw(st.one_of(st.sampled_from((1.0, 178.0)), st.floats(5, 150)))
    return ssrlab.Camera(position=tuple(pos), target=tuple(tgt), fov_y=fov, near=near, far=near * ratio)


# -- constructed scenes ----------------------------------------------------------------------------

MIRROR = ssrlab.Material(base_color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.0, reflectivity=1.0)


def thin_poles() -> ssrlab.Scene:
    """Poles one pixel thin (and thinner) at 64 px, standing on a mirror floor."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 20, material=MIRROR, name="floor")
    for k, w in enumerate((0.05, 0.02, 0.008)):
        s.add_box((-1.5 + 1.5 * k, 1.0, -1.0), (w, 2.0, w), name=f"pole{k}",
                  material=ssrlab.Material(base_color=(0.9, 0.2, 0.1)))
    s.add_light(ssrlab.directional_light((0.3, -1, -0.2)))
    s.camera = ssrlab.Camera(position=(0, 1.0, 4.0), target=(0, 0.6, -1), fov_y=50, near=0.05, far=50)
    return s


def mirror_box() -> ssrlab.Scene:
    """A mirror room: rays bounce toward the camera, graze walls and leave through the border."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 10, material=MIRROR, name="floor")
    s.add_plane((0, 0, -3), 10, normal=(0, 0, 1), material=MIRROR, name="back")
    s.add_plane((-3, 0, 0), 10, normal=(1, 0, 0), material=ssrlab.Material(base_color=(0.2, 0.6, 0.2)), name="left")
    s.add_sphere((0.5, 0.6, -1.0), 0.6, material=ssrlab.Material(base_color=(0.8, 0.3, 0.1), roughness=0.3))
    s.add_light(ssrlab.directional_light((0.2, -1, -0.4)))
    s.camera = ssrlab.Camera(position=(0.3, 1.0, 3.0), target=(0, 0.8, -3), fov_y=60, near=0.05, far=30)
    return s


def degenerate_mesh_scene() -> ssrlab.Scene:
    """Zero-area triangles (repeated and collinear vertices) and zero normals beside real ones."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 10, material=MIRROR, name="floor")
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0.5, 0.5, 0], [2, 2, 0], [0, 1, 0], [0, 1, 0]], np.float32)
    idx = np.array([[0, 1, 2], [0, 0, 0], [0, 3, 4], [5, 6, 5], [0, 2, 5], [1, 1, 2]])
    s.add_mesh(p + [0, 0.2, -1], idx, name="degenerate", material=ssrlab.Material(base_color=(0.2, 0.4, 0.9)))
    s.add_mesh(p + [-1.5, 0.2, -1], idx, normals=np.zeros_like(p), name="zero_normals",
               material=ssrlab.Material(base_color=(0.9, 0.9, 0.2), reflectivity=0.5, roughness=0.2))
    s.add_light(ssrlab.directional_light((0.3, -1, -0.5)))
    s.camera = ssrlab.Camera(position=(0, 1.5, 3.0), target=(0, 0.5, -1), fov_y=50, near=0.05, far=40)
    return s


def transformed(scale: float, offset=(0.0, 0.0, 0.0)) -> tuple[ssrlab.Scene, ssrlab.Camera]:
    """mirror_box's layout at `scale`, moved `offset` away from the origin (camera included)."""
    o = np.asarray(offset, np.float64)
    s = ssrlab.Scene()
    M = ssrlab.transforms.translate(o) @ ssrlab.transforms.scale(scale)
    s.add_plane((0, 0, 0), 10, material=MIRROR, name="floor", transform=M)
    s.add_plane((0, 0, -3), 10, normal=(0, 0, 1), material=MIRROR, name="back", transform=M)
    s.add_box((0.5, 0.6, -1.0), (1, 1.2, 1), rotation_y=30, transform=M,
              material=ssrlab.Material(base_color=(0.8, 0.3, 0.1), roughness=0.3))
    s.add_light(ssrlab.directional_light((0.2, -1, -0.4)))
    cam = ssrlab.Camera(position=tuple(o + scale * np.array([0.3, 1.0, 3.0])),
                        target=tuple(o + scale * np.array([0, 0.8, -3.0])), fov_y=60, near=0.05 * scale,
                        far=30 * scale)
    return s, cam


def small(**kw) -> ssrlab.Settings:
    kw.setdefault("width", 64)
    kw.setdefault("height", 48)
    kw.setdefault("shadow_map_size", 256)
    return ssrlab.Settings(**kw)


# -- properties ------------------------------------------------------------------------------------

@examples(24)
@given(name=st.sampled_from(SCENE_NAMES), s=any_settings())
def test_any_settings_give_finite_outputs_and_hits_on_their_surface(renderer, name, s):
    f = renderer.render(scene_by_name(name), settings=s)
    # Coarse settings (stride up to 64 with binary refinement) may land a hit a step's
    # tolerance away; the on-surface check allows none at stride 1 and 1 % otherwise.
    check(f, max_off=0.0 if s.stride == 1 and s.refine_steps == 0 else 0.01)
    f.release()


@examples(16)
@given(data=st.data(), name=st.sampled_from(SCENE_NAMES), method=st.sampled_from(("linear", "hiz")),
       depth_mode=st.sampled_from(("standard", "reversed_z")))
def test_any_camera_gives_finite_outputs(renderer, data, name, method, depth_mode):
    scene = scene_by_name(name)
    cam = data.draw(any_camera(scene))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # far/near beyond the standard convention's safe range is drawn on purpose
        f = renderer.render(scene, cam, small(method=method, depth_mode=depth_mode, layers=2, sampling="vndf",
                                              rays_per_pixel=2))
    check(f, surface=depth_mode == "reversed_z" or cam.far / cam.near <= 1e6)
    f.release()


@examples(10)
@given(seed=st.integers(0, 2**31 - 1), count=st.integers(1, 40), spread=st.sampled_from((1e-3, 1.0, 1e3)))
def test_random_triangle_soups_render_finite(renderer, seed, count, spread):
    rng = np.random.default_rng(seed)
    p = (rng.normal(size=(3 * count, 3)) * spread).astype(np.float32)
    p[rng.uniform(size=3 * count) < 0.2] = 0.0  # collapsed corners: degenerate triangles
    s = ssrlab.Scene()
    s.add_mesh(p, None, material=ssrlab.Material(reflectivity=float(rng.uniform()), roughness=float(rng.uniform())))
    s.add_plane((0, -3 * spread, 0), 40 * spread, material=MIRROR)
    s.add_light(ssrlab.directional_light(tuple(rng.normal(size=3)) if count % 2 else (0, -1, 0)))
    cam = ssrlab.scenes.frame_camera(s)
    for method in ("linear", "hiz"):
        check(renderer.render(s, cam, small(method=method, layers=3)))


@st.composite
def extreme_transform(draw):
    """An object transform with extreme but finite parts: scale 1e-30..1e30 (per axis or uniform),
    a translation up to 1e12, any rotation, sometimes a projective bottom row."""
    uniform = draw(st.booleans())
    exps = [draw(st.floats(-30, 30))] * 3 if uniform else [draw(st.floats(-30, 30)) for _ in range(3)]
    scale = [draw(st.sampled_from((-1.0, 1.0))) * 10 ** e for e in exps]
    offset = [draw(st.sampled_from((-1.0, 1.0))) * 10 ** draw(st.floats(-3, 12)) for _ in range(3)]
    angle = draw(st.floats(0, 360))
    m = ssrlab.transforms.translate(offset) @ ssrlab.transforms.rotate((0.0, 1.0, 0.0), angle) @ np.diag([*scale, 1.0])
    if draw(st.integers(0, 5)) == 0:  # a projective bottom row: never a glTF TRS matrix
        m = m.copy()
        m[3, draw(st.integers(0, 3))] = 10 ** draw(st.floats(-3, 20))
    return np.asarray(m, np.float32)


@examples(20)
@given(m=extreme_transform(), method=st.sampled_from(("linear", "hiz")))
def test_extreme_transforms_are_refused_or_render_finite(renderer, m, method):
    """Finite in, finite out: a transform whose products overflow float32 anywhere downstream is
    refused where the object is made (a ValueError naming it); any other renders finite."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 20, material=MIRROR, name="floor")
    s.add_light(ssrlab.directional_light((0.2, -1, -0.4)))
    try:
        s.add_box((0.5, 0.6, -1.0), (1, 1.2, 1), material=ssrlab.Material(base_color=(0.8, 0.3, 0.1)),
                  transform=m, name="extreme")
    except ValueError as e:
        assert "object 'extreme'" in str(e) and ("transform" in str(e) or "world space" in str(e)), str(e)
        return
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a far/near ratio beyond the standard convention's is drawn on purpose
        f = renderer.render(s, ssrlab.scenes.frame_camera(s), small(method=method, layers=2))
    check(f, surface=False)
    f.release()


@st.composite
def extreme_camera(draw):
    """A camera anywhere up to 1e20 from the origin, looking anywhere, with any near plane."""
    def far_point():
        return tuple(draw(st.sampled_from((-1.0, 1.0))) * 10 ** draw(st.floats(-3, 20)) for _ in range(3))

    pos = far_point()
    target = draw(st.one_of(st.just((0.0, 0.5, 0.0)), st.builds(far_point)))
    near = 10 ** draw(st.floats(-6, 3))
    return dict(position=pos, target=target, fov_y=draw(st.floats(1, 178)), near=near,
                far=near * 10 ** draw(st.floats(0.5, 9)))


@examples(20)
@given(kw=extreme_camera(), depth_mode=st.sampled_from(("standard", "reversed_z")))
def test_extreme_camera_placements_are_refused_or_render_finite(renderer, kw, depth_mode):
    try:
        cam = ssrlab.Camera(**kw)
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = renderer.render(procedural("spheres_and_boxes"), cam,
                                small(depth_mode=depth_mode, layers=2, rays_per_pixel=2, sampling="vndf"))
    except ValueError as e:
        assert "Camera." in str(e), str(e)
        return
    check(f, surface=False)
    f.release()


# -- named edge cases ------------------------------------------------------------------------------

METHODS = pytest.mark.parametrize("method", ["linear", "hiz"])


@METHODS
def test_grazing_rays(renderer, method):
    """The eye 10 cm above a mirror floor: rays leave the floor at a few degrees and run almost
    along the line of sight (a step of one pixel covers metres in depth: ray_step thickness)."""
    s = procedural("mirror_test")
    cam = ssrlab.Camera(position=(0, 0.1, 6.0), target=(0, 0.05, -6.0), fov_y=40, near=0.01, far=60)
    f = renderer.render(s, cam, small(method=method, sampling="mirror", fade_border=0.0, thickness_mode="ray_step"))
    checked, _ = check(f)
    assert checked > 0


def test_surface_check_detects_wrong_hits(renderer):
    """The on-surface check can fail: hits moved 6 pixels sideways are reported."""
    f = renderer.render(procedural("mirror_test"), settings=small(sampling="mirror"))
    checked, off = hits_off_surface(f)
    assert checked > 100 and off == 0
    hit = f.read("rays.hit").copy()
    hit[..., 1] -= 6.0  # 6 pixels (GL rows) lower: the hit pixel moves down the wall or off it
    f._cache["rays.hit@0"] = hit
    f.__dict__.pop("rays", None)
    checked, off = hits_off_surface(f)
    assert off > 0.5 * checked


@METHODS
def test_rays_toward_the_camera(renderer, method):
    s = ssrlab.Scene()
    s.add_plane((0, 0, -2), 8, normal=(0, 0, 1), material=MIRROR, name="mirror")
    s.add_box((1.0, 0.3, 1.0), (0.5, 0.5, 0.5), material=ssrlab.Material(base_color=(0.9, 0.2, 0.1)))
    s.add_light(ssrlab.directional_light((0, -0.5, -1)))
    cam = ssrlab.Camera(position=(0, 0, 3), target=(0, 0, -2), fov_y=50, near=0.05, far=20)
    # Camera fade off (end <= start): rays straight back at the camera are traced, not faded.
    # Rays leave the mirror back toward the camera and meet the box (its face toward the mirror
    # is hidden from the camera: in layer 2).
    f = renderer.render(s, cam, small(method=method, sampling="mirror", fade_camera_start=1.0, fade_camera_end=1.0,
                                      layers=3))
    checked, _ = check(f)
    toward = f.rays.direction[0][..., 2] > 0.9
    assert toward.sum() > 100 and f.rays.hit[0][toward].sum() > 10 and checked > 0


@METHODS
@pytest.mark.parametrize("downscale", [1, 2])
def test_rays_starting_at_the_image_border(renderer, method, downscale):
    f = renderer.render(procedural("mirror_test"), settings=small(
        method=method, downscale=downscale, fade_border=0.0, sampling="ggx", rays_per_pixel=2, width=37, height=23))
    check(f)
    traced = f.rays.traced
    assert traced[:, 0].any() or traced[:, -1].any() or traced[-1].any()


@METHODS
def test_one_pixel_thin_objects(renderer, method):
    f = renderer.render(thin_poles(), settings=small(method=method, sampling="mirror", layers=2))
    checked, _ = check(f)
    assert checked > 0


@METHODS
@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e5])
def test_scene_scale(renderer, method, scale):
    scene, cam = transformed(scale)
    s = small(method=method, thickness=min(0.2 * scale, 1e6), max_distance=min(100 * scale, 1e7))
    f = renderer.render(scene, cam, s)
    checked, _ = check(f)
    assert checked > 0


@METHODS
@pytest.mark.parametrize("offset", [1e5, 1e6, 1e7])
def test_far_from_the_origin(renderer, method, offset):
    # float32 positions 1e7 from the origin are spaced 1 unit apart: the geometry itself is
    # mangled there, so only finiteness is required; the hits must still be on what was drawn.
    scene, cam = transformed(1.0, (offset, 0.3 * offset, -offset))
    f = renderer.render(scene, cam, small(method=method))
    check(f, max_off=0.0 if offset <= 1e5 else 0.02)


@METHODS
@pytest.mark.parametrize("depth_mode", ["standard", "reversed_z"])
@pytest.mark.parametrize("ratio", [1e2, 1e4, 1e6, 1e8])
def test_near_far_ratios(renderer, method, depth_mode, ratio):
    scene = procedural("spheres_and_boxes")
    c = scene.camera
    cam = ssrlab.Camera(position=tuple(c.position), target=tuple(c.target), fov_y=c.fov_y, near=100.0 / ratio,
                        far=100.0)
    import warnings

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        f = renderer.render(scene, cam, small(method=method, depth_mode=depth_mode))
    warned = any(issubclass(x.category, ssrlab.renderer.DepthPrecisionWarning) for x in w)
    assert warned == (depth_mode == "standard" and ratio > ssrlab.renderer.STANDARD_DEPTH_SAFE_RATIO)
    if not warned:
        check(f)
        return
    # Beyond the safe ratio the standard convention's window depths are coarse (at 1e8 a handful
    # of distinct values over the image, metres apart in view depth): no tracer comparing window
    # depths can place a hit closer than they resolve. The limit is the device's own precision,
    # measured on the frame: its stored depths' error against the exact depths of the surfaces
    # (stored_depth_error), plus one step of the 32-bit float format at that depth for the ray's own
    # window depth. Every hit must lie on its surface to within that, and none beyond it.
    deepest = np.float32(f.gbuffer.window_depth[0][f.gbuffer.coverage[0]].max())
    step = float(deepest - np.nextafter(deepest, np.float32(0)))  # the format's step below the deepest depth
    error = stored_depth_error(f, scene)
    checked, _ = check(f, depth_error=error + step)
    assert checked > 0
    print(f"near/far {ratio:g} {method}: stored depth error {error:.3g} + format step {step:.3g}; "
          f"{checked} hits on their surface to within it")


def test_degenerate_triangles_and_zero_normals(renderer):
    for method in ("linear", "hiz"):
        check(renderer.render(degenerate_mesh_scene(), settings=small(method=method, layers=3)))


def test_nan_normals_are_an_error():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    n = np.array([[0, 0, 1], [np.nan, 0, 1], [0, 0, 1]], np.float32)
    with pytest.raises(ValueError, match="normals must be finite"):
        ssrlab.Scene().add_mesh(p, [0, 1, 2], normals=n)


@pytest.mark.parametrize("size", [(1, 1), (1, 17), (17, 1), (2, 3), (63, 37), (33, 17)])
@pytest.mark.parametrize("method, downscale", [("linear", 1), ("hiz", 1), ("hiz", 2), ("linear", 4)])
def test_tiny_and_odd_images(renderer, size, method, downscale):
    w, h = size
    f = renderer.render(procedural("spheres_and_boxes"), settings=small(
        width=w, height=h, method=method, downscale=downscale, reuse_radius=2, rays_per_pixel=2))
    check(f)
    assert f.color.shape == (h, w, 3)


@METHODS
def test_sixteen_layers(renderer, method):
    f = renderer.render(procedural("box_stack"), settings=small(method=method, layers=16))
    checked, _ = check(f)
    assert checked > 0 and f.rays.hit_layer.max() >= 2


# -- parity ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("method, downscale", [("linear", 1), ("hiz", 1), ("hiz", 2)])
def test_results_do_not_depend_on_the_image_size_parity(renderer, method, downscale):
    """Odd and even image sizes see the same view on pixel grids shifted by half a pixel, so
    pixels cannot be compared one to one; what must agree is how well SSR does against each
    frame's own per-ray reference. Pooled over three even sizes (W and H even) and three odd
    ones (both odd): the share of true hits found may differ only by sampling noise (3 standard
    errors of the difference of two proportions, plus 1 %), the median hit-position error by
    0.1 px, and the mean reflection over reflective pixels by 2 %."""
    scene = procedural("spheres_and_boxes")
    groups = {"even": ((64, 48), (62, 46), (60, 44)), "odd": ((63, 47), (61, 45), (59, 43))}
    stats = {}
    for parity, sizes in groups.items():
        found = real = 0
        errs, refl = [], []
        for w, h in sizes:
            f = renderer.render(scene, settings=small(width=w, height=h, method=method, downscale=downscale,
                                                      rays_per_pixel=4, fade_border=0.0))
            check(f)
            truth = f.reference("per_ray")
            traced = np.broadcast_to(f.rays.traced, truth.hit.shape) & (f.rays.weight > 0)
            real_rays = truth.hit & traced
            found += int(ssrlab.reference.ssr_found(f, truth)[real_rays].sum())
            real += int(real_rays.sum())
            errs.append(ssrlab.reference.hit_position_error(f, truth))
            refl.append(f.reflection[f.gbuffer.reflectivity[0] > 0])
            f.release()
        stats[parity] = (found / real, real, float(np.median(np.concatenate(errs))),
                         float(np.concatenate(refl).mean()))
    (pe, ne, me, re), (po, no, mo, ro) = stats["even"], stats["odd"]
    p = (pe * ne + po * no) / (ne + no)
    se = np.sqrt(p * (1 - p) * (1 / ne + 1 / no))
    assert ne > 500 and no > 500, stats
    assert abs(pe - po) < 3 * se + 0.01, stats
    assert abs(me - mo) < 0.1, stats
    assert abs(re - ro) / re < 0.02, stats
