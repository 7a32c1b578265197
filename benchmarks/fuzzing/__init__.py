"""Benchmarks of the fuzzing genre (benchmarks/README.md)."""
