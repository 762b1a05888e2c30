r"""The noise figures that are one number at each resolution: a :class:`Metric` per figure.

A metric reads the stationary statistics of the noise-driven error system at one
resolution (:class:`~phdesign.numeric.noise.statistics.ErrorStatistics`: the covariance
:math:`P` of :math:`A P E^\top + E P A^\top + G G^\top = 0` and the discretization) and
returns a number; :func:`phdesign.numeric.noise.figures.noise` evaluates every metric at
each resolution of its refinement and :func:`~phdesign.numeric.noise.settle.settle` judges
the sequence (converged, diverging or not converged).  So a new figure is one class with
a ``name`` and a ``value``, handed to ``noise(..., metrics=[...])``:

* :class:`OutputVariance`, :math:`c P c^\top`, the variance of a performance output's
  estimation error (a smooth functional converges; a boundary trace diverges);
* :class:`ErrorEnergy`, :math:`\mathbb E[\tilde H] = \tfrac12 \operatorname{tr}(E P)`,
  infinite for white noise at the boundary of these PDEs (it diverges under refinement).

The L²-gain is not of this kind: it is a peak over the band that *two* resolutions resolve
(:mod:`phdesign.numeric.noise.gain`), so it is computed per pair, not per resolution.

Examples
--------
>>> from dataclasses import dataclass
>>> import numpy as np
>>> @dataclass(frozen=True)
... class TraceOfP(Metric):  # a new figure: the trace of the covariance
...     name: str = "tr P"
...     def value(self, stats):
...         return float(np.trace(stats.covariance))
>>> TraceOfP().label
'tr P'
"""

from __future__ import annotations

from dataclasses import dataclass

from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.noise.statistics import ErrorStatistics

__all__ = ["ErrorEnergy", "Metric", "OutputVariance"]


@dataclass(frozen=True)
class Metric:
    """A noise figure that is one number at each resolution (module docstring).

    Attributes
    ----------
    name : str
        How the report and the JSON name the figure.
    smooth : bool
        Whether the figure is a smooth functional of the error (its divergence, if any,
        is then explained as that of a boundary trace; else as the infinite energy of a
        PDE driven by white noise at its boundary).
    """

    name: str = ""
    smooth: bool = True

    @property
    def label(self) -> str:
        """How warnings name the figure."""
        return self.name

    def value(self, stats: ErrorStatistics) -> float:
        """Return the figure at the resolution of ``stats`` (``inf`` without a steady state)."""
        raise NotImplementedError(f"{type(self).__name__} defines no value")


@dataclass(frozen=True)
class OutputVariance(Metric):
    r"""The stationary variance :math:`c P c^\top` of a performance output's error."""

    functional: Functional | None = None

    def __post_init__(self) -> None:
        if self.functional is not None and not self.name:
            object.__setattr__(self, "name", self.functional.name)

    @property
    def label(self) -> str:
        """``Var[w(1)~]``: the variance of the output's estimation error."""
        return f"Var[{self.name}~]"

    def value(self, stats: ErrorStatistics) -> float:
        r"""Return :math:`c P c^\top` for the functional's row c at this resolution."""
        if self.functional is None:
            raise NotImplementedError("OutputVariance needs a functional")
        return stats.variance(self.functional.row(stats.discrete))


@dataclass(frozen=True)
class ErrorEnergy(Metric):
    r"""The expected error energy :math:`\tfrac12 \operatorname{tr}(E P)`."""

    name: str = "E[H~]"
    smooth: bool = False

    def value(self, stats: ErrorStatistics) -> float:
        r"""Return :math:`\tfrac12 \operatorname{tr}(E P)` at this resolution."""
        return stats.energy()
