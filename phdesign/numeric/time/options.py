r"""How a simulation runs: the one options object of every simulator.

:func:`~phdesign.numeric.time.simulation.simulate` (plant and continuous observer),
:func:`~phdesign.numeric.time.stochastic.simulate_noisy` (with white noise),
:func:`~phdesign.numeric.sampled.simulation.simulate_sampled` (a sampled or lower-order
observer) and :func:`~phdesign.numeric.control.simulation.simulate_loop` (observer-based
control) take the same :class:`SimulationOptions`: the output grid
:math:`t_k = k\, t_\mathrm{end} / (\mathrm{samples} - 1)`, the discretization, the time
stepping, and the options of one kind of run: a sampled observer (``dt``, ``sampler``,
``observer_resolution``) or noise (``noise_intensity``, ``input_intensity``, ``seed``).

Its fields are checked once, when it is made; what needs the model (the number of
intensities, the points ``z_w`` inside the interval, the budgets) is checked by the
simulator.  A simulator refuses the options of a kind of run it does not do, and names the
one that does; :meth:`phdesign.Observer.simulate` picks the simulator from
:attr:`SimulationOptions.kind`, as ``phdesign simulate`` does.

Examples
--------
>>> options = SimulationOptions(t_end=1.0, samples=3, dt=1e-3)
>>> options.kind, options.sampler_name, options.times().tolist()
('sampled', 'average', [0.0, 0.5, 1.0])
>>> SimulationOptions(samples=1)
Traceback (most recent call last):
...
phdesign.core.errors.NumericError: samples must be an integer >= 2; found 1
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from phdesign.core.checks import choice, positive_int, positive_number
from phdesign.core.defaults import current, method_or_default
from phdesign.core.errors import ArgumentError, NumericError
from phdesign.numeric.checks import SAMPLERS, check_sampling
from phdesign.numeric.noise.figures import check_intensity
from phdesign.numeric.time.stepping import SCHEMES

__all__ = ["KINDS", "NOISY_SCHEME", "SAMPLED_SCHEME", "SimulationOptions"]

#: The options that ask for a sampled (or lower-order) observer.
SAMPLING = ("dt", "sampler", "observer_resolution")
#: The options that ask for a noisy run.
NOISE = ("noise_intensity", "input_intensity", "disturbance_intensity", "seed")
#: Why a noisy run refuses another scheme than ``"expm"``.
NOISY_SCHEME = (
    "a noisy simulation steps exactly (Van Loan sampling of the noise); the {scheme!r} "
    "scheme does not apply"
)
#: Why a sampled or lower-order observer refuses another scheme than ``"expm"``.
SAMPLED_SCHEME = (
    "a sampled or lower-order observer is stepped exactly: scheme must be 'expm'; found {scheme!r}"
)
#: Kind of run -> the simulator that does it.
KINDS = {
    "continuous": "simulate",
    "noisy": "simulate_noisy",
    "sampled": "simulate_sampled",
}


@dataclass(frozen=True, init=False)
class SimulationOptions:
    r"""The options of a simulation, checked once (module docstring).

    A field left None takes the default of the table in force when the options are made
    (:mod:`phdesign.core.defaults`: five seconds, 501 samples, the exact exponential, the
    default method), or, for ``tol`` and ``sampler``, when they are read.

    Parameters
    ----------
    t_end : float, optional
        Final time (> 0).
    samples : int, optional
        Output samples on :math:`[0, t_\mathrm{end}]` (>= 2).
    method : str, optional
        A registered discretization
        (:func:`phdesign.numeric.discretization.registry.discretize`).
    resolution : int, optional
        Its degree or nodes per group (default: the method's).
    scheme : {"expm", "midpoint"}, optional
        Exact exponential, or implicit midpoint with substeps chosen so that its estimated
        error is below ``tol`` (:mod:`phdesign.numeric.time.stepping`).  Sampled and noisy
        runs step exactly.
    tol : float, optional
        Midpoint: largest estimated error of the states, relative to their largest energy
        norm (the table's when the run starts; the loop's midpoint takes none).
    z_w : sequence of float, optional
        Points where the displacement is reported (default 21 uniform points).
    check_resolution : bool
        Continuous observer: step the error system again at ⌈1.5 p⌉ to find how far
        H_err is resolved (:mod:`phdesign.numeric.time.simulation`).
    dt : float, optional
        Sampling period of the observer's sensors (a sampled observer).
    sampler : {"average", "point"}, optional
        The sampled observer's front end (needs ``dt``; default the exported observer's,
        ``"average"``).
    observer_resolution : int, optional
        The observer's own Galerkin degree (default: the plant's).
    noise_intensity : float or sequence of float, optional
        Sensor noise intensities :math:`\sigma_i^2` (one per sensor or one for all).
    input_intensity : float or sequence of float, optional
        White noise on the plant inputs (one per input or one for all).
    disturbance_intensity : float or sequence of float, optional
        White noise on the disturbance channels ``w1..wq`` of the model's
        ``[disturbances]`` B (one per channel or one for all), which the observer does not
        know.
    seed : int, optional
        Seed of the noise (needs a noise intensity).
    at : sequence of str or float, optional
        Point outputs reported beside ``w(z)``: a number is the displacement there,
        ``"rotation(1)"`` a named field of the model (read against the model by the
        simulator, :mod:`phdesign.numeric.discretization.points`); every simulator reports
        them (continuous, sampled, noisy and the loop), for the plant and the observer.

    Raises
    ------
    NumericError
        A value out of range, or options of two kinds of run together (sampling and
        noise), or a scheme a sampled or noisy run does not use.
    ArgumentError
        A value of the wrong kind.
    """

    t_end: float
    samples: int
    method: str
    resolution: int | None
    scheme: str
    tol: float | None
    z_w: tuple[float, ...] | None
    check_resolution: bool
    dt: float | None
    sampler: str | None
    observer_resolution: int | None
    noise_intensity: tuple[float, ...] | None
    input_intensity: tuple[float, ...] | None
    disturbance_intensity: tuple[float, ...] | None
    seed: int | None
    at: tuple[str | float, ...] | None

    def __init__(
        self,
        t_end: float | None = None,
        samples: int | None = None,
        method: str | None = None,
        resolution: int | None = None,
        scheme: str | None = None,
        tol: float | None = None,
        z_w: Sequence[float] | None = None,
        check_resolution: bool = True,
        dt: float | None = None,
        sampler: str | None = None,
        observer_resolution: int | None = None,
        noise_intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        seed: int | None = None,
        at: str | float | Sequence[str | float] | None = None,
        disturbance_intensity: float | Sequence[float] | None = None,
    ) -> None:
        table = current()  # None: the table's default, in force when the options are made
        t_end, samples, scheme, _ = table.simulation.fill(t_end, samples, scheme)
        self._set("t_end", positive_number(t_end, "t_end"))
        self._set("samples", positive_int(samples, "samples", minimum=2))
        self._set("method", choice(method_or_default(method), "method", table.method_names))
        for name, value in (
            ("resolution", resolution),
            ("observer_resolution", observer_resolution),
        ):
            self._set(name, None if value is None else positive_int(value, name))
        if not isinstance(scheme, str):
            raise ArgumentError(f"scheme must be a name such as 'expm'; found {scheme!r}")
        if scheme not in SCHEMES:
            raise NumericError(
                f"unknown time-stepping scheme {scheme!r}; expected one of {SCHEMES}"
            )
        self._set("scheme", scheme)
        self._set("tol", None if tol is None else positive_number(tol, "tol"))
        self._set("z_w", None if z_w is None else _points(z_w))
        if not isinstance(check_resolution, bool):
            raise ArgumentError(
                f"check_resolution must be True or False; found {check_resolution!r}"
            )
        self._set("check_resolution", check_resolution)
        self._check_sampling(dt, sampler, observer_resolution)
        self._check_noise(noise_intensity, input_intensity, disturbance_intensity, seed)
        self._set("at", None if at is None else _point_items(at))

    def _set(self, name: str, value: Any) -> None:
        object.__setattr__(self, name, value)  # frozen: the checked value replaces the given

    def _check_sampling(self, dt: Any, sampler: Any, observer_resolution: Any) -> None:
        if sampler is not None:
            choice(sampler, "sampler", SAMPLERS)
            if dt is None:
                raise NumericError("sampler needs dt, the sampling period")
        self._set("sampler", sampler)
        self._set("dt", None if dt is None else check_sampling(dt, self.sampler_name))
        sampled = dt is not None or sampler is not None or observer_resolution is not None
        if sampled and self.scheme != "expm":
            raise NumericError(SAMPLED_SCHEME.format(scheme=self.scheme))

    def _check_noise(
        self, noise_intensity: Any, input_intensity: Any, disturbance_intensity: Any, seed: Any
    ) -> None:
        intensities = (
            ("noise_intensity", noise_intensity),
            ("input_intensity", input_intensity),
            ("disturbance_intensity", disturbance_intensity),
        )
        for name, value in intensities:
            # their number is checked against the model's channels, by the simulator
            count = (np.size(value) if np.ndim(value) else 1) if value is not None else 0
            checked = (
                None if value is None else tuple(check_intensity(value, count, name).tolist())
            )
            self._set(name, checked)
        noisy = any(value is not None for _, value in intensities)
        if seed is not None:
            seed = positive_int(seed, "seed", minimum=0)  # not numpy's traceback
            if not noisy:
                raise NumericError(
                    "seed needs noise_intensity or input_intensity (or disturbance_intensity)"
                )
        self._set("seed", seed)
        if not noisy:
            return
        sampled = [name for name in SAMPLING if getattr(self, name) is not None]
        if sampled:
            raise NumericError(
                f"the noise options run the continuous observer; {sampled[0]} asks for a "
                "sampled one: give one or the other"
            )
        if self.scheme != "expm":
            raise NumericError(NOISY_SCHEME.format(scheme=self.scheme))

    @property
    def kind(self) -> str:
        """``"sampled"``, ``"noisy"`` or ``"continuous"``: the run these options ask for."""
        if any(getattr(self, name) is not None for name in SAMPLING):
            return "sampled"
        if any(getattr(self, name) is not None for name in NOISE):
            return "noisy"
        return "continuous"

    @property
    def sampler_name(self) -> str:
        """The sampler, its default (``"average"``) when none is given."""
        return current().export.sampler if self.sampler is None else self.sampler

    @property
    def midpoint_tol(self) -> float:
        """The midpoint tolerance in force (``tol``, or its default)."""
        return current().simulation.tol if self.tol is None else self.tol

    def times(self) -> np.ndarray:
        """Return the output grid: ``samples`` equal steps on ``[0, t_end]``."""
        return np.linspace(0.0, float(self.t_end), int(self.samples))

    def displacement_points(self, interval: tuple[float, float]) -> np.ndarray:
        """``z_w``, or 21 uniform points of ``interval``."""
        a, b = interval
        return np.linspace(a, b, 21) if self.z_w is None else np.asarray(self.z_w, dtype=float)

    def require(self, simulator: str, *kinds: str) -> None:
        """Refuse options of a kind of run that ``simulator`` does not do.

        Raises
        ------
        ArgumentError
            Naming the options and the simulator that runs them.
        """
        if self.kind in kinds:
            return
        names = SAMPLING if self.kind == "sampled" else NOISE
        given = ", ".join(name for name in names if getattr(self, name) is not None)
        raise ArgumentError(
            f"{simulator} does not run a {self.kind} simulation ({given} given): "
            f"{KINDS[self.kind]} does, and Observer.simulate picks it from the options"
        )

    def deterministic(self) -> SimulationOptions:
        """Return the same options without the noise (the noise-free part of a noisy run)."""
        return replace(
            self,
            noise_intensity=None,
            input_intensity=None,
            disturbance_intensity=None,
            seed=None,
        )

    def discretized(
        self, method: str | None, resolution: int | None, owner: str = "Plant"
    ) -> SimulationOptions:
        """Return these options on the discretization of ``owner`` (a Plant, a Loop).

        Raises
        ------
        ArgumentError
            When the options name another method or resolution: the discretization
            belongs to the owner, which the design's other questions share.
        """
        default = SimulationOptions()
        method = method_or_default(method)
        for name, value in (("method", method), ("resolution", resolution)):
            given = getattr(self, name)
            if given != getattr(default, name) and given != value:
                raise ArgumentError(
                    f"{name} belongs to the {owner} ({owner}(..., {name}={value!r})); found "
                    f"{name}={given!r} in the simulation options"
                )
        return replace(self, method=method, resolution=resolution)

    @classmethod
    def merged(cls, options: SimulationOptions | None = None, **changes: Any) -> SimulationOptions:
        """Return ``options`` (default: the defaults) with ``changes``, checked by name.

        Raises
        ------
        ArgumentError
            ``options`` is not a :class:`SimulationOptions`, or a name is not one of its
            fields (a typo is refused, never ignored).

        Examples
        --------
        >>> SimulationOptions.merged(t_end=2.0).t_end
        2.0
        >>> SimulationOptions.merged(tend=2.0)
        Traceback (most recent call last):
        ...
        phdesign.core.errors.ArgumentError: tend is not a simulation option; expected one of
        t_end, samples, method, ...
        """
        if options is not None and not isinstance(options, cls):
            raise ArgumentError(
                f"options must be SimulationOptions; found {type(options).__name__}"
            )
        names = [f.name for f in fields(cls)]
        unknown = [name for name in changes if name not in names]
        if unknown:
            raise ArgumentError(
                f"{unknown[0]} is not a simulation option; expected one of {', '.join(names)}"
            )
        base = cls() if options is None else options
        return replace(base, **changes) if changes else base


def _points(z_w: Any) -> tuple[float, ...]:
    """Return ``z_w`` as a tuple of finite floats, refusing anything else."""
    try:
        points = np.asarray(z_w, dtype=float)
    except (TypeError, ValueError):
        points = np.array([np.nan])
    if points.ndim != 1 or not points.size or not np.all(np.isfinite(points)):
        raise NumericError(f"z_w must be a non-empty list of finite points; found {z_w!r}")
    return tuple(points.tolist())


def _point_items(at: Any) -> tuple[str | float, ...]:
    """Return ``at`` as a non-empty tuple of texts and numbers (read by the simulator)."""
    items = [at] if isinstance(at, (str, int, float)) else at
    try:
        out = tuple(items)
    except TypeError:
        out = ()
    if not out or not all(
        isinstance(x, (str, int, float)) and not isinstance(x, bool) for x in out
    ):
        raise ArgumentError(
            "at must be a point, a field at a point such as 'rotation(1)', or a non-empty "
            f"list of them; found {at!r}"
        )
    return out
