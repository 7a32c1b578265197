"""The moving-camera study of temporal accumulation (notebooks/temporal.ipynb): the
configurations of history rejection it compares, and the per-frame error of each against
every frame's converged reference along a camera path (ssrlab.sequence.hall_path)."""

from __future__ import annotations

import numpy as np

from ..truth import metrics

# With rejection, the accumulated reflection's error may exceed that of the frame alone (no
# history) by at most this much rmse on any frame: "no ghost trails".
GHOST_MARGIN = 0.005


def history_configurations(settings) -> dict:
    """The configurations the moving-camera study compares, from base `settings` (1 ray):
    no history; accumulation with every rejection on (previous depth, normal, off-screen, and
    the neighbourhood variance clamp, gamma 1); with depth/normal/off-screen rejection only; and
    without any rejection (the ghosting case)."""
    acc = settings.replace(temporal_reflections=True)
    return {
        "no history": settings.replace(temporal_reflections=False),
        "rejection": acc.replace(temporal_clamp=1.0),
        "depth+normal only": acc.replace(temporal_clamp=0.0),
        "no rejection": acc.replace(temporal_clamp=0.0, reject_depth=0.0, reject_normal=-1.0, reject_offscreen=False),
    }


def moving_camera_errors(renderer, scene, cameras, configurations: dict, *, reference_rays: int = 64,
                         metric=None) -> dict:
    """Per configuration, the per-frame rmse of the reflection (frame.reflection: the
    accumulation where temporal_reflections is on) against each frame's own converged
    reference, over that frame's reflective pixels. Each frame's reference is computed once,
    from the first configuration's frame (the reference depends on the camera, not the
    settings being compared). Returns {name: np.ndarray of per-frame errors}."""
    rmse = metric or metrics.rmse
    cameras = list(cameras)
    refs, errors = [], {}
    for name, settings in configurations.items():
        e = []
        for i, frame in enumerate(renderer.render_sequence(scene, cameras, settings)):
            if len(refs) <= i:
                refs.append(frame.reference("converged", rays=reference_rays))
            e.append(rmse(frame.reflection, refs[i].reflection, refs[i].reflective))
        errors[name] = np.asarray(e, np.float64)
    return errors


__all__ = ["GHOST_MARGIN", "history_configurations", "moving_camera_errors"]
