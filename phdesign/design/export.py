r"""The exports of an observer: python-control systems and the sampled observer.

A mixin of :class:`~phdesign.design.observer.Observer` (which owns the design), as
:mod:`phdesign.design.noise` is:

* :meth:`ObserverExport.statespace` exports the plant, the observer or the error system
  as a ``control.StateSpace`` (:mod:`phdesign.numeric.statespace`);
* :meth:`ObserverExport.export` returns the finite-order observer sampled every ``dt``
  that a controller runs (:func:`phdesign.numeric.sampled.export.export_observer`).

``phdesign statespace`` and ``phdesign export`` ask these methods.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from phdesign.core.checks import choice
from phdesign.core.errors import ObserverError
from phdesign.core.progress import Progress, reports_progress
from phdesign.design.plant import Plant

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np
    import sympy

    from phdesign.numeric.sampled.export import SampledObserver

__all__ = ["STATESPACE_SYSTEMS", "ObserverExport"]

#: The systems :meth:`ObserverExport.statespace` exports.
STATESPACE_SYSTEMS = ("plant", "observer", "error")


class ObserverExport:
    """The exports of :class:`~phdesign.design.observer.Observer` (reads its design)."""

    plant: Plant
    C_m: sympy.ImmutableMatrix
    numeric_gain: Callable[..., tuple[np.ndarray, np.ndarray]]

    def statespace(
        self,
        system: str = "error",
        resolution: int | None = None,
        *,
        modes: str = "all",
        at: Any = None,
    ) -> Any:
        """Export ``"plant"``, ``"observer"`` or ``"error"`` as a ``control.StateSpace``.

        On the plant's discretization (at ``resolution`` if given); ``modes="resolved"`` keeps
        the modes resolved under refinement (``.truncation`` says which), ``at`` appends point
        outputs (``["rotation(1)"]``: ``rotation_hat(z=1)``): :mod:`phdesign.numeric.statespace`.
        """
        from phdesign.numeric import statespace as export

        choice(system, "system", STATESPACE_SYSTEMS, ObserverError)
        choice(modes, "modes", export.MODES, ObserverError)
        C, L = (None, None) if system == "plant" else self.numeric_gain("statespace")
        d = self.plant.discrete(resolution)
        return export.design_statespace(d, system, C, L, modes=modes, at=at)

    @reports_progress
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
        strict: bool = False,
        x0: str | Callable[[Any], Any] | Sequence[str | Callable[[Any], Any]] | None = None,
        t_end: float | None = None,
        plant_resolution: int | None = None,
        points: float | str | Sequence[float | str] | None = None,
        design: str | None = None,
        process_noise: float | Sequence[float] = 1.0,
        sensor_noise: float | Sequence[float] = 1.0,
        max_ratio: float | None = None,
        progress: Progress | None = None,
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
        strict : bool
            Verify (``verify`` implied) and raise
            :class:`~phdesign.core.errors.VerificationError` naming each failed check
            (targets, sampled against continuous, the plant's resolution).
        x0 : str, callable or a list of them, optional
            Plant initial state of those runs (``"x1: 0, x2: z - 0.9"``, or a function of
            z); a list is the whole verification set, its first state the order
            selection's. Default: every component ``(z-a)/(b-a) - 0.9``, then two smooth
            states per component that meet the boundary conditions.
        t_end : float
        plant_resolution : int, optional
            Galerkin degree of the verification plant.
        points : sequence of float or str, optional
            Point outputs: ``w(z)`` at numbers, named fields as ``"rotation(1)"`` (default b).
        design : {"auto", "passive", "kalman", "given"}, optional
            The gain the observer runs: the given gain re-tuned inside the dissipative
            averaged structure (``passive``), the steady-state Kalman predictor of the exact
            sampled model (``kalman``), both verified on the initial states and the lower
            worst ratio of floors taken (``auto``, the default), or the given gain as is
            (:mod:`phdesign.numeric.sampled.gain_design`). ``.design`` says which and why.
        process_noise, sensor_noise : float or sequence of float
            The Kalman design's noise model: intensity of white noise at each plant input,
            variance of each sensor sample's noise.
        max_ratio : float, optional
            The largest worst ratio F/F_c over the initial states that passes verification
            (10): ``strict`` fails above it, ``auto`` does not take a Kalman design above it.
        progress : callable, optional
            Called with one line of text at each stage (:mod:`phdesign.core.progress`).

        Returns
        -------
        SampledObserver
            ``.A, .B, .C, .D``, ``.inputs``, ``.outputs``, ``.statespace()``,
            ``.write(path, "json" | "c" | "npz" | "statespace")``.

        Examples
        --------
        >>> import phdesign as phd
        >>> string = phd.Observer(phd.load("wave"), sensors=[2], gain=0.5)
        >>> sampled = string.export(dt=1e-2, order=12)
        >>> sampled.order, sampled.inputs, sampled.sampler
        (12, ('u1', 'u2', 'y2'), 'average')
        """
        from phdesign.numeric.sampled.export import KalmanNoise, export_observer

        C, L = self.numeric_gain("export")
        states = self._initial_states(x0)
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
            strict=strict,
            x0=states,
            t_end=t_end,
            plant_resolution=plant_resolution,
            points=points,
            model_name=self.plant.model.name,
            design=design,
            noise=KalmanNoise(_intensity(process_noise), _intensity(sensor_noise)),
            max_ratio=max_ratio,
        )

    def _initial_states(self, x0: Any) -> Any:
        """Return the verification set of ``x0`` (None: the export's default set)."""
        from phdesign.numeric.sampled.state_set import InitialState

        if x0 is None:
            return None
        given = list(x0) if isinstance(x0, (list, tuple)) else [x0]
        if not given:
            raise ObserverError("x0 must name at least one initial state; found an empty list")
        return [
            InitialState(
                item if isinstance(item, str) else "x0", self.plant.initial_state(item, "x0")
            )
            for item in given
        ]


def _intensity(value: Any) -> Any:
    """Return a number as is, a sequence as a tuple (the noise model checks the values)."""
    return tuple(value) if isinstance(value, (list, tuple)) else value
