"""A live view of a scene in the browser: ``ssrlab.view(scene)`` or ``ssrlab view SCENE``.

The page (viser's, served by this process, 127.0.0.1 unless told otherwise) shows ssrlab's frames
over its 3D view, rendered from the page's own camera at the page's aspect, with every setting of
ssrlab.Settings as a control, every channel a frame holds as a view, a pixel inspector, the live
numbers of each frame and its error against the converged reference. docs/guide/viewer.md.
"""

from __future__ import annotations

from pathlib import Path

from .server import FRAMES, Shown, Viewer

__all__ = ["FRAMES", "Viewer", "Shown", "view"]


def view(scene, settings=None, renderer=None, *, host: str = "127.0.0.1", port: int | None = None,
         lossless: bool = False, accumulate: int = 8, out="renders/view", device: str = "auto",
         watch_shaders: bool = True, reference_rays=(4, 16, 64), frames: str = FRAMES[0],
         moving_fps: float | None = None, verbose: bool = False) -> Viewer:
    """Opens a live view of `scene` and returns at once with its handle (ssrlab.viewer.Viewer): its
    ``url``, ``settings``, ``camera`` and ``frame`` readable and settable while the page is open,
    ``close()``. In Jupyter the handle shows the page inline.

    scene: an ssrlab.Scene, a procedural scene's name (``ssrlab scenes``) or a .gltf/.glb path;
    settings: what the page starts with (width and height follow the page's canvas); renderer: the
    Renderer to render with (default: a new one on `device`); host, port: where the page is served
    (127.0.0.1 and a free port by default: another machine reaches it through an SSH port forward);
    lossless: PNG frames instead of JPEG (what the tests compare pixel for pixel); accumulate: frames
    of new seeds averaged while the camera rests; out: the folder 'save frame' and 'record camera
    path' write into (never replacing a file); watch_shaders: re-render when a user pass's shader
    (or, in a source checkout, any of ssrlab's) changes on disk; reference_rays: the converged
    reference's rays per reflective pixel in each round while the camera rests (with 'reference' on);
    frames: how the page shows frames, "background" (the 3D view's background, in every layout of
    the page) or "overlay" (an image over the canvas: a shorter path in the page, for which the panel
    stays docked; ssrlab.viewer.server.FRAMES says why); moving_fps: frames a second a moving
    camera renders at most (None: as many as the device gives; a limit leaves cores to a page on the
    same machine, and costs frames)."""
    from .. import scenes
    from ..scene import Scene

    source = None
    if isinstance(scene, (str, Path)):
        name = str(scene) if str(scene) in scenes.SCENES else str(Path(scene).resolve())
        source = f"ssrlab.scenes.load({name!r})"
        scene = scenes.load(name)
    elif isinstance(scene, Scene) and scene.name in scenes.SCENES:
        source = f"ssrlab.scenes.load({scene.name!r})"
    return Viewer(scene, settings, renderer, host=host, port=port, scene_source=source, lossless=lossless,
                  accumulate=accumulate, out=out, device=device, watch_shaders=watch_shaders,
                  reference_rays=reference_rays, frames=frames, moving_fps=moving_fps, verbose=verbose)
