r"""Tuning the loop's gains on its converged abscissa, by separation.

The loop's spectrum is the controlled plant's together with the error system's
(:mod:`phdesign.numeric.control.assembly`), so its abscissa is

.. math::

    \alpha_{loop}(K, L) = \max\big(\alpha_{plant}(K), \alpha_{error}(L)\big),
    \qquad \min_{K, L} \alpha_{loop} = \max\big(\min_K \alpha_{plant},\
    \min_L \alpha_{error}\big):

the joint problem splits into two independent ones.  The controlled plant
:math:`E\dot{\hat e} = (J - R - B S_a^\top K S_a B^\top)\hat e` has the form of an error
system with "sensors" :math:`S_a` and gain :math:`K`, so both are tuned by
:func:`phdesign.numeric.tuning.search.tune` (converged abscissa, coalescence detection); the pair
is then verified on the assembled loop (:func:`phdesign.numeric.control.spectrum.loop_spectrum`).
Any K with :math:`\alpha_{plant}(K) \le \min_L \alpha_{error}` is optimal too when the
error system limits the loop; the tuned K is the one that makes the plant fastest.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from phdesign.core.errors import LoopError
from phdesign.core.progress import stage
from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.control.assembly import NumericLoop
from phdesign.numeric.control.spectrum import LoopSpectrum, loop_spectrum
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.tuning.search import TuneResult, tune

__all__ = ["TUNE_TARGETS", "LoopTuneResult", "tune_loop"]

#: What :func:`tune_loop` tunes: the feedback K, the observer gain L, or both.
TUNE_TARGETS = ("feedback", "gain", "both")


@dataclass(frozen=True)
class LoopTuneResult:
    """Result of :func:`tune_loop`.

    Attributes
    ----------
    loop : NumericLoop
        The loop with the tuned gains.
    tuned : str
        ``"feedback"``, ``"gain"`` or ``"both"``.
    report : LoopSpectrum
        The assembled loop's converged spectrum at the tuned gains.
    plant, error : TuneResult or None
        The tuning of K on the controlled plant and of L on the error system (None for
        the gain that was kept).
    """

    loop: NumericLoop
    tuned: str
    report: LoopSpectrum = field(repr=False)
    plant: TuneResult | None = field(default=None, repr=False)
    error: TuneResult | None = field(default=None, repr=False)

    @property
    def spectral_abscissa(self) -> float | None:
        """The assembled loop's converged abscissa at the tuned gains."""
        return self.report.spectral_abscissa

    @property
    def limited_by(self) -> str | None:
        """``"plant"`` or ``"error"``: the block whose abscissa is the loop's."""
        p, e = self.report.plant_abscissa, self.report.error_abscissa
        if p is None or e is None:
            return None if p is None and e is None else ("error" if p is None else "plant")
        return "plant" if p >= e else "error"

    @property
    def warnings(self) -> list[str]:
        """The loop report's warnings, and what each tuning found when not an optimum."""
        out = list(self.report.warnings)
        for name, result in (("controlled plant", self.plant), ("error system", self.error)):
            if result is not None and result.status != "optimum":
                out.append(f"the tuned {name}: {result.status_text()}")
            if result is not None and result.at_coalescence:
                out.append(
                    f"the tuned {name} sits at a coalescence of eigenvalues: its abscissa is "
                    "not Lipschitz there, so rounding the gain moves it; keep the digits"
                )
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "tuned": self.tuned,
            # the spectrum is the same either way (separation); the loop it describes is not
            "feedback_source": self.loop.source,
            "feedback": np.asarray(self.loop.K).tolist(),
            "gain": np.asarray(self.loop.L).tolist(),
            "spectral_abscissa": self.report.to_dict()["spectral_abscissa"],
            "converged": self.report.converged,
            "plant_abscissa": self.report.to_dict()["plant_abscissa"],
            "error_abscissa": self.report.to_dict()["error_abscissa"],
            "limited_by": self.limited_by,
            "plant_at_coalescence": None if self.plant is None else self.plant.at_coalescence,
            "error_at_coalescence": None if self.error is None else self.error.at_coalescence,
            "loop": self.report.to_dict(),
            "warnings": self.warnings,
        }

    def __repr__(self) -> str:
        return (
            f"LoopTuneResult(tuned={self.tuned!r}, K={np.round(self.loop.K, 6).tolist()}, "
            f"L={np.round(self.loop.L, 6).tolist()}, abscissa={self.spectral_abscissa})"
        )[:300]

    def __str__(self) -> str:
        """Return the text ``phdesign loop tune`` prints."""
        r = self.report
        lines = [
            f"model: {r.model}   tuned: {self.tuned}",
            f"feedback K = {np.round(self.loop.K, 8).tolist()}",
            f"observer gain L = {np.round(self.loop.L, 8).tolist()}",
        ]
        if r.spectral_abscissa is None:
            lines.append("loop spectral abscissa: unbounded below at these gains")
        else:
            lines.append(
                f"loop spectral abscissa: {r.spectral_abscissa:.10g}   converged: "
                f"{r.converged}   limited by: {self.limited_by}"
            )
        for name, value in (
            ("controlled plant", r.plant_abscissa),
            ("error system", r.error_abscissa),
        ):
            lines.append(f"{name}: {'unbounded below' if value is None else f'{value:.10g}'}")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = (
            ("K", np.round(self.loop.K, 8).tolist()),
            ("L", np.round(self.loop.L, 8).tolist()),
            ("loop abscissa", self.spectral_abscissa),
            ("limited by", self.limited_by),
        )
        return html_table((), rows, f"tuned loop ({self.tuned})")


@limited_threads
def tune_loop(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    target: str = "both",
    full: bool = False,
    starts: int = 6,
    seed: int = 0,
    resolution: int | None = None,
    maxiter: int = 300,
) -> LoopTuneResult:
    """Tune K (on the controlled plant), L (on the error system) or both (module docstring).

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
        The starting design; the gain that is not tuned is kept.
    target : {"feedback", "gain", "both"}
    full, starts, seed, resolution, maxiter
        As for :func:`phdesign.numeric.tuning.search.tune`.

    Returns
    -------
    LoopTuneResult
    """
    if target not in TUNE_TARGETS:
        raise LoopError(f"tune target must be one of {TUNE_TARGETS}; found {target!r}")
    loop.check(nm.n_ports)
    options: dict[str, Any] = {
        "full": full,
        "starts": starts,
        "seed": seed,
        "resolution": resolution,
        "maxiter": maxiter,
    }
    plant = error = None
    K, L = np.asarray(loop.K, float), np.asarray(loop.L, float)
    if target in ("feedback", "both"):
        with stage("loop: tuning K on the controlled plant"):
            plant = tune(nm, loop.selection(nm.n_ports), **options)
        K = plant.gain
    if target in ("gain", "both"):
        with stage("loop: tuning L on the error system"):
            error = tune(nm, loop.C_m, **options)
        L = error.gain
    tuned = replace(loop, K=K, L=L)
    return LoopTuneResult(tuned, target, loop_spectrum(nm, tuned), plant, error)
