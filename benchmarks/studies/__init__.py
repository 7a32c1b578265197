"""Benchmarks of the studies genre (benchmarks/README.md)."""
