"""Layer 1: the math of PBP in pure NumPy (no Drake import anywhere in this package)."""
