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
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.checks import choice
from phdesign.core.defaults import current
from phdesign.core.errors import ArgumentError, ObserverError
from phdesign.core.text import REPR_LIMIT, html_table, matrix_text, sensors_text, shorten
from phdesign.design.plant import Plant, numeric_matrix
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, measurement_matrix, sensor_matrix

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np

    from phdesign.numeric.noise.report import NoiseReport
    from phdesign.numeric.noise.tradeoff import Tradeoff
    from phdesign.numeric.sampled.export import SampledObserver
    from phdesign.numeric.spectrum.report import SpectrumReport
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.result import SimulationResult
    from phdesign.numeric.tuning.search import TuneResult
    from phdesign.symbolic.classify import Classification

__all__ = ["STATESPACE_SYSTEMS", "Observer", "Plant", "numeric_matrix"]

#: The systems :meth:`Observer.statespace` exports.
STATESPACE_SYSTEMS = ("plant", "observer", "error")


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
        self,
        *,
        max_resolution: int | None = None,
        tol: float | None = None,
        count: int | None = None,
    ) -> SpectrumReport:
        r"""Return the converged spectrum of the error system.

        The error system is the plant with :math:`\tilde u = -C_m^\top L C_m \tilde y`.

        Only eigenvalues that agree at two resolutions are kept; the report says whether
        the abscissa converged (:func:`phdesign.numeric.spectrum.converged.spectrum`).
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
        u: str | Callable[[float], Any] | None = None,
        options: SimulationOptions | None = None,
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
        options : SimulationOptions, optional
            How to run (:class:`~phdesign.numeric.time.options.SimulationOptions`: the
            grid, the stepping, a sampled observer, noise); the discretization is the plant's.
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
        return self.plant.run(C, L, x0, xhat0=xhat0, u=u, options=opts, labels=self.labels())

    def tune(
        self, *, full: bool = False, starts: int = 6, seed: int = 0, resolution: int | None = None
    ) -> Observer:
        """Tune the gain for these sensors: minimize the error system's converged abscissa.

        Returns
        -------
        Observer
            A new observer with the same sensors and the tuned gain; its ``tuning``
            attribute holds the :class:`~phdesign.numeric.tuning.search.TuneResult` (the abscissa,
            whether it converged, whether eigenvalues coalesce there, every start).
            The observer it was called on is unchanged.
        """
        from phdesign.numeric.tuning.search import tune

        C = numeric_matrix(self.C_m, "C_m", "tune")
        report = tune(
            self.plant.numeric, C, full=full, starts=starts, seed=seed, resolution=resolution
        )
        return self._copy(gain=report.gain, tuning=report)

    def statespace(self, system: str = "error", resolution: int | None = None) -> Any:
        """Export ``"plant"``, ``"observer"`` or ``"error"`` as a ``control.StateSpace``.

        The discretization is the plant's (:class:`Plant`), at ``resolution`` if given.
        See :mod:`phdesign.numeric.statespace` for the inputs, outputs and states.
        """
        from phdesign.numeric import statespace as export

        choice(system, "system", STATESPACE_SYSTEMS, ObserverError)
        if system == "plant":
            return export.plant_statespace(self.plant.discrete(resolution))
        C, L = self.numeric_gain("statespace")
        d = self.plant.discrete(resolution)
        if system == "observer":
            return export.observer_statespace(d, C, L)
        return export.error_statespace(d, C, L)

    # ------------------------------------------------------------------ noise and export
    def noise(
        self,
        *,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
    ) -> NoiseReport:
        r"""Return what the gain costs in sensor noise: each figure converged or flagged.

        The observer receives :math:`y_m + \nu`, :math:`\mathbb E[\nu(t)\nu(s)^\top] =
        \Sigma_\nu \delta(t - s)`, so the error system is driven at the boundary,

        .. math::

            \tilde u = -C_m^\top L C_m \tilde y - C_m^\top L \nu ,

        and the report gives the steady-state variance of each performance output's
        error, the L²-gain from the noise to :math:`\tilde x` (energy norm) with its
        frequency, and the expected error energy :math:`\mathbb E[\tilde H]`, which is
        infinite for the PDE (reported as diverging, never as a number):
        :func:`phdesign.numeric.noise.figures.noise`.

        Parameters
        ----------
        intensity : float or sequence of float, optional
            Sensor noise intensities :math:`\sigma_i^2`, one per sensor or one for all
            (default 1).
        input_intensity : float or sequence of float, optional
            White noise on the plant inputs, which the observer does not know (default none).
        performance : str or sequence of str, optional
            Outputs whose estimation-error variance is reported: ``"w(1)"`` (the
            displacement at a point), a boundary trace such as ``"e1(1)"``, or an integral
            ``"x2: sin(pi*z)"``; default the displacement at b when the model has one.
        max_resolution, tol : optional
            Largest resolution of the refinement, and the relative agreement that makes a
            figure converged (default 1e-6 Galerkin, 1e-3 FD).

        Returns
        -------
        NoiseReport
            ``.performance[0].value`` (None unless converged), ``.rms()``, ``.l2_gain``,
            ``.error_energy``; ``str()`` is what ``phdesign noise`` prints.

        Examples
        --------
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2], gain=0.5)
        >>> report = string.noise(performance="x2: 1", intensity=0.3)
        >>> round(report.performance[0].value, 8)  # Var = k sigma^2 / 2 for the damper k
        0.075
        >>> report.error_energy.diverges, round(report.l2_gain.value**2, 8)  # sigma^2 max(1, k)^2
        (True, 0.3)
        """
        from phdesign.numeric.noise.figures import noise

        C, L = self.numeric_gain("noise")
        return noise(
            self.plant.numeric,
            C,
            L,
            model=self.plant.design_model,
            intensity=intensity,
            input_intensity=input_intensity,
            performance=performance,
            method=self.plant.method,
            resolution=self.plant.resolution,
            max_resolution=max_resolution,
            tol=tol,
        )

    def tradeoff(
        self,
        *,
        direction: Any = None,
        scales: Sequence[float] | None = None,
        grid: Sequence[Sequence[float]] | None = None,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
    ) -> Tradeoff:
        r"""Decay rate against error RMS for these sensors, over a ray or a grid of gains.

        Along the ray :math:`L(s) = s L_0` (or over a grid of diagonal gains) each gain
        gets the converged spectral abscissa :math:`\alpha` of the error system (decay
        rate :math:`-\alpha`) and the noise figures of :meth:`noise`; the gains that no
        other beats in both decay and RMS of the first performance output are marked
        Pareto-optimal (:func:`phdesign.numeric.noise.tradeoff.tradeoff`).

        Parameters
        ----------
        direction : number, sequence or matrix, optional
            :math:`L_0`; default this observer's gain (so :math:`s = 1` is this design),
            or the identity for an observer without one.
        scales : sequence of float, optional
            The scales s (default 12 log-spaced from 0.1 to 10).
        grid : sequence of sequences of float, optional
            Per-sensor gain values, every combination a diagonal gain (instead of a ray).
        intensity, input_intensity, performance
            As for :meth:`noise`.

        Returns
        -------
        Tradeoff
            ``.points`` (gain, decay rate, rms, Pareto flag), ``.pareto_points``,
            ``.to_csv()``, ``.plot()``; ``str()`` is what ``phdesign tradeoff`` prints.

        Examples
        --------
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2], gain=0.5)
        >>> t = string.tradeoff(scales=[0.5, 1, 4], performance="x2: 1")
        >>> [round(p.decay_rate, 6) for p in t.points]  # (1/2) ln|(1 + k)/(1 - k)|
        [0.255413, 0.549306, 0.549306]
        >>> [p.pareto for p in t.points]  # k = 2 decays as fast as k = 1/2, noisier
        [True, True, False]
        """
        from phdesign.numeric.noise.tradeoff import tradeoff

        C = numeric_matrix(self.C_m, "C_m", "tradeoff")
        if direction is None and grid is None and self.L is not None:
            direction = numeric_matrix(self.L, "L", "tradeoff (the default direction)")
        elif direction is not None:
            try:  # read as a gain is read (exact numbers, one per sensor or the matrix)
                exact = gain_matrix(direction, self.q)
            except ObserverError as error:
                raise ObserverError(
                    f"direction (the gain L_0 of the ray s L_0): {error}"
                ) from None
            direction = numeric_matrix(exact, "direction", "tradeoff")
        return tradeoff(
            self.plant.numeric,
            C,
            model=self.plant.design_model,
            direction=direction,
            scales=scales,
            grid=grid,
            intensity=intensity,
            input_intensity=input_intensity,
            performance=performance,
            method=self.plant.method,
        )

    def export(
        self,
        *,
        dt: float,
        sampler: str | None = None,
        order: int | None = None,
        reduction: str = "none",
        tol: float | None = None,
        output_tol: float | None = None,
        verify: bool = False,
        x0: str | Callable[[Any], Any] | None = None,
        t_end: float | None = None,
        plant_resolution: int | None = None,
        points: float | Sequence[float] | None = None,
    ) -> SampledObserver:
        r"""Return the observer a controller runs: finite order, sampled every ``dt``.

        .. math::

            \hat x_{k+1} = A \hat x_k + B v_k, \qquad \hat y_k = C \hat x_k + D v_k,
            \qquad v_k = (u_k;\ y_{m,k}),

        exact for the declared sampler: ``"average"`` (the mean of :math:`y_m` over each
        period; its error system is dissipative for every period) or ``"point"``
        (samples :math:`y_m(t_k)`, which alias a boundary velocity's unresolved content):
        :func:`phdesign.numeric.sampled.export.export_observer`.  The observer is a
        Legendre-Galerkin one whatever the plant's ``method``; its order is chosen from
        ``tol`` and ``output_tol`` unless given.

        Parameters
        ----------
        dt : float
            Sampling period (s).
        sampler : {"average", "point"}, optional
            Default ``"average"``; this and every default are the export's
            (:mod:`phdesign.core.defaults`).
        order : int, optional
            Observer states (default: the smallest that meets the targets).
        reduction : {"none", "modal", "balanced"}
        tol, output_tol : float
            Relative accuracy of the rightmost error eigenvalues; error floor of the
            performance outputs relative to their peak.
        verify : bool
            Run the exported observer against a high-resolution plant.
        x0 : str or callable, optional
            Plant initial state of those runs (``"x1: 0, x2: z - 0.9"``, or a function of z).
        t_end : float
        plant_resolution : int, optional
            Galerkin degree of the verification plant.
        points : sequence of float, optional
            Displacement points of the outputs ``w(z)`` (default b, with a displacement).

        Returns
        -------
        SampledObserver
            ``.A, .B, .C, .D``, ``.inputs``, ``.outputs``, ``.statespace()``,
            ``.write(path, "json" | "c" | "npz" | "statespace")``.

        Examples
        --------
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2], gain=0.5)
        >>> sampled = string.export(dt=1e-2, order=12)
        >>> sampled.order, sampled.inputs, sampled.sampler
        (12, ('u1', 'u2', 'y2'), 'average')
        """
        from phdesign.numeric.sampled.export import export_observer

        C, L = self.numeric_gain("export")
        return export_observer(
            self.plant.numeric,
            C,
            L,
            dt=dt,
            sampler=sampler,
            order=order,
            reduction=reduction,
            tol=tol,
            output_tol=output_tol,
            verify=verify,
            x0=self.plant.initial_state(x0, "x0"),
            x0_text=x0 if isinstance(x0, str) else None,
            t_end=t_end,
            plant_resolution=plant_resolution,
            points=points,
            model_name=self.model.name,
        )

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
            ["discretization", str(self.plant.method)],
        ]
        if self.tuning is not None:
            rows.append(["tuned abscissa", str(self.tuning.spectral_abscissa)])
        return html_table(["observer", ""], rows)
