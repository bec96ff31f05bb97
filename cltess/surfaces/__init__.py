"""NumPy reference evaluation of each patch kind (float64, slow, obviously right)."""
