r"""The argument checks of the numeric front door: spectrum, simulate and tune.

Each public numeric function calls one checker of this module first, so that a wrong
argument is refused before any work with a phdesign error that names it (never an
``AttributeError`` or ``IndexError`` from deep inside, never a silent NaN).  The sensors
and the gain go through the same validation as everywhere else
(:func:`~phdesign.symbolic.observer.measurement_matrix` and
:func:`~phdesign.symbolic.observer.gain_matrix`: shape, finiteness, full row rank of
:math:`C_m`, :math:`L + L^\top \succ 0`, exactly on the given floats), so that no command
accepts what another refuses.

Examples
--------
>>> import numpy as np
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> nm = to_numeric(load_builtin("wave"))
>>> check_sensors_and_gain(nm, np.array([[0.0, 0.0]]), np.eye(1))  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
phdesign.core.errors.ObserverError: C_m must have full row rank ...; expected rank 1 but found 0
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from phdesign.core import limits
from phdesign.core.checks import choice, positive_int, positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, NumericError, ObserverError
from phdesign.numeric.bridge import require_numeric_model
from phdesign.numeric.discretization.registry import check_basis

__all__ = [
    "check_initial_state",
    "check_sensors_and_gain",
    "check_simulate_arguments",
    "check_spectrum_arguments",
    "check_tune_arguments",
]


def check_sensors_and_gain(
    nm: Any, C_m: Any, L: Any, *, gain_required: bool = True, what: str = "this computation"
) -> None:
    """Refuse sensors or a gain that the symbolic layer would refuse (one validation).

    Parameters
    ----------
    nm : NumericModel
    C_m, L : array-like or None
        Sensors and gain (both or neither when ``gain_required``; ``L`` unused otherwise).
    gain_required : bool
        Whether ``L`` must accompany ``C_m`` (spectrum, simulate) or is not taken (tune).
    what : str
        The computation, for the message refusing a symbolic gain.
    """
    from phdesign.symbolic.observer import gain_matrix, measurement_matrix

    if gain_required and (C_m is None) != (L is None):
        raise NumericError("give both the sensors C_m and the gain L, or neither")
    if C_m is None:
        return
    exact = measurement_matrix(C_m, nm.n_ports)
    if gain_required:
        gain = gain_matrix(L, exact.rows)
        if gain.free_symbols:
            names = ", ".join(sorted(map(str, gain.free_symbols)))
            raise ObserverError(
                f"{what} needs a numeric gain; found the symbolic L with {names}: give numbers "
                "(e.g. gain=[0.1, 1]) or tune one; symbolic gains are for classify"
            )


def check_initial_state(x0: Any, nm: Any, name: str) -> None:
    """Refuse an initial state that is not a function of z returning finite ``(m, n)`` values."""
    if x0 is None:
        return
    if not callable(x0):
        raise ArgumentError(
            f"{name} must be a function of z returning the state at the points z, shape (m, n) "
            f"(initial_state_function reads text such as 'x1: z'); found {type(x0).__name__}"
        )
    a, b = nm.interval
    z = np.linspace(a, b, 17)
    with np.errstate(all="ignore"):
        values = np.asarray(x0(z), dtype=float)
    if values.shape != (z.size, nm.size):
        raise NumericError(
            f"{name}(z) must return an array of shape (len(z), n) = ({z.size}, {nm.size}); "
            f"found {values.shape}"
        )
    bad = ~np.isfinite(values)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise NumericError(
            f"{name} must be finite on [{a:g}, {b:g}]; found {values[i, j]} in component "
            f"{j + 1} at z = {z[i]:g}"
        )


def _common(
    nm: Any, method: str, resolution: Any, tol: Any = None, max_resolution: Any = None
) -> None:
    require_numeric_model(nm)
    choice(method, "method", current().method_names)
    if resolution is not None:
        positive_int(resolution, "resolution")
    if max_resolution is not None:
        positive_int(max_resolution, "max_resolution")
    if tol is not None:
        positive_number(tol, "tol")


def check_spectrum_arguments(
    nm: Any,
    C_m: Any,
    L: Any,
    *,
    method: str,
    resolution: Any,
    max_resolution: Any,
    tol: Any,
    rtol_resolved: Any,
    count: Any,
    basis: Any = None,
) -> None:
    """Check the arguments of the spectrum (:mod:`phdesign.numeric.spectrum.converged`)."""
    _common(nm, method, resolution, tol, max_resolution)
    check_basis(current().entry(method), basis)
    if rtol_resolved is not None:
        positive_number(rtol_resolved, "rtol_resolved")
    positive_int(count, "count")
    check_sensors_and_gain(nm, C_m, L, what="the spectrum")
    limits.check_discretization(nm, method, resolution, max_resolution)


def check_simulate_arguments(
    nm: Any,
    C_m: Any,
    L: Any,
    *,
    x0: Any,
    xhat0: Any,
    t_end: Any,
    samples: Any,
    method: str,
    resolution: Any,
    u: Callable[[float], Any] | None,
    scheme: Any,
    z_w: Any,
    discrete: Any = None,
) -> None:
    """Check the arguments of :func:`~phdesign.numeric.time.simulation.simulate` and its budget."""
    _common(nm, method, resolution)
    positive_number(t_end, "t_end")
    positive_int(samples, "samples", minimum=2)
    if not isinstance(scheme, str):
        raise ArgumentError(f"scheme must be a name such as 'expm'; found {scheme!r}")
    check_sensors_and_gain(nm, C_m, L, what="a simulation")
    check_initial_state(x0, nm, "x0")
    check_initial_state(xhat0, nm, "xhat0")
    if xhat0 is not None and C_m is None:
        raise NumericError("xhat0 needs an observer: give the sensors C_m and the gain L")
    if u is not None and not callable(u):
        raise ArgumentError(f"u must be a function of t returning the inputs; found {u!r}")
    if z_w is not None:
        points = np.asarray(z_w, dtype=float)
        a, b = nm.interval
        if points.ndim != 1 or not points.size or not np.all(np.isfinite(points)):
            raise NumericError(f"z_w must be a non-empty list of finite points; found {z_w!r}")
        if points.min() < a or points.max() > b:
            raise NumericError(f"z_w must lie in [{a:g}, {b:g}]; found {points.tolist()}")
    limits.check_simulation(nm, C_m, t_end, samples, method, resolution, discrete)


def check_tune_arguments(
    nm: Any,
    C_m: Any,
    *,
    full: Any,
    starts: Any,
    seed: Any,
    log_range: Any,
    resolution: Any,
    maxiter: Any,
    method: str,
) -> None:
    """Check the arguments of :func:`~phdesign.numeric.tuning.search.tune` and its budget."""
    _common(nm, method, resolution)
    if C_m is None:
        raise ObserverError("tuning needs the sensors C_m")
    check_sensors_and_gain(nm, C_m, None, gain_required=False)
    if not isinstance(full, bool):
        raise ArgumentError(f"full must be True or False; found {full!r}")
    positive_int(starts, "starts")
    positive_int(seed, "seed", minimum=0)
    positive_int(maxiter, "maxiter")
    try:
        low, high = (float(x) for x in log_range)
    except (TypeError, ValueError):
        raise NumericError(f"log_range must be a pair (low, high); found {log_range!r}") from None
    if not (np.isfinite(low) and np.isfinite(high) and low < high):
        raise NumericError(f"log_range must hold finite low < high; found {log_range!r}")
    limits.check_tuning(nm, starts, seed, maxiter, resolution)
