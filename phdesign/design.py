r"""The design objects: a plant and its boundary observer, in plain Python.

A notebook user describes a design once and asks it questions::

    import phdesign as phd
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    obs.classify()            # which proposition holds, with κ*
    obs.spectrum()            # how fast: converged spectral abscissa of the error system
    obs.simulate(x0="x1: 0, x2: z - 0.9", t_end=5)
    obs.tune()                # a new Observer with the tuned gain (its report in .tuning)
    obs.statespace("error")   # control.StateSpace

:class:`Observer` holds the exact :math:`C_m` and :math:`L` (sympy; positive symbols for
``gain="symbolic"``), checked once, here, by the validation every command of the command
line goes through as well (:func:`~phdesign.symbolic.observer.measurement_matrix`,
:func:`~phdesign.symbolic.observer.gain_matrix`).  The numeric plumbing is a separate,
reusable piece, :class:`Plant`: the model with its parameter overrides and discretization
options, and the numeric model it caches (the bridge runs once per plant).  Designs built
on a plant (the observer here, an observer-based loop) share it.

The observer implemented is the paper's:

.. math::

    \hat u = u + C_m^\top L\, (y_m - \hat y_m), \qquad
    \tilde u = -C_m^\top L C_m \tilde y \quad (\tilde x = x - \hat x).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import sympy

from phdesign._display import REPR_LIMIT, html_table, matrix_text, sensors_text, shorten
from phdesign.arguments import choice, positive_int, require_model
from phdesign.errors import ArgumentError, ObserverError, ParameterError
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, measurement_matrix, sensor_matrix

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np

    from phdesign.numeric.bridge import NumericModel
    from phdesign.numeric.phs import DiscretePHS
    from phdesign.numeric.simulate import SimulationResult
    from phdesign.numeric.spectrum import SpectrumReport
    from phdesign.numeric.tune import TuneResult
    from phdesign.symbolic.classify import Classification

__all__ = ["STATESPACE_SYSTEMS", "Observer", "Plant", "numeric_matrix"]

#: The systems :meth:`Observer.statespace` exports.
STATESPACE_SYSTEMS = ("plant", "observer", "error")


def numeric_matrix(M: sympy.MatrixBase, name: str, what: str) -> np.ndarray:
    """Return an exact numeric matrix as floats; refuse symbols, saying what to do.

    Parameters
    ----------
    M : sympy matrix
        :math:`C_m` or :math:`L`.
    name : str
        Its name in messages.
    what : str
        The numeric computation that needs it (``"spectrum"``, ``"simulate"``).
    """
    import numpy as np

    if M.free_symbols:
        names = ", ".join(sorted(map(str, M.free_symbols)))
        raise ObserverError(
            f"{what} needs numbers for {name}; {name} = {matrix_text(M)} is symbolic ({names}): "
            "give numbers (the gain [0.1, 1], or --gain 0.1,1 on the command line) or tune "
            "one; symbolic gains are for classify, which answers for all their positive values"
        )
    return np.array(M.evalf(17).tolist(), dtype=float)


@dataclass(frozen=True, repr=False)
class Plant:
    """A model with its parameter overrides and discretization: the numeric plumbing.

    Parameters
    ----------
    model : BCPHS
        The symbolic model (:func:`phdesign.load`).
    parameters : mapping of str to number, optional
        Overrides of the model's parameter defaults (``{"d": 0.5}``), used by the
        classification and by the numbers alike.
    method : {"galerkin", "fd"}
        Discretization (:func:`phdesign.numeric.discretize.discretize`).
    resolution : int, optional
        Degree or nodes per group; for spectra, the first resolution of the refinement.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> plant = Plant(load_builtin("euler-bernoulli"), parameters={"d": 0.5})
    >>> plant.numeric.parameters["d"]
    0.5
    >>> round(plant.spectrum().spectral_abscissa, 10)  # every mode has Re λ = -d/2
    -0.25
    """

    model: BCPHS
    parameters: Mapping[str, Any] = field(default_factory=dict, hash=False)
    method: str = "galerkin"
    resolution: int | None = None

    def __post_init__(self) -> None:
        require_model(self.model)
        if not isinstance(self.parameters, Mapping):
            raise ParameterError(
                "parameters must be a mapping of names to values such as {'d': 0.5}; found "
                f"{type(self.parameters).__name__}"
            )
        from phdesign.numeric.discretize import METHODS

        choice(self.method, "method", METHODS)
        if self.resolution is not None:
            positive_int(self.resolution, "resolution")
        object.__setattr__(self, "parameters", dict(self.parameters))
        self.design_model  # noqa: B018 - checks the overrides now, not at first use

    @cached_property
    def design_model(self) -> BCPHS:
        """The model with the parameter overrides as its defaults."""
        return self.model.with_parameters(self.parameters) if self.parameters else self.model

    @cached_property
    def numeric(self) -> NumericModel:
        """The numeric model (parameters substituted), made once."""
        from phdesign.numeric.bridge import to_numeric

        return to_numeric(self.model, self.parameters or None)

    def discrete(self, resolution: int | None = None) -> DiscretePHS:
        """Return the discretized plant at ``resolution`` (default: the plant's)."""
        from phdesign.numeric.discretize import discretize

        return discretize(self.numeric, self.method, resolution or self.resolution)

    def initial_state(self, x0: str | Callable[[Any], Any] | None, name: str) -> Any:
        """Return an initial state as a function of z (text ``"x1: z - 0.9"`` is parsed)."""
        if x0 is None or callable(x0):
            return x0
        if not isinstance(x0, str):
            raise ArgumentError(
                f"{name} must be text such as 'x1: 0, x2: z - 0.9' or a function of z; "
                f"found {type(x0).__name__}"
            )
        from phdesign.numeric.bridge import initial_state_function

        return initial_state_function(x0, self.numeric)

    def spectrum(
        self, *, max_resolution: int | None = None, tol: float | None = None, count: int = 6
    ) -> SpectrumReport:
        """Return the converged spectrum of the plant with u = 0."""
        return self.closed_spectrum(
            None, None, max_resolution=max_resolution, tol=tol, count=count
        )

    def closed_spectrum(
        self,
        C_m: np.ndarray | None,
        L: np.ndarray | None,
        *,
        max_resolution: int | None = None,
        tol: float | None = None,
        count: int = 6,
    ) -> SpectrumReport:
        r"""Return the converged spectrum with :math:`u = -C_m^\top L C_m y` (u = 0 without)."""
        from phdesign.numeric.spectrum import spectrum

        return spectrum(
            self.numeric,
            C_m,
            L,
            method=self.method,
            resolution=self.resolution,
            max_resolution=max_resolution,
            tol=tol,
            count=count,
        )

    def simulate(
        self,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        t_end: float = 5.0,
        samples: int = 501,
        u: Callable[[float], Any] | None = None,
        scheme: str = "expm",
        tol: float = 1e-6,
    ) -> SimulationResult:
        """Simulate the plant alone from ``x0`` (text or a function of z; zero by default).

        ``tol`` bounds the error of ``scheme="midpoint"`` (its substeps are chosen to meet
        it; :func:`phdesign.numeric.simulate.simulate`).
        """
        return self.run(None, None, x0, t_end=t_end, samples=samples, u=u, scheme=scheme, tol=tol)

    def run(
        self,
        C_m: np.ndarray | None,
        L: np.ndarray | None,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        xhat0: str | Callable[[Any], Any] | None = None,
        labels: Mapping[str, str] | None = None,
        **options: Any,
    ) -> SimulationResult:
        """Simulate the plant, with the observer of ``(C_m, L)`` when given.

        ``options`` are those of :func:`phdesign.numeric.simulate.simulate` (``t_end``,
        ``samples``, ``u``, ``scheme``, ``z_w``), checked there; ``labels`` name the design
        in the result (presentation only: the plots' titles and the JSON).
        """
        from phdesign.numeric.simulate import simulate

        result = simulate(
            self.numeric,
            C_m,
            L,
            x0=self.initial_state(x0, "x0"),
            xhat0=self.initial_state(xhat0, "xhat0"),
            method=self.method,
            resolution=self.resolution,
            **options,
        )
        return self.labelled(result, **(labels or {}))

    def labelled(self, result: SimulationResult, **labels: str) -> SimulationResult:
        """Return the result with the model's name (and the design's ``labels``) in its ``info``.

        Presentation only: the plots' titles and the JSON name what was simulated.
        """
        return replace(result, info={**result.info, "model": self.model.name, **labels})

    def __repr__(self) -> str:
        extra = f", parameters={self.parameters}" if self.parameters else ""
        text = f"Plant(model={self.model.name!r}{extra}, method={self.method!r})"
        return shorten(text, REPR_LIMIT)


@dataclass(frozen=True, init=False, repr=False)
class Observer:
    r"""A boundary observer for a model: sensors :math:`C_m` and gain :math:`L`.

    Parameters
    ----------
    model : BCPHS or Plant
        The plant (:func:`phdesign.load`), or a :class:`Plant` with its parameter
        overrides and discretization (shared by several designs).
    sensors : int or sequence of int, optional
        The measured outputs, 1-based: ``[3, 4]`` measures :math:`y_3, y_4` (unit rows).
    C_m : matrix, optional
        The sensor matrix in full instead (``q x Nn``, full row rank): nested lists, a
        numpy array or a sympy matrix.
    gain : number, sequence, matrix or "symbolic", optional
        :math:`L`: one number for every sensor, one per sensor (the diagonal), the
        ``q x q`` matrix (:math:`L + L^\top \succ 0`), or ``"symbolic"`` for
        :math:`\mathrm{diag}(l_1, \dots, l_q)` with positive symbols (classification
        only).  Without a gain the observer can only be tuned (:meth:`tune`).
    parameters : mapping, optional
        Parameter overrides (``{"d": 0.5}``).
    method, resolution : optional
        Discretization of the numeric methods (see :class:`Plant`).

    Attributes
    ----------
    plant : Plant
        The model, its overrides and discretization, and the cached numeric model.
    C_m : sympy.ImmutableMatrix
        Exact sensors.
    L : sympy.ImmutableMatrix or None
        Exact gain (``None`` before tuning).
    tuning : TuneResult or None
        For an observer returned by :meth:`tune`, the tuning report.

    Raises
    ------
    ObserverError
        Sensors or gain malformed (the message names ``sensors``, ``C_m`` or ``gain``).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> obs = Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    >>> obs
    Observer(model='euler-bernoulli', sensors='y3, y4', L='diag(0.1, 1)', method='galerkin')
    >>> obs.classify().verdict
    'exponential'
    """

    plant: Plant
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix | None
    tuning: TuneResult | None = field(default=None, compare=False)

    def __init__(
        self,
        model: BCPHS | Plant,
        sensors: int | Sequence[int] | None = None,
        *,
        C_m: Any = None,
        gain: Any = None,
        parameters: Mapping[str, Any] | None = None,
        method: str = "galerkin",
        resolution: int | None = None,
        tuning: TuneResult | None = None,
    ) -> None:
        if not isinstance(model, Plant):
            plant = Plant(model, dict(parameters or {}), method, resolution)
        elif parameters or method != "galerkin" or resolution is not None:
            raise ArgumentError("give parameters, method and resolution to the Plant, not twice")
        else:
            plant = model
        n_outputs = plant.model.n_ports  # the external outputs ([feedback] closes the others)
        if (sensors is None) == (C_m is None):
            raise ObserverError(
                "an observer needs either sensors=[...] (outputs by index, e.g. [3, 4]) or "
                "C_m=[[...]] (the sensor matrix); found "
                + ("neither" if sensors is None else "both")
            )
        exact = (
            sensor_matrix(sensors, n_outputs)
            if sensors is not None
            else measurement_matrix(C_m, n_outputs)
        )
        object.__setattr__(self, "plant", plant)
        object.__setattr__(self, "C_m", exact)
        object.__setattr__(self, "L", None if gain is None else gain_matrix(gain, exact.rows))
        object.__setattr__(self, "tuning", tuning)

    # ------------------------------------------------------------------ views
    @property
    def model(self) -> BCPHS:
        """The symbolic model (as given, without the parameter overrides)."""
        return self.plant.model

    @property
    def q(self) -> int:
        """The number of sensors."""
        return int(self.C_m.rows)

    @property
    def symbolic(self) -> bool:
        """Whether the gain holds symbols (then only :meth:`classify` applies)."""
        return self.L is not None and bool(self.L.free_symbols)

    def with_gain(self, gain: Any) -> Observer:
        """Return an observer with the same sensors and another gain."""
        return self._copy(gain=gain_matrix(gain, self.q), tuning=None)

    def _copy(self, gain: Any, tuning: TuneResult | None) -> Observer:
        return Observer(self.plant, C_m=self.C_m, gain=gain, tuning=tuning)

    def _gain(self, what: str) -> sympy.ImmutableMatrix:
        if self.L is None:
            raise ObserverError(
                f"{what} needs a gain: give gain=[...] (one number per sensor, or a matrix), "
                "or tune() one"
            )
        return self.L

    def numeric_gain(self, what: str = "this computation") -> tuple[np.ndarray, np.ndarray]:
        """``(C_m, L)`` as float arrays; a symbolic or missing gain is refused."""
        L = numeric_matrix(self._gain(what), "L", what)
        return numeric_matrix(self.C_m, "C_m", what), L

    # ------------------------------------------------------------------ questions
    def classify(self, method: str = "auto") -> Classification:
        r"""Classify the design against Propositions 3.1 to 3.4 (exact; κ* or a witness).

        ``method`` says how :math:`\kappa^*` is computed: ``"auto"``, ``"exact"`` or
        ``"float"`` (the decision is always exact).
        """
        from phdesign.symbolic.classify import classify

        return classify(self.plant.design_model, self.C_m, self._gain("classify"), method)

    def spectrum(
        self, *, max_resolution: int | None = None, tol: float | None = None, count: int = 6
    ) -> SpectrumReport:
        r"""Return the converged spectrum of the error system.

        The error system is the plant with :math:`\tilde u = -C_m^\top L C_m \tilde y`.

        Only eigenvalues that agree at two resolutions are kept; the report says whether
        the abscissa converged (:func:`phdesign.numeric.spectrum.spectrum`).
        """
        C, L = self.numeric_gain("spectrum")
        return self.plant.closed_spectrum(
            C, L, max_resolution=max_resolution, tol=tol, count=count
        )

    def simulate(
        self,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        xhat0: str | Callable[[Any], Any] | None = None,
        t_end: float = 5.0,
        samples: int = 501,
        u: Callable[[float], Any] | None = None,
        scheme: str = "expm",
        z_w: Any = None,
        tol: float = 1e-6,
    ) -> SimulationResult:
        """Simulate plant and observer together.

        Parameters
        ----------
        x0, xhat0 : str or callable, optional
            Initial states of plant and observer: text such as ``"x1: 0, x2: z - 0.9"``
            (state names or efforts ``e1``, expressions in ``z`` and the parameters) or a
            function ``f(z) -> (len(z), n)``.  Both default to zero: without ``x0`` and
            ``u`` every series is zero.
        t_end, samples, u, scheme, z_w, tol
            See :func:`phdesign.numeric.simulate.simulate`.
        """
        C, L = self.numeric_gain("simulate")
        return self.plant.run(
            C,
            L,
            x0,
            xhat0=xhat0,
            labels=self.labels(),
            t_end=t_end,
            samples=samples,
            u=u,
            scheme=scheme,
            z_w=z_w,
            tol=tol,
        )

    def tune(
        self, *, full: bool = False, starts: int = 6, seed: int = 0, resolution: int | None = None
    ) -> Observer:
        """Tune the gain for these sensors: minimize the error system's converged abscissa.

        Returns
        -------
        Observer
            A new observer with the same sensors and the tuned gain; its ``tuning``
            attribute holds the :class:`~phdesign.numeric.tune.TuneResult` (the abscissa,
            whether it converged, whether eigenvalues coalesce there, every start).
            The observer it was called on is unchanged.
        """
        from phdesign.numeric.tune import tune

        C = numeric_matrix(self.C_m, "C_m", "tune")
        report = tune(
            self.plant.numeric, C, full=full, starts=starts, seed=seed, resolution=resolution
        )
        return self._copy(gain=report.gain, tuning=report)

    def statespace(self, system: str = "error", resolution: int | None = None) -> Any:
        """Export ``"plant"``, ``"observer"`` or ``"error"`` as a ``control.StateSpace``.

        The discretization is the plant's (:class:`Plant`), at ``resolution`` if given.
        See :mod:`phdesign.numeric.export` for the inputs, outputs and states.
        """
        from phdesign.numeric import export

        choice(system, "system", STATESPACE_SYSTEMS, ObserverError)
        if system == "plant":
            return export.plant_statespace(self.plant.discrete(resolution))
        C, L = self.numeric_gain("statespace")
        d = self.plant.discrete(resolution)
        if system == "observer":
            return export.observer_statespace(d, C, L)
        return export.error_statespace(d, C, L)

    # ------------------------------------------------------------------ display
    def labels(self) -> dict[str, str]:
        """Return the design as text (sensors, gain), as it labels simulations and plots."""
        gain = "none (tune one)" if self.L is None else matrix_text(self.L)
        return {"sensors": sensors_text(self.C_m), "gain": gain}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description: model, sensors and gain rows (exact, as text), options."""
        return {
            "model": self.model.name,
            "sensors": [[str(x) for x in row] for row in self.C_m.tolist()],
            "gain": None if self.L is None else [[str(x) for x in row] for row in self.L.tolist()],
            "parameters": {k: str(v) for k, v in self.plant.parameters.items()},
            "method": self.plant.method,
            "resolution": self.plant.resolution,
            "tuned": self.tuning is not None,
        }

    def __str__(self) -> str:
        labels = self.labels()
        lines = [
            f"observer of {self.model.name}: sensors {labels['sensors']}, gain L = "
            f"{labels['gain']}"
        ]
        if self.plant.parameters:
            lines.append(f"parameters: {self.plant.parameters}")
        if self.tuning is not None:
            alpha = self.tuning.spectral_abscissa
            lines.append(
                "tuned: spectral abscissa "
                + ("unbounded below" if alpha is None else f"{alpha:.10g}")
            )
        return "\n".join(lines)

    def __repr__(self) -> str:
        labels = self.labels()
        text = (
            f"Observer(model={self.model.name!r}, sensors={shorten(labels['sensors'], 60)!r}, "
            f"L={shorten(labels['gain'], 80)!r}, method={self.plant.method!r}"
        )
        if self.tuning is not None:
            alpha = self.tuning.spectral_abscissa
            text += f", tuned_abscissa={None if alpha is None else round(alpha, 6)}"
        return shorten(text + ")", REPR_LIMIT)

    def _repr_html_(self) -> str:
        labels = self.labels()
        rows = [
            ["model", self.model.name],
            ["sensors", labels["sensors"]],
            ["gain L", labels["gain"]],
            ["discretization", self.plant.method],
        ]
        if self.tuning is not None:
            rows.append(["tuned abscissa", str(self.tuning.spectral_abscissa)])
        return html_table(["observer", ""], rows)
