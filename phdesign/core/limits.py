r"""The budgets that bound what any input may cost, each checked before the work it bounds.

A short input must never buy unbounded time or memory: ``(z+1)**64`` in a matrix entry,
``--gain 'exp(1e300)'``, ``--resolution 20000`` or ``show /dev/zero``. Every budget is a
constant of this module (documented here, and only here) and is checked *before* the work;
an exact symbolic check that would exceed its budget falls back to the documented numeric
check and says so (in ``BCPHS.checks``, or the certificate's ``path``), while every other
request over budget is refused with an error that names the argument, the value found and
the budget.

Text and exact numbers (parser, :mod:`phdesign.symbolic.parser`)
    ========================  ========  ==================================================
    ``MAX_EXPRESSION_LENGTH``  10 000    characters of one expression
    ``MAX_DEPTH``              100       nesting depth of one expression
    ``MAX_EXPONENT``           64        magnitude of a numeric exponent, as written
    ``MAX_DEGREE``             64        degree in ``z`` or a parameter once the expression
                                         is built (``z*z*…*z`` counts as ``z**k``), and
                                         any exponent sympy forms by combining powers
    ``MAX_NUMBER_BITS``        1000      bits of the numerator or denominator of an exact
                                         rational (about 1e±300)
    ``MAX_NUMBER_DIGITS``      310       digits of a number as written
    ``MAX_MAGNITUDE``          1e300     magnitude of a constant (``exp(800)`` is refused;
                                         the argument of ``exp``, ``sinh``, ``cosh`` at
                                         most ln 2e300 ≈ 691.5)
    ``MAX_NUMBER_OPERATIONS``  1000      operations in a number given as a sympy
                                         expression (it is evaluated to check its range)
    ========================  ========  ==================================================

Models (:mod:`phdesign.symbolic.model`, :mod:`phdesign.io`)
    ========================  ========  ==================================================
    ``MAX_MODEL_FILE_BYTES``   1 MiB     size of a model file (read in bounded pieces)
    ``MAX_PARAMETERS``         200       parameters of one model
    ``MAX_ORDER``              8         the order N
    ``MAX_SIZE``               16        the size n
    ``MAX_PORTS``              64        N n, the number of inputs (ports layer: exact
                                         linear algebra on 2 N n traces)
    ========================  ========  ==================================================

Exact decisions that fall back to a numeric check (and say so)
    ==============================  =====  ================================================
    ``EXACT_DEFINITENESS_SIZE``      8      largest matrix whose z-dependent definiteness
                                            is decided exactly (minors and real roots)
    ``EXACT_DEFINITENESS_DEGREE``    128    largest degree in z of an entry's numerator or
                                            denominator, and of a minor (estimated first)
    ``EXACT_DEFINITENESS_BITS``      4096   largest estimated coefficient size of a minor
    ``EXACT_KAPPA_OPERATIONS``       400    operations in the pencil of the exact κ*
                                            (larger pencils use the float path)
    ``EXACT_KAPPA_BITS``             256    bits of the integer coefficients of the pencil's
                                            characteristic polynomial (degree 2 and more)
                                            whose roots are isolated exactly: sympy factors
                                            integers of that size there (598 bits took 55 s,
                                            ``--gain 1e-45,1e45`` on the beam); beyond, the
                                            float path, which scales the pencil
    ``EXACT_KAPPA_DEGREE``           64     degree of those coefficients in a constant
                                            (``exp(100)`` is ``E**100``: 30 s; ``exp(690)``
                                            ran past 600 s)
    ==============================  =====  ================================================

Searches and numerics (checked at the entry of each library function; the checks of a
simulation's span and size, of its sampling periods and of noise intensities are
:mod:`phdesign.numeric.checks`'s, the other checks this module's)
    =========================  ===========  ===============================================
    ``MAX_SENSOR_OUTPUTS``      16           outputs of a model whose every sensor subset
                                             is classified (2^16 - 1 = 65 535 subsets)
    ``MAX_DISCRETE_STATES``     2000         states of one discretization, size n times
                                             (resolution + 1); a dense eigenproblem with
                                             vectors at 2000 states takes minutes, and an
                                             export's verification plant of 2000 states
                                             (``--plant-resolution 999`` on the beam)
                                             about 45 s and 1.6 GB
    ``MAX_NOISE_STATES``        1000         states of the largest discretization of the
                                             noise figures (dense Lyapunov equations: 13 s
                                             and 0.5 GB at 1000 states on the beam, 67 s
                                             and 1.3 GB at 2000)
    ``MAX_SIMULATION_VALUES``   20 000 000   samples times states of a simulation (plant
                                             and observer), 160 MB per copy
    ``MAX_T_END``               1e12         final time of a simulation
    ``MIN_TIME_STEP``           1e-300       t_end / (samples - 1): time stamps stay
                                             distinct normal floats
    ``MAX_PERIODS``             1e9          sampling periods t_end / dt of one sampled
                                             run (the period of a run is also at most its
                                             length t_end); a run with an input signal
                                             steps every period, so periods times states
                                             count against ``MAX_SIMULATION_VALUES``
    ``MAX_NOISE_INTENSITY``     1e100        a noise intensity (variance per unit time):
                                             the noise figures and paths scale with it
                                             in double precision; at 1e300 the
                                             covariances of a fine discretization leave
                                             the range of doubles
    ``MAX_STARTS``              100          starts of the gain tuning
    ``MAX_TUNE_ITERATIONS``     10 000       optimizer iterations per start
    ``MAX_TRADEOFF_GAINS``      1000         gains of a trade-off (scales of a ray, or the
                                             product of a grid's counts); each costs a
                                             spectrum and the noise figures (about 0.1 s on
                                             the beam: 1000 gains take minutes), checked
                                             before the gains are built
    =========================  ===========  ===============================================

Sweeps (:mod:`phdesign.sweep`, checked before any store is created or worker started)
    ============================  ===========  ============================================
    ``MAX_SWEEP_POINTS``          1 000 000    points of a sweep (the product of its axes;
                                               each axis, and the sensor sets ``all``, are
                                               checked before their values are built): a
                                               10⁶-point beam map is 3 h on one core
                                               (``docs/scaling.md``)
    ``MAX_STORE_METADATA_BYTES``  64 MiB       a metadata file of a stored sweep (its
                                               description holds every axis value: 10⁶
                                               values take about 25 MB), read in one
                                               bounded piece before it is parsed
    ``MAX_WORKERS_PER_CORE``      1            workers of a local cluster per core this
                                               process may use: each is a process of about
                                               150 MB, and the jobs are CPU-bound (more
                                               workers than cores cost memory, not time)
    ============================  ===========  ============================================

Work built once (:mod:`phdesign.core.cache`: least recently used entries go first)
    ===========================  ========  ============================================
    ``MAX_CACHED_MODEL_WORK``    64        entries of the work kept per model and
                                           resolution: dimensionless forms,
                                           discretizations, their eigen stages
    ``MAX_CACHED_STRUCTURES``    256       structures of the spectrum above the band
                                           (one per model and gain, and each model's
                                           form)
    ``MAX_CACHED_ROWS``          256       rows of performance outputs (one per
                                           discretization and output: the noise
                                           figures read them at every call)
    ``MAX_CACHE_BYTES``          128 MiB   bytes of arrays each of those caches holds
                                           (a discretization of 900 states is about
                                           35 MB, one of 60 states 0.2 MB)
    ===========================  ========  ============================================

Examples
--------
>>> check_sensor_outputs(4)
>>> check_sensor_outputs(30)
Traceback (most recent call last):
...
phdesign.core.errors.ObserverError: the sensor search classifies 2^30 - 1 = 1073741823 sensor sets
...
"""

from __future__ import annotations

import math
import operator
from typing import Any

from phdesign.core.defaults import current
from phdesign.core.errors import (
    ModelError,
    ModelFileError,
    NumericError,
    ObserverError,
    SweepError,
)

__all__ = [
    "EXACT_DEFINITENESS_BITS",
    "EXACT_DEFINITENESS_DEGREE",
    "EXACT_DEFINITENESS_SIZE",
    "EXACT_KAPPA_BITS",
    "EXACT_KAPPA_DEGREE",
    "EXACT_KAPPA_OPERATIONS",
    "MAX_CACHED_MODEL_WORK",
    "MAX_CACHED_ROWS",
    "MAX_CACHED_STRUCTURES",
    "MAX_CACHE_BYTES",
    "MAX_DEGREE",
    "MAX_DEPTH",
    "MAX_DISCRETE_STATES",
    "MAX_EXPONENT",
    "MAX_EXPRESSION_LENGTH",
    "MAX_MAGNITUDE",
    "MAX_MODEL_FILE_BYTES",
    "MAX_NOISE_INTENSITY",
    "MAX_NOISE_STATES",
    "MAX_NUMBER_BITS",
    "MAX_NUMBER_DIGITS",
    "MAX_NUMBER_OPERATIONS",
    "MAX_ORDER",
    "MAX_PARAMETERS",
    "MAX_PERIODS",
    "MAX_PORTS",
    "MAX_SENSOR_OUTPUTS",
    "MAX_SIMULATION_VALUES",
    "MAX_SIZE",
    "MAX_STARTS",
    "MAX_STORE_METADATA_BYTES",
    "MAX_SWEEP_POINTS",
    "MAX_TRADEOFF_GAINS",
    "MAX_TUNE_ITERATIONS",
    "MAX_T_END",
    "MAX_WORKERS_PER_CORE",
    "MIN_TIME_STEP",
    "budget_text",
    "check_discretization",
    "check_local_workers",
    "check_model_dimensions",
    "check_noise_resolution",
    "check_parameter_count",
    "check_sensor_outputs",
    "check_sweep_points",
    "check_tradeoff_gains",
    "check_tuning",
    "integer",
    "resolution_or_default",
    "state_count",
]

# ---------------------------------------------------------------- text and exact numbers
MAX_EXPRESSION_LENGTH = 10_000
MAX_DEPTH = 100
MAX_EXPONENT = 64
MAX_DEGREE = 64
MAX_NUMBER_BITS = 1000
MAX_NUMBER_DIGITS = 310
MAX_MAGNITUDE = 1e300
MAX_NUMBER_OPERATIONS = 1000
# ---------------------------------------------------------------- models
MAX_MODEL_FILE_BYTES = 1 << 20
MAX_PARAMETERS = 200
MAX_ORDER = 8
MAX_SIZE = 16
MAX_PORTS = 64
# ---------------------------------------------------------------- exact decisions
EXACT_DEFINITENESS_SIZE = 8
EXACT_DEFINITENESS_DEGREE = 128
EXACT_DEFINITENESS_BITS = 4096
EXACT_KAPPA_OPERATIONS = 400
EXACT_KAPPA_BITS = 256
EXACT_KAPPA_DEGREE = 64
# ---------------------------------------------------------------- searches and numerics
MAX_SENSOR_OUTPUTS = 16
MAX_DISCRETE_STATES = 2000
MAX_NOISE_STATES = 1000
MAX_SIMULATION_VALUES = 20_000_000
MAX_T_END = 1e12
MIN_TIME_STEP = 1e-300
MAX_PERIODS = 1e9
MAX_NOISE_INTENSITY = 1e100
MAX_STARTS = 100
MAX_TUNE_ITERATIONS = 10_000
MAX_TRADEOFF_GAINS = 1000
# ---------------------------------------------------------------- sweeps
MAX_SWEEP_POINTS = 1_000_000
MAX_STORE_METADATA_BYTES = 64 << 20
MAX_WORKERS_PER_CORE = 1
# ---------------------------------------------------------------- work built once
MAX_CACHED_MODEL_WORK = 64
MAX_CACHED_STRUCTURES = 256
MAX_CACHED_ROWS = 256
MAX_CACHE_BYTES = 128 << 20


def budget_text(name: str) -> str:
    """Return how a message names the budget ``name``."""
    return f"the budget phdesign.core.limits.{name}"


def integer(value: object, what: str, error: type[Exception]) -> int:
    """``value`` as an int, refusing booleans, fractions and other types by name."""
    if isinstance(value, bool):
        raise error(f"{what} must be an integer; found the boolean {value}")
    try:
        return operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        raise error(f"{what} must be an integer; found {type(value).__name__} {value!r}") from None


def check_parameter_count(count: int) -> None:
    """Refuse models with more than :data:`MAX_PARAMETERS` parameters."""
    if count > MAX_PARAMETERS:
        raise ModelError(
            f"the model has {count} parameters; expected at most {MAX_PARAMETERS} "
            f"({budget_text('MAX_PARAMETERS')})"
        )


def check_model_dimensions(order: int, size: int) -> None:
    """Refuse an order, size or number of ports N n beyond the model budgets."""
    for what, value, name in (("order N", order, "MAX_ORDER"), ("size n", size, "MAX_SIZE")):
        if value > globals()[name]:
            raise ModelError(
                f"the model's {what} is {value}; expected at most {globals()[name]} "
                f"({budget_text(name)})"
            )
    if order * size > MAX_PORTS:
        raise ModelError(
            f"the model has N n = {order * size} inputs; expected at most {MAX_PORTS} "
            f"({budget_text('MAX_PORTS')})"
        )


def check_file_size(size: int, source: str) -> None:
    """Refuse a model file larger than :data:`MAX_MODEL_FILE_BYTES`."""
    if size > MAX_MODEL_FILE_BYTES:
        raise ModelFileError(
            f"{source} is larger than {MAX_MODEL_FILE_BYTES:,} bytes; expected a model file "
            f"({budget_text('MAX_MODEL_FILE_BYTES')})"
        )


def check_sensor_outputs(n_outputs: int) -> None:
    """Refuse a sensor search over more than :data:`MAX_SENSOR_OUTPUTS` outputs."""
    n_outputs = integer(n_outputs, "the number of outputs", ObserverError)
    if n_outputs > MAX_SENSOR_OUTPUTS:
        count = f" = {2**n_outputs - 1}" if n_outputs <= 64 else ""
        raise ObserverError(
            f"the sensor search classifies 2^{n_outputs} - 1{count} sensor sets "
            f"for {n_outputs} outputs; expected at most {MAX_SENSOR_OUTPUTS} outputs "
            f"({budget_text('MAX_SENSOR_OUTPUTS')}): classify chosen sets with sensors=... instead"
        )


def state_count(nm: Any, resolution: int) -> int:
    """Return the states of a discretization of ``nm`` at ``resolution``: n (p + 1)."""
    return int(nm.size) * (resolution + 1)


def resolution_or_default(nm: Any, method: object, resolution: object) -> int:
    """``resolution``, or the registered default of ``method`` for the model's order."""
    if resolution is not None:
        return integer(resolution, "resolution", NumericError)
    table = current()
    name = method if isinstance(method, str) and method in table.methods else table.method
    return table.discretization(name, int(nm.order)).resolution


def check_discretization(nm: Any, method: object, *resolutions: object) -> None:
    """Refuse resolutions whose discretization would exceed :data:`MAX_DISCRETE_STATES`.

    Parameters
    ----------
    nm : NumericModel
        The model (its size ``n``).
    method : str
        The discretization method (for the message).
    *resolutions : int or None
        The resolutions requested (``None``: the method's default, within budget).
    """
    for resolution in resolutions:
        if resolution is None:
            continue
        value = integer(resolution, "resolution", NumericError)
        if value < 1:
            raise NumericError(f"resolution must be a positive integer; found {value}")
        states = state_count(nm, value)
        if states > MAX_DISCRETE_STATES:
            raise NumericError(
                f"resolution {value} gives the {method} discretization of a size-{nm.size} "
                f"model about {states:,} states; expected at most {MAX_DISCRETE_STATES:,} "
                f"({budget_text('MAX_DISCRETE_STATES')}; at 2,000 states an eigenproblem takes "
                "minutes, an export's verification plant 45 s and 1.6 GB)"
            )


def check_noise_resolution(nm: Any, resolution: int, name: str) -> None:
    """Refuse noise figures whose largest discretization exceeds :data:`MAX_NOISE_STATES`.

    ``resolution`` is the largest resolution the refinement may reach, ``name`` the
    argument that sets it (``"resolution"`` or ``"max_resolution"``).
    """
    states = state_count(nm, resolution)
    if states > MAX_NOISE_STATES:
        raise NumericError(
            f"{name} {resolution} gives the noise figures of a size-{nm.size} model about "
            f"{states:,} states; expected at most {MAX_NOISE_STATES:,} "
            f"({budget_text('MAX_NOISE_STATES')}: dense Lyapunov equations, 13 s and 0.5 GB at "
            "1,000 states on the beam, 67 s and 1.3 GB at 2,000)"
        )


def check_tuning(
    nm: Any, starts: object, seed: object, maxiter: object, resolution: object
) -> None:
    """Refuse a tuning run beyond :data:`MAX_STARTS` or :data:`MAX_TUNE_ITERATIONS`.

    The resolution pair (``resolution`` and 1.5 times it) is checked by
    :func:`check_discretization`.
    """
    for what, value, name in (
        ("starts", starts, "MAX_STARTS"),
        ("maxiter", maxiter, "MAX_TUNE_ITERATIONS"),
    ):
        number = integer(value, what, NumericError)
        if not 1 <= number <= globals()[name]:
            raise NumericError(
                f"{what} must be an integer from 1 to {globals()[name]:,}; found {number} "
                f"({budget_text(name)})"
            )
    if integer(seed, "seed", NumericError) < 0:
        raise NumericError(f"seed must be a non-negative integer; found {seed}")
    if resolution is not None:
        fine = math.ceil(1.5 * integer(resolution, "resolution", NumericError))
        check_discretization(nm, current().method, resolution, fine)


def check_tradeoff_gains(count: int, what: str) -> None:
    """Refuse a trade-off of more than :data:`MAX_TRADEOFF_GAINS` gains (before building them).

    ``what`` names the argument for the message (``"scales"``, ``"grid"``).
    """
    if count > MAX_TRADEOFF_GAINS:
        raise NumericError(
            f"{what} gives {count:,} gains; a trade-off evaluates at most "
            f"{MAX_TRADEOFF_GAINS:,} (a spectrum and the noise figures at each, about 0.1 s "
            f"apiece on the beam; {budget_text('MAX_TRADEOFF_GAINS')})"
        )


def check_sweep_points(count: int, what: str) -> None:
    """Refuse a sweep, or one of its axes, of more than :data:`MAX_SWEEP_POINTS` points."""
    if count > MAX_SWEEP_POINTS:
        raise SweepError(
            f"{what} has {count:,} points; a sweep has at most {MAX_SWEEP_POINTS:,} "
            f"({budget_text('MAX_SWEEP_POINTS')}): split the study into several sweeps"
        )


def check_local_workers(workers: int, cores: int) -> None:
    """Refuse more local workers than :data:`MAX_WORKERS_PER_CORE` per usable core."""
    cap = max(1, MAX_WORKERS_PER_CORE * cores)
    if workers > cap:
        raise SweepError(
            f"workers: a local cluster has at most {cap} workers on this machine "
            f"({MAX_WORKERS_PER_CORE} per core it may use, {budget_text('MAX_WORKERS_PER_CORE')}: "
            f"each worker is a process of about 150 MB); found {workers}"
        )
