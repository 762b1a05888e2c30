"""Gain tuning on the converged abscissa, its result and its robustness figure."""
