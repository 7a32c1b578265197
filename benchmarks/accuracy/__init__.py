"""Benchmarks of the accuracy genre (benchmarks/README.md)."""
