"""Time: exact-in-time simulation of plant and observer, deterministic or with noise."""
