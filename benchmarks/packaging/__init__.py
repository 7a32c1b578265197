"""Benchmarks of the packaging genre (benchmarks/README.md)."""
