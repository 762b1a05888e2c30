r"""The argument checks of the numeric front door: spectrum, simulate, tune and sampling.

Each public numeric function calls one checker of this module first, so that a wrong
argument is refused before any work with a phdesign error that names it (never an
``AttributeError`` or ``IndexError`` from deep inside, never a silent NaN).  The sensors
and the gain go through the same validation as everywhere else
(:func:`~phdesign.symbolic.observer.measurement_matrix` and
:func:`~phdesign.symbolic.observer.gain_matrix`: shape, finiteness, full row rank of
:math:`C_m`, :math:`L + L^\top \succ 0`), so that no command accepts what another refuses.
Float arrays are checked in floating point first (shape, finiteness, the singular values
of :math:`C_m`, a Cholesky factorization of :math:`L + L^\top`; 0.1 ms where the exact
checks took 3 ms, at every call of a spectrum): when they pass by the margin
:data:`CLEAR_MARGIN` the exact checks, which read each float as its shortest decimal
(within a relative 1e-16), would pass too and are skipped; anything else (a list of text,
a symbol, a failure, a case within the margin) goes through the exact checks, which
decide and word the message.

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

import math
import numbers
from collections.abc import Callable
from typing import Any

import numpy as np

from phdesign.core import limits
from phdesign.core.checks import SAMPLERS, choice, positive_int, positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, NumericError, ObserverError
from phdesign.numeric.bridge import require_numeric_model
from phdesign.numeric.discretization.registry import check_basis

__all__ = [
    "SAMPLERS",
    "check_initial_state",
    "check_noise_intensity",
    "check_periods",
    "check_sampling",
    "check_sensors_and_gain",
    "check_simulate_arguments",
    "check_simulation",
    "check_spectrum_arguments",
    "check_tune_arguments",
]


def check_sampling(dt: object, sampler: object, *, dt_name: str = "dt") -> float:
    """Return ``dt`` as a float after checking it and the sampler's name.

    ``dt_name`` is how the period is called in the message (``"--dt"`` on the command line).

    Examples
    --------
    >>> check_sampling(1e-3, "average")
    0.001
    >>> check_sampling(0, "point")
    Traceback (most recent call last):
    ...
    phdesign.core.errors.NumericError: dt must be a finite positive number of seconds; found 0
    """
    value = math.nan
    if not isinstance(dt, bool) and isinstance(dt, (int, float, np.floating, np.integer)):
        value = float(dt)
    if not (math.isfinite(value) and value > 0):
        raise NumericError(f"{dt_name} must be a finite positive number of seconds; found {dt!r}")
    if sampler not in SAMPLERS:
        raise NumericError(f"unknown sampler {sampler!r}; expected one of {', '.join(SAMPLERS)}")
    return value


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
    C = _clearly_valid_sensors(C_m, nm.n_ports)
    if C is not None and (not gain_required or _clearly_definite_gain(L, C.shape[0])):
        return  # floats, checked in floating point: the exact checks would agree
    exact = measurement_matrix(C_m, nm.n_ports)
    if gain_required:
        gain = gain_matrix(L, exact.rows)
        if gain.free_symbols:
            names = ", ".join(sorted(map(str, gain.free_symbols)))
            raise ObserverError(
                f"{what} needs a numeric gain; found the symbolic L with {names}: give numbers "
                "(e.g. gain=[0.1, 1]) or tune one; symbolic gains are for classify"
            )


#: How clearly a float C_m or L must pass its check for the exact one to be skipped: the
#: exact checks read the floats' shortest decimals, within 1e-16 of them (module docstring).
CLEAR_MARGIN = 1e-10


def _real_matrix(value: Any) -> np.ndarray | None:
    """Return ``value`` as a finite 2-D array of real numbers, or None if it is not one."""
    if value is None or isinstance(value, str | bytes):
        return None
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        return None
    if array.ndim != 2 or array.dtype.kind not in "fiu" or array.size == 0:
        return None
    array = array.astype(float, copy=False)
    return array if np.all(np.isfinite(array)) else None


def _clearly_valid_sensors(C_m: Any, n_outputs: int) -> np.ndarray | None:
    r"""Return C_m as floats if it clearly has the shape (q, N n) and full row rank, else None.

    Full row rank by the singular values: :math:`\sigma_{\min} > \tau q \sigma_{\max}`,
    :math:`\tau` = :data:`CLEAR_MARGIN`.
    """
    C = _real_matrix(C_m)
    if C is None or not 1 <= C.shape[0] <= n_outputs or C.shape[1] != n_outputs:
        return None
    sigma = np.linalg.svd(C, compute_uv=False)
    return C if sigma[-1] > CLEAR_MARGIN * C.shape[0] * sigma[0] else None


def _clearly_definite_gain(L: Any, q: int) -> bool:
    r"""Tell whether L is a float (q, q) matrix with :math:`S = L + L^\top` clearly ≻ 0.

    By Cholesky, :math:`S = R R^\top`: :math:`\lambda_{\min}(S) = \|R^{-1}\|_2^{-2} \ge
    \|R^{-1}\|_F^{-2}`, which must exceed :math:`\tau q \max|S_{ij}|`.
    """
    G = _real_matrix(L)
    if G is None or G.shape != (q, q):
        return False
    S = G + G.T
    try:
        R = np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        return False
    inverse = np.linalg.solve(R, np.eye(q))
    return bool(1.0 / np.sum(inverse * inverse) > CLEAR_MARGIN * q * np.max(np.abs(S)))


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
    expected = f"{name}(z) must return an array of shape (len(z), n) = ({z.size}, {nm.size})"
    with np.errstate(all="ignore"):
        returned = x0(z)
        try:
            values = np.asarray(returned, dtype=float)
        except (ValueError, TypeError):  # ragged: e.g. [0, z - 0.9], a number beside an array
            raise NumericError(
                f"{expected}, one row per point; found {_shapes(returned)} (a list of "
                "components is np.column_stack([np.zeros_like(z), z - 0.9]), or give the "
                "text 'x1: 0, x2: z - 0.9')"
            ) from None
    if values.shape != (z.size, nm.size):
        raise NumericError(f"{expected}; found {values.shape}")
    bad = ~np.isfinite(values)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise NumericError(
            f"{name} must be finite on [{a:g}, {b:g}]; found {values[i, j]} in component "
            f"{j + 1} at z = {z[i]:g}"
        )
    boundary = getattr(x0, "boundary", None)
    expected_states = sum(b.size for b in nm.boundary)
    if boundary is not None and np.shape(boundary) != (expected_states,):
        raise NumericError(
            f"{name}.boundary must hold the {expected_states} boundary states of "
            f"{nm.name!r}; found shape {np.shape(boundary)}"
        )


def _shapes(value: Any) -> str:
    """Describe a ragged return value: ``a list of 2 entries of shapes (), (17,)``."""
    if isinstance(value, (list, tuple)):
        shapes = ", ".join(_shape_text(v) for v in value)
        return f"a {type(value).__name__} of {len(value)} entries of shapes {shapes}"
    return f"a {type(value).__name__}"


def _shape_text(value: Any) -> str:
    try:
        return str(np.shape(value))
    except (ValueError, TypeError):  # itself ragged
        return "?"


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
    u: Callable[[float], Any] | None,
    options: Any,
    discrete: Any = None,
) -> None:
    """Check what a simulation's options cannot check alone: the model's part, the budget.

    ``options`` is a checked :class:`~phdesign.numeric.time.options.SimulationOptions`;
    here are the sensors and gain, the initial states and inputs against the model, the
    points ``z_w`` against its interval, and the budget of
    :func:`check_simulation`.
    """
    require_numeric_model(nm)
    check_sensors_and_gain(nm, C_m, L, what="a simulation")
    check_initial_state(x0, nm, "x0")
    check_initial_state(xhat0, nm, "xhat0")
    if xhat0 is not None and C_m is None:
        raise NumericError("xhat0 needs an observer: give the sensors C_m and the gain L")
    if u is not None and not callable(u):
        raise ArgumentError(f"u must be a function of t returning the inputs; found {u!r}")
    if options.z_w is not None:
        a, b = nm.interval
        if min(options.z_w) < a or max(options.z_w) > b:
            raise NumericError(f"z_w must lie in [{a:g}, {b:g}]; found {list(options.z_w)}")
    check_simulation(
        nm, C_m, options.t_end, options.samples, options.method, options.resolution, discrete
    )


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


def check_simulation(
    nm: Any,
    C_m: Any,
    t_end: object,
    samples: object,
    method: object,
    resolution: object,
    discrete: Any = None,
) -> None:
    """Refuse a simulation whose time span or size is beyond the budgets.

    Parameters
    ----------
    nm : NumericModel
    C_m : array or None
        The sensors (the observer runs too when given: twice the states).
    t_end : float
        Final time: ``0 < t_end <= limits.MAX_T_END``.
    samples : int
        Output samples; ``t_end / (samples - 1) >= limits.MIN_TIME_STEP`` and samples times
        states at most :data:`limits.MAX_SIMULATION_VALUES`.
    method, resolution
        The discretization (checked by :func:`check_discretization`).
    discrete : DiscretePHS, optional
        A discretization given ready-made (its states replace the estimate).
    """
    if isinstance(t_end, bool) or not isinstance(t_end, numbers.Real):
        raise NumericError(f"t_end must be a number; found {type(t_end).__name__} {t_end!r}")
    end = float(t_end)
    if not (math.isfinite(end) and 0 < end <= limits.MAX_T_END):
        raise NumericError(
            f"t_end must be a positive number at most {limits.MAX_T_END:g}; found {end:g} "
            f"({limits.budget_text('MAX_T_END')})"
        )
    count = limits.integer(samples, "samples", NumericError)
    if count < 2:
        raise NumericError(f"samples must be at least 2; found {count}")
    step = end / (count - 1)
    if not step >= limits.MIN_TIME_STEP:
        raise NumericError(
            f"t_end / (samples - 1) = {step:.3g} is below {limits.MIN_TIME_STEP:g}: the time "
            "stamps would not be distinct; expected a longer t_end or fewer samples "
            f"({limits.budget_text('MIN_TIME_STEP')})"
        )
    if discrete is not None:
        states = int(discrete.dim)
    else:
        limits.check_discretization(nm, method, resolution)
        states = limits.state_count(nm, limits.resolution_or_default(nm, method, resolution))
    states *= 1 if C_m is None else 2
    total = count * states
    if total > limits.MAX_SIMULATION_VALUES:
        raise NumericError(
            f"samples = {count} times {states:,} states is {total:,} values; expected at "
            f"most {limits.MAX_SIMULATION_VALUES:,} "
            f"({limits.budget_text('MAX_SIMULATION_VALUES')}): ask for fewer samples"
        )


def check_noise_intensity(largest: float, name: str = "intensity") -> None:
    """Refuse a noise intensity above :data:`limits.MAX_NOISE_INTENSITY` (``largest`` of them)."""
    if largest > limits.MAX_NOISE_INTENSITY:
        raise NumericError(
            f"{name}: intensities must be at most {limits.MAX_NOISE_INTENSITY:g} (variances per "
            f"unit time); found {largest:g} ({limits.budget_text('MAX_NOISE_INTENSITY')})"
        )


def check_periods(
    dt: float,
    t_end: float,
    *,
    stepped: bool = True,
    states: int = 0,
    names: tuple[str, str] = ("`dt`", "`t_end`"),
) -> None:
    """Refuse a sampling period longer than the run, or more periods than a run may step.

    Parameters
    ----------
    dt, t_end : float
        The period and the run's length (both checked finite and positive before).
    stepped : bool
        The run steps the periods (a simulation, a verification); an export without
        verification only needs ``dt <= t_end``.
    states : int
        States stepped one period at a time (a run with an input signal), whose
        periods times states count against :data:`limits.MAX_SIMULATION_VALUES`; 0 when the
        periods are jumped over by powers of the one-period map.
    names : (str, str)
        How ``dt`` and ``t_end`` are called in the message: as code, which the command
        line writes as its options (``--dt``, ``--t-end``).
    """
    dt_name, t_name = names
    if dt > t_end:
        raise NumericError(
            f"{dt_name} = {dt:g} s is longer than {t_name} = {t_end:g} s; expected a sampling "
            f"period at most the run's length (a longer {t_name}, or a shorter {dt_name})"
        )
    periods = t_end / dt
    if stepped and periods > limits.MAX_PERIODS:
        raise NumericError(
            f"{t_name} / {dt_name} = {periods:.3g} sampling periods; expected at most "
            f"{limits.MAX_PERIODS:.0e} ({limits.budget_text('MAX_PERIODS')}): a longer "
            f"{dt_name} or a shorter {t_name}"
        )
    if stepped and states and periods * states > limits.MAX_SIMULATION_VALUES:
        raise NumericError(
            f"{t_name} / {dt_name} = {periods:.3g} periods, each stepped with an input, times "
            f"{states:,} states is {periods * states:.3g} values; expected at most "
            f"{limits.MAX_SIMULATION_VALUES:,} ({limits.budget_text('MAX_SIMULATION_VALUES')}): "
            f"a longer {dt_name} or a shorter {t_name}"
        )
