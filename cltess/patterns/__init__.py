"""Tessellation patterns, one module each: the NumPy mirror of the device header
kernels/patterns/<name>.h (ARCHITECTURE.md section 2)."""
