"""Independent re-checks of phdesign's proof files, with the standard library alone.

Nothing here imports numpy, sympy, mpmath, python-flint, cvxpy or the rest of phdesign
(only :mod:`phdesign.core` would be allowed): a mistake in the prover cannot pass the
checker by sharing its code.
"""
