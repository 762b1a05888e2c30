"""The jobs a sweep can run at each point, and the registry that names them.

A job says which figures it computes at a point (their names are the keys of the
corresponding command's JSON: ``spectral_abscissa``, ``converged``, ``verdict``,
``kappa``, ...), which fixed options it takes, and where its evaluator lives.  The
evaluator is imported only inside the process that runs a chunk, so this module (and the
command line that lists the jobs) stays free of numpy, scipy and sympy.

The evaluator contract: ``prepare(model, sensors, options)`` is called once per chunk
and setting (a model with the setting's parameter values, the sensor set or ``None``,
the job's options) and returns ``evaluate(gain) -> dict``, called once per point with
the diagonal of :math:`L` (a tuple of floats, or ``None`` without sensors); the dict
maps every figure name to its value (``None`` for a missing number).

Adding a job is one entry in :data:`JOBS`, e.g. for noise figures::

    "noise": Job(
        name="noise",
        summary="steady-state error energy under boundary sensor noise",
        figures=(Figure("error_energy", "float64", "E[H̃] [J]"), ...),
        options=(Option("resolution", "int", None, "Galerkin degree"), ...),
        prepare="phdesign.numeric.noise.figures:sweep_evaluator",
        needs_sensors=True,
    ),

Examples
--------
>>> sorted(JOBS)
['classify', 'gain', 'spectrum']
>>> [f.name for f in JOBS["classify"].figures]
['verdict', 'kappa', 'best']
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from phdesign.core.checks import positive_int, positive_number
from phdesign.core.defaults import current
from phdesign.core.errors import SweepError

__all__ = ["JOBS", "Figure", "Job", "Option", "get_job"]

#: What a job's evaluator returns for one point: figure name -> value.
PointFigures = Mapping[str, Any]


@dataclass(frozen=True)
class Figure:
    """One figure a job computes at every point.

    Parameters
    ----------
    name : str
        Its name in the Dataset, the CSV header and the job's JSON.
    dtype : str
        ``"float64"`` (missing: NaN), ``"int32"`` (missing: -1), ``"bool"`` or
        ``"<U{n}"`` (text of at most n characters, missing: empty).
    description : str
        One line for the Dataset's ``long_name`` attribute.
    units : str
        Units, if any.
    """

    name: str
    dtype: str
    description: str
    units: str = ""

    @property
    def fill(self) -> Any:
        """The value stored where a point has no number (or is not computed yet)."""
        if self.dtype.startswith("float"):
            return math.nan
        if self.dtype.startswith("int"):
            return -1
        if self.dtype == "bool":
            return False
        return ""


@dataclass(frozen=True)
class Option:
    """A fixed option of a job (the same at every point of a sweep).

    Parameters
    ----------
    name : str
    kind : {"int", "float", "choice"}
        Positive integer, positive finite float, or one of ``choices``.
    default : object or callable
        ``None`` leaves the choice to the library (its documented default); a function
        without arguments is asked at each use (the table of defaults in force).
    help : str
    choices : tuple of str, or a function without arguments returning them
    """

    name: str
    kind: str
    default: Any
    help: str
    choices: tuple[str, ...] | Callable[[], tuple[str, ...]] = ()

    @property
    def allowed(self) -> tuple[str, ...]:
        """The choices now (those of the table in force, for the discretization method)."""
        return self.choices() if callable(self.choices) else self.choices

    @property
    def default_value(self) -> Any:
        """The default now (``None``: the library's)."""
        return self.default() if callable(self.default) else self.default

    def check(self, value: Any) -> Any:
        """Return ``value`` validated (``None`` stays ``None``).

        Raises
        ------
        SweepError
            A value of the wrong kind, not positive, not finite, or not a choice.
        """
        if value is None:
            return None
        if self.kind == "choice":
            if value not in self.allowed:
                raise SweepError(
                    f"option {self.name}: expected one of {', '.join(self.allowed)}; "
                    f"found {value!r}"
                )
            return value
        if self.kind == "int":
            return positive_int(value, f"option {self.name}", SweepError)
        return positive_number(value, f"option {self.name}", SweepError)


@dataclass(frozen=True)
class Job:
    """A per-point computation of a sweep.

    Parameters
    ----------
    name : str
    summary : str
    figures : tuple of Figure
    options : tuple of Option
    prepare : str
        ``"module:function"`` of the evaluator factory (see the module docstring).
    needs_sensors : bool
        The job answers a question about an observer (it needs a sensor set).
    points_per_chunk : int
        Points per task when gains vary inside a setting (the prepared model and
        discretization serve every point of the chunk): about half a second of work.
    settings_per_chunk : int
        Points per task when every point is a new setting (no gain axis).
    check : str
        ``"module:function"`` of ``check(model, options)``, which refuses options the
        evaluator would refuse at every point (a resolution over budget) before the sweep
        starts; empty: nothing to check.
    """

    name: str
    summary: str
    figures: tuple[Figure, ...]
    options: tuple[Option, ...]
    prepare: str
    needs_sensors: bool
    points_per_chunk: int
    settings_per_chunk: int
    check: str = ""

    def option_values(self, given: Mapping[str, Any] | None) -> dict[str, Any]:
        """Every option of the job, validated, with defaults for those not given.

        Raises
        ------
        SweepError
            An option the job does not have, or a bad value.
        """
        given = dict(given or {})
        known = {o.name: o for o in self.options}
        for name in given:
            if name not in known:
                expected = ", ".join(known) or "none"
                raise SweepError(
                    f"job {self.name} has no option {name!r}; its options: {expected}"
                )
        return {o.name: o.check(given.get(o.name, o.default_value)) for o in self.options}

    def check_options(self, model: Any, options: Mapping[str, Any]) -> None:
        """Refuse, before the sweep, options that every point would refuse (see ``check``)."""
        if self.check:
            _load(self.check)(model, options)

    def evaluator_factory(self) -> Callable[..., Callable[[Any], PointFigures]]:
        """Import and return the evaluator factory ``prepare(model, sensors, options)``."""
        factory: Callable[..., Callable[[Any], PointFigures]] = _load(self.prepare)
        return factory


def _load(target: str) -> Any:
    """Return the function named ``"module:function"`` (imported when needed)."""
    module, _, function = target.partition(":")
    return getattr(importlib.import_module(module), function)


def _default_method() -> str:
    return current().method


def _method_names() -> tuple[str, ...]:
    return current().method_names


# the registered discretizations and the default one, read from the table when used
_METHOD = Option(
    "method", "choice", _default_method, "discretization (default: the table's)", _method_names
)

#: The discretization and its refinement, options of the numeric jobs
_REFINEMENT = (
    _METHOD,
    Option("resolution", "int", None, "first resolution of the refinement pairs"),
    Option("max_resolution", "int", None, "largest resolution"),
)

JOBS: dict[str, Job] = {
    "spectrum": Job(
        name="spectrum",
        summary="converged spectral abscissa of the error system (of the plant without sensors)",
        figures=(
            Figure("spectral_abscissa", "float64", "spectral abscissa α", "1/s"),
            Figure("converged", "bool", "α agrees to tol between two resolutions"),
            Figure("digits", "float64", "agreeing digits of α"),
            Figure("n_resolved", "int32", "eigenvalues resolved at the reported pair"),
            Figure("unbounded_below", "bool", "no eigenvalue converges (finite-time extinction)"),
            Figure("ill_conditioned", "bool", "the rightmost eigenvalue is near a coalescence"),
        ),
        options=(
            *_REFINEMENT,
            Option("tol", "float", None, "required agreement of α (times max(1, |α|))"),
        ),
        prepare="phdesign.sweep.spectrum_job:prepare",
        needs_sensors=False,
        points_per_chunk=32,
        settings_per_chunk=4,
        check="phdesign.sweep.spectrum_job:check_options",
    ),
    "gain": Job(
        name="gain",
        summary="H∞ and H₂ norms from the disturbances to the performance outputs (their "
        "estimation error with sensors)",
        figures=(
            Figure("hinf", "float64", "H∞ norm (L²-gain), NaN unless converged"),
            Figure("hinf_converged", "bool", "the H∞ norm agrees to tol under refinement"),
            Figure("hinf_frequency", "float64", "frequency of the H∞ peak", "rad/s"),
            Figure("h2", "float64", "H₂ norm, NaN unless converged"),
            Figure("h2_converged", "bool", "the H₂ norm agrees to tol under refinement"),
            Figure("h2_diverges", "bool", "the H₂ norm grows with the resolution (infinite)"),
            Figure("steady_state", "bool", "the system is exponentially stable"),
        ),
        options=(
            *_REFINEMENT,
            Option("tol", "float", None, "relative agreement of a converged norm"),
            Option("intensity", "float", None, "sensor noise intensity σ² (default 1)"),
        ),
        prepare="phdesign.sweep.gain_job:prepare",
        needs_sensors=False,
        points_per_chunk=8,
        settings_per_chunk=2,
        check="phdesign.sweep.spectrum_job:check_options",
    ),
    "classify": Job(
        name="classify",
        summary="verdict of Propositions 3.1 to 3.4 and the best certificate κ*",
        figures=(
            Figure("verdict", "<U12", "exponential, asymptotic or inconclusive"),
            Figure("kappa", "float64", "κ* of the best holding variant (NaN: none or unbounded)"),
            Figure("best", "<U8", "the best holding variant, e.g. 3.4.4"),
        ),
        options=(),
        prepare="phdesign.sweep.classify_job:prepare",
        needs_sensors=True,
        points_per_chunk=8,
        settings_per_chunk=4,
    ),
}


def get_job(name: str) -> Job:
    """Return the registered job ``name``.

    Raises
    ------
    SweepError
        No such job.
    """
    try:
        return JOBS[name]
    except KeyError:
        raise SweepError(
            f"unknown sweep job {name!r}; expected one of {', '.join(sorted(JOBS))}"
        ) from None
