"""The result of :func:`phdesign.numeric.tuning.search.tune`, and how it shows itself.

``str(result)`` is exactly what ``phdesign tune`` prints, ``result.to_dict()`` what
``phdesign tune --json`` prints (strict JSON), ``_repr_html_`` a small table.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.text import html_table
from phdesign.numeric.spectrum.report import SpectrumReport, finite_or_none

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.numeric.spectrum.coalescence import Coalescence
    from phdesign.numeric.tuning.robustness import Robustness

__all__ = ["LocalSearch", "TuneResult"]


@dataclass(frozen=True)
class LocalSearch:
    """One local search of the tuner: where it started and where it ended."""

    start: np.ndarray
    gain: np.ndarray
    spectral_abscissa: float | None
    evaluations: int
    #: Nelder-Mead converged (its simplex shrank below the tolerance within its iterations).
    settled: bool = True

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {
            "start": self.start.tolist(),
            "gain": self.gain.tolist(),
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "evaluations": self.evaluations,
            "settled": self.settled,
        }


@dataclass(frozen=True)
class TuneResult:
    """Result of :func:`phdesign.numeric.tuning.search.tune`.

    Attributes
    ----------
    gain : ndarray
        The tuned L (full precision: near a coalescence the abscissa is not Lipschitz in
        the gain, and 8 printed digits already move it by 2e-3 on the paper's beam).
    spectral_abscissa : float or None
        Abscissa of the error system at ``gain``: the coalesced eigenvalue's real part when
        the optimum is a coalescence (accurate where the individual eigenvalues are not),
        else the verified spectrum's; None for an empty spectrum.
    converged : bool
        Whether the verified spectrum converged.
    at_coalescence : bool
        Whether eigenvalues coalesce at the optimum (located by Newton's method, or an
        ill-conditioned cluster at the rightmost of the verified spectrum).
    active : list of complex
        Counted eigenvalues (upper half-plane) whose real parts lie within 1e-3 max(s, |α|)
        of α.
    report : SpectrumReport
        The spectrum at ``gain``.
    starts : list of LocalSearch
        Every local search.
    status : {"optimum", "extinction", "descending", "no decay"}
        An optimum; finite-time extinction at ``gain`` (the spectrum is empty: no better
        gain exists); no optimum located, the abscissa still falling where the search
        stopped (``gain`` is the best found, a direction rather than an optimum:
        :func:`phdesign.numeric.tuning.search.tune`); or no exponential decay found (the abscissa
        is 0 within accuracy).
    evaluations : int
        Gains evaluated (each two eigenvalue problems, at the search or verification pair).
    robustness : Robustness or None
        Worst abscissa over the ±5 % box of gains (or the ``robust`` box).
    coalescence : Coalescence or None
        The coalescence located by Newton's method, when the optimum is one.
    search_resolutions : tuple of int
        The resolution pair of the search (``report.resolutions`` is the verification).
    robust : float or None
        The box half-width the search minimized the worst case over (None: nominal).
    seconds : float
        Wall time of the tuning.
    model : str
    descent : str
        Why the status is ``"descending"``: ``"restarts"`` (every restart of a local search
        that its iteration limit stopped still improved the abscissa) or ``"empty
        spectrum"`` (the search's low resolution found no resolved eigenvalue at
        ``gain``, and the verification a finite abscissa); empty otherwise.
    """

    gain: np.ndarray
    spectral_abscissa: float | None
    converged: bool
    at_coalescence: bool
    active: list[complex]
    report: SpectrumReport
    starts: list[LocalSearch] = field(default_factory=list)
    status: str = "optimum"
    evaluations: int = 0
    robustness: Robustness | None = None
    coalescence: Coalescence | None = None
    search_resolutions: tuple[int, int] = (0, 0)
    robust: float | None = None
    seconds: float = 0.0
    model: str = ""
    descent: str = ""

    @classmethod
    def from_report(
        cls,
        *,
        model: str,
        gain: np.ndarray,
        report: SpectrumReport,
        status: str,
        starts: list[LocalSearch],
        evaluations: int,
        robustness: Robustness | None,
        coalescence: Coalescence | None,
        search_resolutions: tuple[int, int],
        robust: float | None,
        seconds: float,
        descent: str = "",
    ) -> TuneResult:
        """Assemble the result from the verified spectrum at ``gain``."""
        alpha = report.spectral_abscissa
        if coalescence is not None:
            alpha = float(coalescence.eigenvalue.real)
        active: list[complex] = []
        if alpha is not None and report.rightmost:
            s = max(report.rate_scale, abs(alpha))
            up = [z for z in report.rightmost if z.imag >= -1e-12 * s]
            active = [z for z in up if z.real >= alpha - 1e-3 * s]
        # several eigenvalues sharing the abscissa (every mode of a wave with a damper) is
        # not a coalescence; an ill-conditioned cluster at the rightmost is
        coalesced = coalescence is not None or report.ill_conditioned
        return cls(
            gain=np.asarray(gain, dtype=float),
            spectral_abscissa=alpha,
            converged=report.converged,
            at_coalescence=bool(coalesced and status == "optimum"),
            active=active,
            report=report,
            starts=starts,
            status=status,
            evaluations=evaluations,
            robustness=robustness,
            coalescence=coalescence,
            search_resolutions=search_resolutions,
            robust=robust,
            seconds=seconds,
            model=model,
            descent=descent,
        )

    # -- text -------------------------------------------------------------------------

    def status_text(self) -> str:
        """One sentence: what was found."""
        if self.status == "extinction":
            return (
                "finite-time extinction at this gain: the error system's spectrum is empty and "
                "its abscissa unbounded below, so no gain does better (no optimum to refine)"
            )
        if self.status == "descending" and self.descent == "empty spectrum":
            return (
                "no optimum located: at the gain below the search's low resolution resolved "
                "no eigenvalue, where the verification finds the abscissa below; the search "
                "stopped there, so the gain is the best found, not an optimum"
            )
        if self.status == "descending":
            return (
                "no optimum located: the local search did not settle within its budget "
                "(every restart of Nelder-Mead still improved the abscissa); the gain below "
                "is the best found, not an optimum: the abscissa may keep falling (toward a "
                "boundary of the gains, or without bound), or the search needs a larger maxiter"
            )
        if self.status == "no decay":
            return (
                "no exponential decay found: at the best gain the spectral abscissa is 0 within "
                "its accuracy; these sensors give no uniform exponential decay at any gain tried"
            )
        if self.coalescence is not None:
            c = self.coalescence
            return (
                f"optimum at a coalescence of {c.size} eigenvalues at {c.eigenvalue.real:.10g}"
                + (f" {c.eigenvalue.imag:+.10g}i" if c.eigenvalue.imag else "")
            )
        return "optimum" + (" at a coalescence of eigenvalues" if self.at_coalescence else "")

    def __str__(self) -> str:
        rep = self.report
        lines = [f"model: {self.model}   sensors C_m = {rep.sensors}"]
        lines.append(f"status: {self.status_text()}")
        lines.append(f"gain L = {self.gain.tolist()}")
        if self.spectral_abscissa is None:
            lines.append("spectral abscissa: unbounded below at this gain")
        else:
            lines.append(
                f"spectral abscissa: {self.spectral_abscissa:.10g}   converged: {self.converged}"
                f"   at coalescence: {self.at_coalescence}"
            )
        if self.robustness is not None:
            lines.append(f"robustness: {self.robustness}")
        p, q = self.search_resolutions
        lines.append(
            f"search: {self.evaluations} evaluations at resolutions {p}, {q}, verified at "
            f"{rep.resolutions[0]}, {rep.resolutions[1]}"
            + (
                ""
                if self.robust is None
                else f"; worst case over ±{100 * self.robust:g} % minimized"
            )
        )
        lines += [f"warning: {w}" for w in rep.warnings]
        return "\n".join(lines)

    def __repr__(self) -> str:
        alpha = "None" if self.spectral_abscissa is None else f"{self.spectral_abscissa:.8g}"
        gain = np.array2string(self.gain, precision=6, separator=", ").replace("\n", "")
        return (
            f"TuneResult(model={self.model!r}, status={self.status!r}, gain={gain[:120]}, "
            f"spectral_abscissa={alpha}, evaluations={self.evaluations})"
        )

    def _repr_html_(self) -> str:
        rows = [
            ("status", self.status_text()),
            ("gain L", str(self.gain.tolist())),
            (
                "spectral abscissa",
                "unbounded below"
                if self.spectral_abscissa is None
                else f"{self.spectral_abscissa:.10g}",
            ),
            ("robustness", "—" if self.robustness is None else str(self.robustness)),
            ("evaluations", str(self.evaluations)),
        ]
        return html_table((), rows, f"{self.model}: tuned gain")

    # -- data -------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the keys of the command-line contract kept)."""
        rep = self.report
        c = self.coalescence
        return {
            "model": self.model,
            "gain": self.gain.tolist(),
            "spectral_abscissa": finite_or_none(self.spectral_abscissa),
            "converged": self.converged,
            "at_coalescence": self.at_coalescence,
            "active": [[z.real, z.imag] for z in self.active],
            "rightmost": [[z.real, z.imag] for z in rep.rightmost],
            "digits": finite_or_none(rep.digits),
            "resolutions": list(rep.resolutions),
            "starts": [s.to_dict() for s in self.starts],
            "warnings": list(rep.warnings),
            "status": self.status,
            "descent": self.descent or None,
            "unbounded_below": rep.unbounded_below,
            "no_decay": self.status == "no decay",
            "evaluations": self.evaluations,
            "search_resolutions": list(self.search_resolutions),
            "robustness": None if self.robustness is None else self.robustness.to_dict(),
            "robust": self.robust,
            "coalescence": None
            if c is None
            else {
                "size": c.size,
                "eigenvalue": [c.eigenvalue.real, c.eigenvalue.imag],
                "residual": c.residual,
            },
            "seconds": self.seconds,
            "spectrum": rep.to_dict(),
        }
