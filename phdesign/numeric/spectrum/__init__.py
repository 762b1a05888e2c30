"""Converged spectra: the eigen stage, the drift test, the abscissa and the refinement."""
