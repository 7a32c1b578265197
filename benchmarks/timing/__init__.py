"""Benchmarks of the timing genre (benchmarks/README.md)."""
