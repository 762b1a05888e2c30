r"""The noise questions of an observer: what its gain costs, speed against noise, a gain.

A mixin of :class:`~phdesign.design.observer.Observer` (which owns the design): the
observer receives :math:`y_m + \nu` with white sensor noise :math:`\nu`, and

* :meth:`ObserverNoise.noise` reports the figures of the gain (error variances of the
  performance outputs, the L²-gain from the noise, the expected error energy), each
  converged under refinement or flagged;
* :meth:`ObserverNoise.tradeoff` puts decay rate against error RMS over a ray or a grid
  of gains, the Pareto-optimal ones marked;
* :meth:`ObserverNoise.tune_noise` tunes a positive diagonal gain under an RMS budget or a
  decay requirement;
* :meth:`ObserverNoise.noise_samples` runs plant and observer from zero many times and
  returns the errors of the performance outputs (a Monte Carlo check of :meth:`noise`).

The numbers come from :mod:`phdesign.numeric.noise`; ``phdesign noise``, ``tradeoff`` and
``tune --max-rms`` ask these methods.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from phdesign.core.checks import positive_int, positive_number
from phdesign.core.errors import ObserverError
from phdesign.core.progress import Progress, reports_progress
from phdesign.design.plant import Plant, numeric_matrix
from phdesign.symbolic.observer import gain_matrix

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np
    import sympy

    from phdesign.numeric.noise.disturbance_report import GainReport
    from phdesign.numeric.noise.disturbance_tradeoff import DisturbanceTradeoff
    from phdesign.numeric.noise.disturbance_tuning import DisturbanceTuneResult
    from phdesign.numeric.noise.metrics import Metric
    from phdesign.numeric.noise.report import NoiseReport
    from phdesign.numeric.noise.tradeoff import Tradeoff
    from phdesign.numeric.noise.tuning import NoiseTuneResult

__all__ = ["ObserverNoise"]


class ObserverNoise:
    """The noise questions of :class:`~phdesign.design.observer.Observer` (reads its design)."""

    plant: Plant
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix | None
    numeric_gain: Callable[..., tuple[np.ndarray, np.ndarray]]

    @reports_progress
    def noise(
        self,
        *,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
        metrics: Sequence[Metric] = (),
        progress: Progress | None = None,
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
        metrics : sequence of Metric, optional
            Further figures, one class each (:mod:`phdesign.numeric.noise.metrics`),
            reported in ``.figures``.
        progress : callable, optional
            Called with one line of text at each stage (:mod:`phdesign.core.progress`).

        Returns
        -------
        NoiseReport
            ``.performance[0].value`` (None unless converged), ``.rms()``, ``.l2_gain``,
            ``.error_energy``; ``str()`` is what ``phdesign noise`` prints.

        Examples
        --------
        >>> from phdesign import Observer
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
            metrics=metrics,
        )

    @reports_progress
    def gain(
        self,
        *,
        intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        max_resolution: int | None = None,
        tol: float | None = None,
        optimal: bool = False,
        progress: Progress | None = None,
    ) -> GainReport:
        r"""Return the H∞ and H₂ norms from the disturbances and sensor noise to the error.

        The observer knows u but not the disturbances (the model's ``[disturbances]``
        :math:`B(z) w` and unknown inputs) nor the sensor noise ν of ``intensity``
        (default 1; 0 leaves it out); the report gives the norms from all of them to the
        estimation error of the ``[performance]`` outputs, split per source, each
        converged or flagged (:meth:`phdesign.design.plant.Plant.gain`).  With
        ``optimal``, the optimal full-order estimators of the same plant, disturbances
        and noise are printed beside: the Kalman–Bucy H₂ error and the H∞-optimal level
        γ* (:mod:`phdesign.numeric.noise.optimal`), the price of a boundary observer.
        """
        C, L = self.numeric_gain("gain")
        return self.plant.gain(
            C,
            L,
            intensity=intensity,
            performance=[performance] if isinstance(performance, str) else performance,
            max_resolution=max_resolution,
            tol=tol,
            optimal=optimal,
        )

    @reports_progress
    def tradeoff(
        self,
        *,
        direction: Any = None,
        scales: Sequence[float] | None = None,
        grid: Sequence[Sequence[float]] | None = None,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        against: str = "rms",
        progress: Progress | None = None,
    ) -> Tradeoff | DisturbanceTradeoff:
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
        intensity, input_intensity, performance, progress
            As for :meth:`noise`.
        against : {"rms", "hinf"}
            ``"hinf"``: the decay rate against the H∞ norm of :meth:`gain` from the model's
            ``[disturbances]`` and the sensor noise of ``intensity`` (default 1) to the error
            of its ``[performance]`` outputs (``performance`` in that grammar;
            ``input_intensity`` does not apply): a
            :class:`~phdesign.numeric.noise.disturbance_tradeoff.DisturbanceTradeoff`
            (:func:`phdesign.numeric.noise.disturbance_tradeoff.disturbance_tradeoff`).

        Returns
        -------
        Tradeoff or DisturbanceTradeoff
            ``.points`` (gain, decay rate, rms or H∞, Pareto flag), ``.pareto_points``,
            ``.to_csv()``, ``.plot()``; ``str()`` is what ``phdesign tradeoff`` prints.

        Examples
        --------
        >>> from phdesign import Observer
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
                exact = gain_matrix(direction, int(self.C_m.rows))
            except ObserverError as error:
                raise ObserverError(
                    f"direction (the gain L_0 of the ray s L_0): {error}"
                ) from None
            direction = numeric_matrix(exact, "direction", "tradeoff")
        if against not in ("rms", "hinf"):
            raise ObserverError(f"against must be 'rms' or 'hinf'; found {against!r}")
        if against == "hinf":
            from phdesign.numeric.noise.disturbance_tradeoff import disturbance_tradeoff

            if input_intensity is not None:
                raise ObserverError("input_intensity belongs to the RMS trade-off (against='rms')")
            return disturbance_tradeoff(
                self.plant.numeric,
                C,
                model=self.plant.design_model,
                direction=direction,
                scales=scales,
                grid=grid,
                intensity=intensity,
                performance=[performance] if isinstance(performance, str) else performance,
                method=self.plant.method,
            )
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

    def noise_samples(
        self,
        *,
        steps: int,
        dt: float,
        runs: int,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        seed: int | None = None,
    ) -> np.ndarray:
        r"""Return Monte Carlo samples of the performance outputs' errors, from zero.

        ``runs`` independent paths of plant and observer, both started at zero and driven
        by the noise of :meth:`noise`, sampled exactly every ``dt`` (the Van Loan
        covariance over each step, :mod:`phdesign.numeric.time.stochastic`) at the plant's
        discretization.  At large ``steps * dt`` the samples' variance estimates the
        Lyapunov variance that :meth:`noise` reports at that resolution, with no
        time-stepping bias.

        Parameters
        ----------
        steps, dt : int, float
            Number of steps and their length (in the model's time unit).
        runs : int
            Number of independent paths.
        intensity, input_intensity, performance
            As for :meth:`noise` (sensor intensities default 1).
        seed : int, optional
            Seed of :func:`numpy.random.default_rng`: the same seed gives the same samples.

        Returns
        -------
        ndarray, shape (steps + 1, len(performance), runs)
            The error :math:`c^\top (\hat e - \hat e_{obs})` of each performance output at
            the times ``0, dt, ..., steps * dt`` (zero at the first).

        Examples
        --------
        >>> from phdesign import Observer
        >>> from phdesign.models import load_builtin
        >>> string = Observer(load_builtin("wave"), sensors=[2], gain=0.5, resolution=8)
        >>> e = string.noise_samples(steps=4, dt=1.0, runs=3, performance="x2: 1", seed=0)
        >>> e.shape, float(abs(e[0]).max())
        ((5, 1, 3), 0.0)
        """
        import numpy as np

        from phdesign.numeric.discretization.functionals import parse_functionals
        from phdesign.numeric.noise.figures import noise_intensities
        from phdesign.numeric.time.stochastic import noisy_coupled_system, sampled_noise

        steps = positive_int(steps, "steps")
        runs = positive_int(runs, "runs")
        dt = positive_number(dt, "dt")
        C, L = self.numeric_gain("noise_samples")
        nm = self.plant.numeric
        sigma, w_in = noise_intensities(nm, C.shape[0], intensity, input_intensity)
        d = self.plant.discrete()
        rows = [f.row(d) for f in parse_functionals(performance, nm, self.plant.design_model)]
        E2, A2, _, N2 = noisy_coupled_system(d, C, L, sigma, w_in)
        paths = sampled_noise(E2, A2, N2, dt).paths(steps, runs, rng=seed)
        errors = paths[:, : d.dim] - paths[:, d.dim :]
        return np.array([[row @ e for row in rows] for e in errors])

    @reports_progress
    def tune_noise(
        self,
        *,
        objective: str = "abscissa",
        max_rms: float | None = None,
        min_decay: float | None = None,
        max_hinf: float | None = None,
        intensity: float | Sequence[float] | None = None,
        input_intensity: float | Sequence[float] | None = None,
        performance: str | Sequence[str] | None = None,
        progress: Progress | None = None,
    ) -> NoiseTuneResult | DisturbanceTuneResult:
        r"""Tune a positive diagonal gain for these sensors under a noise or disturbance budget.

        ``objective="abscissa"`` minimizes the converged spectral abscissa subject to the
        error RMS of the performance outputs at most ``max_rms``; ``"rms"`` minimizes the
        RMS subject to the abscissa at most ``-min_decay``
        (:func:`phdesign.numeric.noise.tuning.tune_noise`).  ``intensity``,
        ``input_intensity``, ``performance`` and ``progress`` are those of :meth:`noise`.

        Against the model's ``[disturbances]`` (:meth:`gain`'s figures, sensor noise of
        ``intensity`` included): ``"hinf"`` (``"h2"``) minimizes the H∞ (H₂) norm to the
        error of the ``[performance]`` outputs, subject to the abscissa at most
        ``-min_decay`` when given; ``"abscissa"`` with ``max_hinf`` minimizes the abscissa
        subject to the H∞ norm at most ``max_hinf``
        (:func:`phdesign.numeric.noise.disturbance_tuning.tune_disturbance`).  There
        ``performance`` is in the ``[performance]`` grammar (``"integral(e1)"``; default
        the model's) and ``input_intensity`` does not apply.

        Returns
        -------
        NoiseTuneResult or DisturbanceTuneResult
            ``.gain`` and the figures it reaches, verified; ``str()`` is what ``phdesign
            tune --max-rms`` (``--objective hinf``, ``--max-hinf``) prints.

        Examples
        --------
        >>> from phdesign import Observer
        >>> from phdesign.io import model_from_dict, model_to_dict
        >>> from phdesign.models import load_builtin
        >>> data = model_to_dict(load_builtin("wave"))  # the string under a uniform force
        >>> data["disturbances"] = {"B": [[1], [0]]}
        >>> data["performance"] = {"outputs": ["integral(e1)"]}
        >>> string = Observer(model_from_dict(data), sensors=[2])
        >>> tuned = string.tune_noise(objective="hinf", intensity=0)
        >>> round(float(tuned.gain[0, 0]), 2), round(tuned.hinf, 4)  # the damped tip k*
        (0.96, 0.5349)
        """
        C = numeric_matrix(self.C_m, "C_m", "tune")
        if objective in ("hinf", "h2") or max_hinf is not None:
            from phdesign.numeric.noise.disturbance_tuning import tune_disturbance

            if max_rms is not None or input_intensity is not None:
                given = "max_rms" if max_rms is not None else "input_intensity"
                raise ObserverError(
                    f"{given} belongs to the noise objectives; the disturbance objectives "
                    "(hinf, h2, max_hinf) take the sensor noise as intensity"
                )
            return tune_disturbance(
                self.plant.numeric,
                C,
                model=self.plant.design_model,
                objective=objective,
                max_hinf=max_hinf,
                min_decay=min_decay,
                intensity=intensity,
                performance=[performance] if isinstance(performance, str) else performance,
                method=self.plant.method,
            )
        from phdesign.numeric.noise.tuning import tune_noise

        return tune_noise(
            self.plant.numeric,
            C,
            objective=objective,
            max_rms=max_rms,
            min_decay=min_decay,
            intensity=intensity,
            input_intensity=input_intensity,
            performance=performance,
            model=self.plant.design_model,
        )
