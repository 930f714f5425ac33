"""Slow, plain NumPy references for the product's kernels (tests only)."""
