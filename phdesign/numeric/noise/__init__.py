"""Noise: what a gain costs in sensor noise, under refinement, and the speed/noise trade-off."""
