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

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, ObserverError
from phdesign.core.progress import Progress, reports_progress
from phdesign.core.text import REPR_LIMIT, html_table, matrix_text, sensors_text, shorten
from phdesign.design.certify import ObserverCertify
from phdesign.design.export import STATESPACE_SYSTEMS, ObserverExport
from phdesign.design.noise import ObserverNoise
from phdesign.design.plant import Plant, numeric_matrix
from phdesign.symbolic.feedback import external_numbering
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, observer_sensors

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np

    from phdesign.numeric.spectrum.drift import PairSpectrum
    from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
    from phdesign.numeric.spectrum.report import SpectrumReport
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.result import SimulationResult
    from phdesign.numeric.tuning.search import TuneResult
    from phdesign.symbolic.classify import Classification

__all__ = ["STATESPACE_SYSTEMS", "Observer", "Plant", "numeric_matrix"]


@dataclass(frozen=True, init=False, repr=False)
class Observer(ObserverNoise, ObserverExport, ObserverCertify):
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
        method: str | None = None,
        resolution: int | None = None,
        tuning: TuneResult | None = None,
    ) -> None:
        if not isinstance(model, Plant):
            plant = Plant(model, dict(parameters or {}), method, resolution)
        elif parameters or method not in (None, current().method) or resolution is not None:
            raise ArgumentError("give parameters, method and resolution to the Plant, not twice")
        else:
            plant = model
        # the external outputs ([feedback] closes the others, and renumbers them)
        fb = plant.model.feedback
        note = "" if fb is None else external_numbering(len(plant.model.inputs), fb)
        exact, L = observer_sensors(sensors, C_m, gain, plant.model.n_ports, note)
        object.__setattr__(self, "plant", plant)
        object.__setattr__(self, "C_m", exact)
        object.__setattr__(self, "L", L)
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
        if self.q == 0:  # refuses any gain: no sensors
            return self._copy(observer_sensors(None, self.C_m, gain, self.C_m.cols)[1], None)
        # these sensors are checked already, and gain_matrix checks L (shape, L + Lᵀ ≻ 0):
        # the copy is not read and checked again (half of classify's observer)
        L = gain_matrix(gain, self.q)
        copy = object.__new__(Observer)
        for name, value in (("plant", self.plant), ("C_m", self.C_m), ("L", L), ("tuning", None)):
            object.__setattr__(copy, name, value)
        return copy

    def _copy(self, gain: Any, tuning: TuneResult | None) -> Observer:
        return Observer(self.plant, C_m=self.C_m, gain=gain, tuning=tuning)

    def _gain(self, what: str) -> sympy.ImmutableMatrix:
        if self.L is None:
            raise ObserverError(
                f"{what} needs a gain: give gain=[...] (one number per sensor, or a matrix), "
                "or tune() one"
            )
        return self.L

    def _need_sensors(self, what: str) -> None:
        if self.q == 0:
            raise ObserverError(
                f"{what} needs at least one sensor; found C_m with no rows (an observer "
                "without sensors only classifies: classify() certifies the plant by its own "
                "boundary dissipation; Plant.spectrum() and Plant.simulate() act on the plant)"
            )

    def numeric_gain(self, what: str = "this computation") -> tuple[np.ndarray, np.ndarray]:
        """``(C_m, L)`` as read-only float arrays; a symbolic or missing gain is refused.

        They are converted once per observer (every numeric method asks for them).
        """
        self._need_sensors(what)
        if self._gain(what).free_symbols:
            numeric_matrix(self._gain(what), "L", what)  # refuses it, saying what to do
        return self._floats

    @cached_property
    def _floats(self) -> tuple[np.ndarray, np.ndarray]:
        C, L = numeric_matrix(self.C_m, "C_m", ""), numeric_matrix(self._gain(""), "L", "")
        for matrix in (C, L):
            matrix.setflags(write=False)
        return C, L

    # ------------------------------------------------------------------ questions
    def classify(self, method: str = "auto") -> Classification:
        r"""Classify the design against Propositions 3.1 to 3.4 (exact; κ* or a witness).

        ``method`` says how :math:`\kappa^*` is computed: ``"auto"``, ``"exact"`` or
        ``"float"`` (the decision is always exact).
        """
        from phdesign.symbolic.classify import classify

        return classify(self.plant.design_model, self.C_m, self._gain("classify"), method)

    @reports_progress
    def spectrum(
        self,
        *,
        max_resolution: int | None = None,
        tol: float | None = None,
        count: int | None = None,
        progress: Progress | None = None,
    ) -> SpectrumReport:
        r"""Return the converged spectrum of the error system.

        The error system is the plant with :math:`\tilde u = -C_m^\top L C_m \tilde y`.

        Only eigenvalues that agree at two resolutions are kept; the report says whether
        the abscissa converged (:func:`phdesign.numeric.spectrum.converged.spectrum`).
        ``progress`` is called with one line of text at each stage of the refinement
        (:mod:`phdesign.core.progress`).
        """
        C, L = self.numeric_gain("spectrum")
        return self.plant.closed_spectrum(
            C, L, max_resolution=max_resolution, tol=tol, count=count
        )

    @reports_progress
    def simulate(
        self,
        x0: str | Callable[[Any], Any] | None = None,
        *,
        xhat0: str | Callable[[Any], Any] | None = None,
        u: str | Callable[[float], Any] | None = None,
        w: str | Callable[[float], Any] | None = None,
        options: SimulationOptions | None = None,
        progress: Progress | None = None,
        **settings: Any,
    ) -> SimulationResult:
        """Simulate plant and observer together: what ``phdesign simulate`` runs.

        Parameters
        ----------
        x0, xhat0 : str or callable, optional
            Initial states of plant and observer: text such as ``"x1: 0, x2: z - 0.9"``
            (state names or efforts ``e1``, expressions in ``z`` and the parameters) or a
            function ``f(z) -> (len(z), n)``.  Both default to zero: without ``x0`` and
            ``u`` every series is zero.
        u : str or callable, optional
            Plant inputs: text such as ``"u2: sin(2*t)"`` or a function ``u(t)``.
        w : str or callable, optional
            Disturbances on the model's ``[disturbances]`` B, which the observer does not
            know: text such as ``"w1: sin(3*t)"`` (the grammar of ``u``) or a function
            ``w(t) -> (q,)``; white disturbances are ``disturbance_intensity=...``.
        options : SimulationOptions, optional
            How to run (:class:`~phdesign.numeric.time.options.SimulationOptions`: the
            grid, the stepping, a sampled observer, noise); the discretization is the plant's.
        progress : callable, optional
            Called with one line of text at each stage (:mod:`phdesign.core.progress`).
        **settings
            Its fields by name, over ``options`` (``t_end=2``, ``dt=1e-3``,
            ``noise_intensity=0.1`` ...); a name that is not a field is refused.

        Examples
        --------
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2], gain=0.5, resolution=8)
        >>> run = string.simulate("x2: 1", t_end=1.0, samples=3, dt=0.01, sampler="point")
        >>> run.info["sampler"], run.t.tolist()
        ('point', [0.0, 0.5, 1.0])
        """
        C, L = self.numeric_gain("simulate")
        opts = self.plant.simulation_options(options, **settings)
        return self.plant.run(C, L, x0, xhat0=xhat0, u=u, w=w, options=opts, labels=self.labels())

    def abscissas(
        self, gains: Iterable[Any], *, resolution: int | tuple[int, int] | None = None
    ) -> np.ndarray:
        r"""Return the error system's spectral abscissa at many gains, for these sensors.

        Each value is the abscissa :meth:`spectrum` reports at the first pair of its
        refinement, without refining: the drift test and the rules of
        :mod:`phdesign.numeric.spectrum.abscissa` at one fixed pair of resolutions, the pair
        discretized once per observer (a gain map, a search of one's own, a scan).

        Parameters
        ----------
        gains : iterable of gains
            Each a number (every sensor), a sequence (the diagonal) or a ``q x q`` matrix.
        resolution : int or (int, int), optional
            The pair ``(p, p_fine)``, or ``p`` for ``(p, ⌈1.5 p⌉)``; default: the start of
            the spectrum's refinement (:mod:`phdesign.core.defaults`).

        Returns
        -------
        ndarray of float
            One abscissa per gain (``-inf``: empty spectrum, ``nan``: unresolved).

        Examples
        --------
        >>> import math
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2])
        >>> string.abscissas([0.5, [3.0]], resolution=(20, 30)).round(10).tolist()
        [-0.5493061443, -0.3465735903]
        >>> round(0.5 * math.log(1 / 3), 10)  # the exact damper at k = 0.5
        -0.5493061443
        """
        evaluator = self._evaluator(resolution)
        return evaluator.abscissas([self._gain_array(g) for g in gains])

    def pair(self, gain: Any, *, resolution: int | tuple[int, int] | None = None) -> PairSpectrum:
        """Return the error system's eigenvalues at one gain and a fixed resolution pair.

        What :meth:`abscissas` reads at that gain: ``.eigenvalues`` at the finer
        resolution (in the model's time unit), ``.resolved`` (agrees with the coarser),
        ``.coarse``; ``gain`` and ``resolution`` as there.
        """
        return self._evaluator(resolution).pair(self._gain_array(gain))

    def _evaluator(self, resolution: int | tuple[int, int] | None) -> AbscissaEvaluator:
        from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator

        self._need_sensors("abscissas")
        if resolution is None:
            order = self.plant.numeric.order
            resolution = current().discretization(str(self.plant.method), order).spectrum_start
        key: tuple[int, int] | int = (
            (int(resolution[0]), int(resolution[1]))
            if isinstance(resolution, tuple | list)
            else int(resolution)
        )
        if key not in self._evaluators:
            C = numeric_matrix(self.C_m, "C_m", "abscissas")
            self._evaluators[key] = AbscissaEvaluator(
                self.plant.numeric, C, key, method=self.plant.method
            )
        return self._evaluators[key]

    @cached_property
    def _evaluators(self) -> dict[tuple[int, int] | int, AbscissaEvaluator]:
        return {}  # one per resolution pair: the discretizations are built once

    def _gain_array(self, gain: Any) -> np.ndarray:
        """Return a numeric gain as the ``q x q`` array (a number, a diagonal or the matrix)."""
        import numpy as np

        L = np.asarray(gain, dtype=float)
        if L.ndim < 2:
            L = np.diag(np.broadcast_to(L, (self.q,)).copy()) if L.size in (1, self.q) else L
        if L.shape != (self.q, self.q):
            raise ArgumentError(
                f"gain: expected a number, {self.q} numbers or a {self.q} x {self.q} matrix; "
                f"found shape {L.shape}"
            )
        return L

    def tune(
        self,
        *,
        full: bool = False,
        starts: int = 6,
        seed: int = 0,
        resolution: int | None = None,
        robust: float | None = None,
        progress: Progress | None = None,
    ) -> Observer:
        """Tune the gain for these sensors: minimize the error system's converged abscissa.

        ``robust`` (a fraction, 0.05 for ±5 %) minimizes the worst abscissa over a box of
        gains around each candidate instead; ``progress`` receives one line of text as the
        search goes (:func:`phdesign.numeric.tuning.search.tune`, :mod:`phdesign.core.progress`).

        Returns
        -------
        Observer
            A new observer with the same sensors and the tuned gain; its ``tuning``
            attribute holds the :class:`~phdesign.numeric.tuning.search.TuneResult` (the abscissa,
            whether it converged, whether eigenvalues coalesce there, every start).
            The observer it was called on is unchanged.
        """
        from phdesign.numeric.tuning.search import tune

        self._need_sensors("tune")
        C = numeric_matrix(self.C_m, "C_m", "tune")
        report = tune(
            self.plant.numeric,
            C,
            full=full,
            starts=starts,
            seed=seed,
            resolution=resolution,
            robust=robust,
            progress=progress,
        )
        return self._copy(gain=report.gain, tuning=report)

    # ------------------------------------------------------------------ display
    def labels(self) -> dict[str, str]:
        """Return the design as text (sensors, gain), as it labels simulations and plots."""
        gain = "none (tune one)" if self.L is None else matrix_text(self.L)
        if self.q == 0:
            return {"sensors": "none", "gain": "none (no sensors)"}
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
            ["discretization", str(self.plant.method)],
        ]
        if self.tuning is not None:
            rows.append(["tuned abscissa", str(self.tuning.spectral_abscissa)])
        return html_table(["observer", ""], rows)
