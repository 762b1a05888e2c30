"""Certified numbers: the exact closed system, the certified spectrum and its proof file."""
