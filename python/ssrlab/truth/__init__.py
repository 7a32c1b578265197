"""The truth: what a rendered image is compared with.

    reference           the converged, per-ray and thesis references (Frame.reference, reference_image)
    analytic            closed-form answers for the test scenes (mirror hits, GGX shading)
    metrics             image errors (thesis error, RMSE, PSNR, FLIP, SSIM)
    crosscheck          the reference against Mitsuba 3: loading it, the scene in Mitsuba, its renders
    mitsuba_bsdf        ssrlab's BRDF as a Mitsuba BSDF, and where Mitsuba's own BSDFs are exact
    crosscheck_scenes   the scenes the cross-check renders
    crosscheck_compare  the ssrlab side of the cross-check and its statistics
    views               how the references show themselves in Jupyter

Nothing here is imported by ``import ssrlab``; ``ssrlab.reference``, ``ssrlab.metrics`` and the
other old names still reach these modules.
"""

from . import views as _views

_views.install()  # the references' Jupyter representations, as ssrlab.display gives the frames theirs
