"""Benchmarks of the tools genre (benchmarks/README.md)."""
