r"""The modal table: the resolved modes of a spectrum by frequency, as an engineer reports them.

A spectrum report (:class:`~phdesign.numeric.spectrum.report.SpectrumReport`) lists its
*rightmost* eigenvalues, the ones that decide the abscissa.  A structural engineer reads
the modes in order of frequency instead.  :func:`modal_table` takes every eigenvalue of the
report's finer resolution that the drift test resolved (or kept as a member of a cluster
near a coalescence), one per conjugate pair (:math:`\operatorname{Im}\lambda \ge 0`, a
real eigenvalue once), and orders them by natural frequency.  For
:math:`\lambda = -\zeta\omega_n \pm i\omega_n\sqrt{1-\zeta^2}` (a mode of
:math:`\ddot q + 2\zeta\omega_n \dot q + \omega_n^2 q = 0`):

.. math::

    \omega_n = |\lambda|, \qquad f = \frac{\omega_n}{2\pi}, \qquad
    \zeta = -\frac{\operatorname{Re}\lambda}{|\lambda|}, \qquad
    \text{decay rate} = -\operatorname{Re}\lambda, \qquad
    \omega_d = \operatorname{Im}\lambda,

so a real eigenvalue has :math:`\zeta = 1` and the mode :math:`\lambda = 0` none.  The
decay rate carries the accuracy of the real part (its drift between the resolutions, at
least the round-off floor: :mod:`phdesign.numeric.spectrum.drift`); a real part within its
accuracy of 0 is printed as 0, never as a growth, and its damping ratio as 0.

The block a mode belongs to is the report's system: ``"plant"`` for the plant with
u = 0, ``"error"`` for the observer error system x̃ = x − x̂.  The report of the error
system alone cannot tell more; by separation the plant and observer together (in
(x, x̃), block-triangular) have the error system's modes and the plant's own, which the
plant's report lists.  Units: the model's time unit (``[units] t``) when it states one
(rad/s and Hz for seconds), else the model's own unit of time.

Examples
--------
>>> import phdesign as phd
>>> table = phd.Plant(phd.load("euler-bernoulli")).spectrum().modes(count=2)
>>> [round(m.natural_frequency, 4) for m in table.modes]  # 1.8751², 4.6941²
[3.516, 22.0345]
>>> [round(m.damping_ratio, 4) for m in table.modes]  # d / (2 ρ ω): 0.2 / (2 ω)
[0.0284, 0.0045]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from phdesign.core.checks import positive_int
from phdesign.core.text import html_table, text_table

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.numeric.spectrum.report import SpectrumReport

__all__ = ["ModalTable", "Mode", "modal_table"]

#: |Im λ| below this, relative to max(rate, |λ|), is a real eigenvalue.
REAL_AXIS = 1e-12


@dataclass(frozen=True)
class Mode:
    """One mode of a modal table (module docstring for the formulas).

    Attributes
    ----------
    eigenvalue : complex
        λ, with Im λ >= 0.
    natural_frequency, frequency_hz, damped_frequency : float
        ω_n = |λ|, ω_n / 2π and Im λ.
    damping_ratio : float or None
        ζ = −Re λ / |λ| (0 when Re λ is 0 within its accuracy; None for λ = 0).
    decay_rate, decay_accuracy : float
        −Re λ and the accuracy of Re λ.
    resolved : bool
        Agrees between the two resolutions (else kept: a member of a cluster or
        ill-conditioned, near a coalescence).
    condition : float
        Energy-norm condition number.
    block : str
        ``"plant"`` or ``"error"`` (module docstring).
    """

    eigenvalue: complex
    natural_frequency: float
    frequency_hz: float
    damped_frequency: float
    damping_ratio: float | None
    decay_rate: float
    decay_accuracy: float
    resolved: bool
    condition: float
    block: str

    @property
    def zero_decay(self) -> bool:
        """Re λ is 0 within its accuracy (round-off on a lossless mode)."""
        return abs(self.decay_rate) <= self.decay_accuracy

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (strict JSON: non-finite numbers are ``null``)."""
        from phdesign.numeric.spectrum.report import finite_or_none

        return {
            "eigenvalue": [
                finite_or_none(self.eigenvalue.real),
                finite_or_none(self.eigenvalue.imag),
            ],
            "natural_frequency": finite_or_none(self.natural_frequency),
            "frequency_hz": finite_or_none(self.frequency_hz),
            "damped_frequency": finite_or_none(self.damped_frequency),
            "damping_ratio": finite_or_none(self.damping_ratio),
            "decay_rate": finite_or_none(self.decay_rate),
            "decay_accuracy": finite_or_none(self.decay_accuracy),
            "resolved": self.resolved,
            "condition": finite_or_none(self.condition),
            "block": self.block,
        }


def _units(time_unit: str | None) -> dict[str, str | None]:
    """Return the units of ω, f and the decay rate for the model's time unit."""
    if not time_unit:
        return {"time": None, "angular_frequency": None, "frequency": None, "rate": None}
    return {
        "time": time_unit,
        "angular_frequency": f"rad/{time_unit}",
        "frequency": "Hz" if time_unit == "s" else f"1/{time_unit}",
        "rate": f"1/{time_unit}",
    }


@dataclass(frozen=True)
class ModalTable:
    """The first modes of a spectrum by frequency (:func:`modal_table`).

    Attributes
    ----------
    modes : tuple of Mode
    count : int
        How many were asked for (``len(modes)`` is smaller when fewer are resolved).
    model, system, method : str
        As the spectrum report says.
    resolutions : tuple of int
        The report's resolution pair.
    time_unit : str or None
        The model's unit of time, when it states one.
    n_available : int
        Resolved (or kept) modes with Im λ >= 0 at the report's pair.
    """

    modes: tuple[Mode, ...]
    count: int
    model: str
    system: str
    method: str
    resolutions: tuple[int, int]
    time_unit: str | None
    n_available: int

    @property
    def units(self) -> dict[str, str | None]:
        """Units of time, ω, f and decay rate (None where the model states none)."""
        return _units(self.time_unit)

    def _cells(self) -> tuple[list[str], list[list[str]]]:
        u = self.units

        def head(label: str, key: str) -> str:
            return f"{label} [{u[key]}]" if u[key] else label

        headers = [
            "mode",
            head("ω_n", "angular_frequency"),
            head("f", "frequency"),
            "ζ",
            head("decay rate", "rate"),
            "resolved",
            "condition",
            "block",
        ]
        rows = []
        for i, m in enumerate(self.modes, 1):
            zeta = "—" if m.damping_ratio is None else f"{m.damping_ratio:.4g}"
            decay = "0" if m.zero_decay else f"{m.decay_rate:.6g}"
            rows.append(
                [
                    str(i),
                    f"{m.natural_frequency:.8g}",
                    f"{m.frequency_hz:.6g}",
                    zeta,
                    f"{decay} ± {m.decay_accuracy:.2g}",
                    "yes" if m.resolved else "no (kept)",
                    f"{m.condition:.3g}",
                    m.block,
                ]
            )
        return headers, rows

    def notes(self) -> list[str]:
        """Return what a reader needs beside the rows: units, shortfall, the blocks."""
        out = []
        if not self.time_unit:
            out.append("the model states no unit of time: frequencies are per unit of its time")
        if len(self.modes) < self.count:
            out.append(
                f"only {len(self.modes)} resolved modes at resolutions "
                f"{self.resolutions[0]}, {self.resolutions[1]} ({self.count} asked for)"
            )
        if any(m.block == "error" for m in self.modes):
            out.append(
                "these are the error system's modes (x̃ = x − x̂); with the plant, the observer "
                "adds them to the plant's own (separation), which the plant's table lists"
            )
        return out

    def __str__(self) -> str:
        lines = [
            f"model: {self.model}   system: {self.system}   method: {self.method}   "
            f"resolutions {self.resolutions[0]}, {self.resolutions[1]}",
            "modes by natural frequency: ω_n = |λ|, f = ω_n/2π, ζ = −Re λ/|λ|, "
            "decay rate = −Re λ (± its accuracy)",
        ]
        headers, rows = self._cells()
        lines += text_table(headers, rows)
        lines += [f"note: {n}" for n in self.notes()]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"ModalTable(model={self.model!r}, system={self.system!r}, "
            f"modes={len(self.modes)}, resolutions={self.resolutions})"
        )

    def _repr_html_(self) -> str:
        headers, rows = self._cells()
        return html_table(
            headers,
            rows,
            f"{self.model}: modes of the {self.system}",
            "; ".join(self.notes()) or None,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (the ``phdesign modes --json`` output)."""
        return {
            "model": self.model,
            "system": self.system,
            "method": self.method,
            "resolutions": list(self.resolutions),
            "count": self.count,
            "n_available": self.n_available,
            "units": self.units,
            "modes": [m.to_dict() for m in self.modes],
            "notes": self.notes(),
        }


def _block(system: str) -> str:
    return "plant" if system.startswith("plant") else "error"


def modal_table(report: SpectrumReport, count: int | None = None) -> ModalTable:
    """Return the first ``count`` modes of ``report`` by natural frequency (module docstring).

    Parameters
    ----------
    report : SpectrumReport
    count : int, optional
        How many modes (default: the number of rightmost eigenvalues the report lists,
        at least 6).

    Raises
    ------
    NumericError
        ``count`` is not a positive integer.
    """
    count = max(6, len(report.rightmost)) if count is None else positive_int(count, "count")
    lam = np.asarray(report.eigenvalues, dtype=complex)
    keep = np.asarray(report.resolved, dtype=bool) | np.asarray(report.kept, dtype=bool)
    keep &= np.isfinite(lam)
    size = np.maximum(report.rate_scale, np.abs(lam))
    real = np.abs(lam.imag) <= REAL_AXIS * size
    keep &= real | (lam.imag > 0)
    idx = np.flatnonzero(keep)
    idx = idx[np.lexsort((lam.imag[idx], np.abs(lam[idx])))]
    modes = tuple(_mode(report, int(i), bool(real[i])) for i in idx[:count])
    return ModalTable(
        modes=modes,
        count=int(count),
        model=report.model,
        system=report.system,
        method=report.method,
        resolutions=report.resolutions,
        time_unit=report.time_unit,
        n_available=int(idx.size),
    )


def _mode(report: SpectrumReport, i: int, real: bool) -> Mode:
    """Return the mode of eigenvalue ``i`` of ``report`` (a real one when ``real``)."""
    z = complex(report.eigenvalues[i])
    if real:
        z = complex(z.real, 0.0)
    w = abs(z)
    accuracy = report.real_accuracy[i] if len(report.real_accuracy) else math.nan
    accuracy = float(accuracy) if np.isfinite(accuracy) else 0.0
    condition = float(report.condition_all[i]) if len(report.condition_all) else 1.0
    zero = abs(z.real) <= accuracy
    zeta = None if w == 0 else (0.0 if zero else -z.real / w)
    return Mode(
        eigenvalue=z,
        natural_frequency=w,
        frequency_hz=w / (2 * math.pi),
        damped_frequency=z.imag,
        damping_ratio=zeta,
        decay_rate=-z.real,
        decay_accuracy=accuracy,
        resolved=bool(report.resolved[i]),
        condition=condition,
        block=_block(report.system),
    )
