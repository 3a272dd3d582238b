"""Benchmarks of the coated-punch solvers (work-precision diagrams, see work_precision.py)."""
