r"""The convergence verdict of a figure computed at increasing resolutions.

A noise figure is a number of the PDE only if the discretizations agree on it.  Given its
values :math:`f_0, \dots, f_m` at resolutions :math:`p_0 < \dots < p_m`:

- it has **converged** when the last two agree,
  :math:`|f_m - f_{m-1}| \le \mathrm{tol} \cdot |f_m|`; its digits are
  :math:`-\log_{10}(|f_m - f_{m-1}| / |f_m|)`;
- it **diverges** when, over the last three, it grows by more than its tolerance at each
  step, :math:`f_k - f_{k-1} > \mathrm{tol} \cdot |f_k|` for :math:`k = m-1, m`, and its
  growth per unit of :math:`\log p` does not slow down,
  :math:`d_k = (f_k - f_{k-1}) / \log(p_k / p_{k-1})`, :math:`d_m \ge 0.95\, d_{m-1} > 0`.
  Increments below the tolerance are the figure's own noise (round-off, or the last digits
  of a converged value), not growth: a value that agrees to 13 digits at every resolution
  but whose comparison pair disagrees is *not converged*, never diverging.
  A convergent sequence :math:`f_\infty - c p^{-s}` has :math:`d_m / d_{m-1} =
  (p_{m-1}/p_m)^{s} < 1`; a divergent one :math:`c p^r` or :math:`c \log p` has a ratio
  :math:`\ge 1`.  The local growth exponent :math:`r = \log(f_m/f_{m-1}) / \log(p_m/p_{m-1})`
  (f grows like :math:`p^r`) is reported with it;
- otherwise it is **not converged** at these resolutions.

A figure that diverges is never reported as a number.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["DIVERGENCE_RATIO", "Estimate", "settle"]

#: Ratio of successive growth rates (per unit log p) at or above which a figure diverges.
DIVERGENCE_RATIO = 0.95


@dataclass(frozen=True, repr=False)
class Estimate:
    """One figure at several resolutions and its verdict (module docstring).

    Attributes
    ----------
    name : str
    values : tuple of float
        The figure at each resolution (``inf`` where it does not exist).
    resolutions : tuple of int
    converged, diverges : bool
    digits : float or None
        Agreeing digits of the last two values.
    growth : float or None
        Local exponent r (the figure grows like p^r) of the last pair, when it diverges.
    """

    name: str
    values: tuple[float, ...]
    resolutions: tuple[int, ...]
    converged: bool
    diverges: bool
    digits: float | None
    growth: float | None = None

    @property
    def value(self) -> float | None:
        """The finest value when converged, else None (a diverging figure has no value)."""
        return self.values[-1] if self.converged else None

    def status(self) -> str:
        """One phrase: ``converged (8.1 digits)``, ``diverges (grows like p^0.86)``, ..."""
        if self.converged:
            return f"converged ({self.digits:.1f} digits)" if self.digits is not None else "exact"
        if self.diverges:
            return f"diverges (grows like p^{self.growth:.2f})" if self.growth else "diverges"
        if self.digits is None:
            return "not converged"
        return f"not converged ({max(self.digits, 0.0):.1f} digits)"

    def rounded(self, value: float | None = None) -> str | None:
        """Return a figure that did not converge, to the digits that agree: ``0.6095``.

        ``value`` is a function of the finest value with the same relative accuracy (the
        RMS, its square root, has at least as many digits); None when the figure
        converged, diverges, or has no finite value or no agreeing digits to show.
        """
        if self.converged or self.diverges or not self.values or self.digits is None:
            return None
        top = self.values[-1] if value is None else value
        if not math.isfinite(top):
            return None
        return f"{top:.{min(10, max(1, math.ceil(self.digits)))}g}"

    def approximate(self) -> str | None:
        """``≈ 0.6095, 3.6 digits, not converged`` (see :meth:`rounded`), else None."""
        shown = self.rounded()
        if shown is None or self.digits is None:
            return None
        return f"≈ {shown}, {max(self.digits, 0.0):.1f} digits, not converged"

    def __str__(self) -> str:
        """``w(1) = 0.1347085719   converged (8.5 digits) (0.1347, ... at resolutions ...)``."""
        values = ", ".join(f"{v:.6g}" for v in self.values)
        at = ", ".join(str(r) for r in self.resolutions)
        shown = self.approximate()
        if shown is not None:
            head = f"{self.name} {shown}"
        elif self.value is None:
            head = f"{self.name}   {self.status()}"
        else:
            head = f"{self.name} = {self.value:.10g}   {self.status()}"
        return head + (f" ({values} at resolutions {at})" if at else "")

    def __repr__(self) -> str:
        value = None if self.value is None else float(f"{self.value:.10g}")
        return (
            f"Estimate(name={self.name[:60]!r}, value={value}, status={self.status()!r}, "
            f"resolutions={self.resolutions[-6:]})"
        )

    def _repr_html_(self) -> str:
        from phdesign.core.text import html_table

        rows = [[str(r), f"{v:.12g}"] for r, v in zip(self.resolutions, self.values, strict=True)]
        return html_table(["resolution", self.name], rows, footer=self.status())

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (non-finite values become null)."""
        return {
            "value": finite_or_none(self.value),
            "converged": self.converged,
            "diverges": self.diverges,
            "digits": finite_or_none(self.digits),
            "growth": finite_or_none(self.growth),
            "values": [finite_or_none(v) for v in self.values],
            "resolutions": list(self.resolutions),
        }


def finite_or_none(value: float | None) -> float | None:
    """``float(value)``, or None for None, NaN and infinities (strict JSON)."""
    if value is None or not math.isfinite(value):
        return None
    return float(value)


def settle(
    name: str,
    values: Sequence[float],
    resolutions: Sequence[int],
    tol: float,
    pair: tuple[float, float] | None = None,
) -> Estimate:
    """Return the :class:`Estimate` of a figure (the rule of the module docstring).

    Parameters
    ----------
    name : str
    values, resolutions : sequences of equal length
    tol : float
        Relative agreement required of the last two values.
    pair : (coarse, fine), optional
        The two values to compare instead of the last two of ``values`` (a figure whose
        comparison needs both resolutions on a common footing, such as a peak over a band
        that only the finer pair resolves).

    Examples
    --------
    >>> settle("E[H]", [2.0, 3.0, 4.5], [20, 30, 45], 1e-6).status()  # linear in p
    'diverges (grows like p^1.00)'
    >>> settle("w(1)", [0.1347085750, 0.1347085724], [20, 30], 1e-6).status()
    'converged (7.7 digits)'
    >>> settle("g", [1, 1 + 1e-14, 1 + 3e-14], [30, 45, 68], 1e-6, pair=(1, 1 + 2e-6)).status()
    'not converged (5.7 digits)'
    """
    f = [float(v) for v in values]
    p = [int(r) for r in resolutions]
    if len(f) != len(p):
        raise ValueError("values and resolutions must have the same length")  # internal
    coarse, fine = pair if pair is not None else (f[-2], f[-1]) if len(f) >= 2 else (None, None)
    digits: float | None = None
    converged = False
    if coarse is not None and fine is not None and math.isfinite(coarse + fine):
        gap = abs(fine - coarse)
        scale = abs(fine)
        converged = gap <= tol * scale or gap == 0.0
        digits = 16.0 if gap == 0.0 else min(16.0, -math.log10(gap / scale)) if scale else None
    diverges = False
    growth = None
    if not converged and len(f) >= 3:
        if any(not math.isfinite(v) for v in f[-2:]):
            diverges = True
        else:
            last = (len(f) - 2, len(f) - 1)
            rates = [(f[k] - f[k - 1]) / math.log(p[k] / p[k - 1]) for k in last]
            # growth is evidence only where it exceeds the figure's own accuracy: two
            # round-off increments (1e-14 on a value of 1) are not a trend
            visible = all(f[k] - f[k - 1] > tol * abs(f[k]) for k in last)
            diverges = (
                visible and rates[0] > 0 and rates[1] >= DIVERGENCE_RATIO * rates[0] and f[-2] > 0
            )
            if diverges:
                growth = math.log(f[-1] / f[-2]) / math.log(p[-1] / p[-2])
    return Estimate(name, tuple(f), tuple(p), bool(converged), bool(diverges), digits, growth)
