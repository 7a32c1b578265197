"""The lab: studies that use the renderer and the truth to measure techniques.

    plan, run, report   a sweep of settings, scored against a reference (``ssrlab bench``)
    timing              statistics of repeated timings (spread, medians, when a time can be judged)
    journal             a sweep's rows on disk as they finish (resume, several runs)
    experiments         the thesis's experiments over sweeps; glossy, hybrid, precision,
                        temporal: the studies of one technique each
    hostile_gltf        malformed glTF files that the loader must reject cleanly
    lanes               how a SIMD vector's lanes use the walk steps it pays for

Nothing here is imported by ``import ssrlab``; ``ssrlab.bench``, ``ssrlab.experiments`` and the
other old names still reach these modules.
"""
