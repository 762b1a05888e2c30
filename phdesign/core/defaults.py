"""Defaults of the exported observer, one row shared by every entry point.

:func:`phdesign.numeric.sampled.export.export_observer`,
:func:`phdesign.numeric.sampled.order.select_order`,
:meth:`phdesign.Observer.export` and ``phdesign export`` read their defaults here, so a
change of policy is one edit.  The module imports nothing: the command line builds its
parser from it without loading the numeric layer (``phdesign classify`` starts fast).

Examples
--------
>>> EXPORT.sampler, EXPORT.tol, EXPORT.output_tol, EXPORT.t_end
('average', 1e-06, 0.001, 5.0)
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EXPORT", "ExportDefaults"]


@dataclass(frozen=True)
class ExportDefaults:
    """Defaults of the exported observer, shared by the library, the design object and the CLI.

    Attributes
    ----------
    sampler : str
        ``"average"``: the mean of the sensors over each period, whose sampled error system
        is dissipative for every period (:mod:`phdesign.numeric.sampled.period_maps`);
        point samples alias a boundary velocity's unresolved content.
    tol : float
        Relative accuracy of the rightmost error eigenvalues the order must reproduce.
    output_tol : float
        Error floor of the performance outputs, relative to their peak.
    t_end : float
        Length (s) of the performance and verification runs: five seconds hold several
        periods of the paper's beam's slowest modes and its error's decay to the floor.
    """

    sampler: str = "average"
    tol: float = 1e-6
    output_tol: float = 1e-3
    t_end: float = 5.0


#: The one row of export defaults (:class:`ExportDefaults`).
EXPORT = ExportDefaults()
