"""The benchmark scripts, one folder per genre (benchmarks/README.md), and the helpers they share
(benchmarks.common). A package so that a script of one genre can import another's code by name
(benchmarks.timing.raster_floor) once it has put the repository's root on sys.path."""
