r"""The one registry of per-method numeric defaults: resolutions, basis, refinement caps.

Every default resolution of the numeric layer is read from here, so that a change of
policy is one edit and the reason for each number stands next to it.  There is one frozen
table per discretization method, with one row per model order N (the last row serves
every higher order):

``GALERKIN``
    ============  =======  ==========  ===========  ======  ========  ==============  =====
    order          degree  first pair  largest      tune    basis     cap (Legendre)  band
    ============  =======  ==========  ===========  ======  ========  ==============  =====
    N = 1              40          20          100      30  legendre  --                330
    N = 2              40          20          110      30  legendre  --                240
    N >= 3             16           8          110      30  scaled    48                110
    ============  =======  ==========  ===========  ======  ========  ==============  =====

``FD`` (staggered finite differences, N = 1 and 2)
    70 nodes per state group (the paper's 140 states for the beam), refinement from 70
    to 240.

Why these numbers:

* ``degree`` (:func:`phdesign.numeric.discretization.registry.discretize` and so ``simulate``):
degree
  40 resolves the low modes of N <= 2 models to ~1e-12; for N >= 3 the weakly imposed
  feedback on high derivative traces makes :math:`E^{-1}A` grow like :math:`p^{4N-3}`
  and degree 16 is where the exact time stepping still keeps its energy balance (degree
  40 loses it, ``tests/test_honesty.py``) while airy's slow modes are resolved to 1e-5.
* ``first pair`` and ``largest``: the spectrum refines p -> 1.5 p from the first
  resolution up to the largest; N >= 3 starts low because its rightmost modes are
  resolved early.  With the plain Legendre basis (``basis="legendre"``) round-off
  grows with the degree for N >= 3, which is why that basis is capped at 48.
* ``band``: the largest resolution the refinement reaches while its band does not reach
  the onset of the principal part (:mod:`phdesign.numeric.spectrum.branches`): a steel
  Timoshenko beam's thickness-shear branch starts at 2.03e5 rad/s, 78 times its rate,
  and needs the pair (153, 230); a resolution of 330 costs about 5 s for n = 4.
* ``tune``: the coarse degree of tuning's resolution pair when the spectrum at L = I
  did not converge (an unconverged start says nothing about a good pair).
* ``basis``: the trace-scaled basis for N >= 3 turns 9 digits into 15 on the airy error
  abscissa (:mod:`phdesign.numeric.discretization.galerkin`); for N <= 2 both bases agree to
  round-off and the Legendre one keeps E well conditioned for any H(z).

Examples
--------
>>> row = defaults_for("galerkin", 3)
>>> row.resolution, row.basis, row.legendre_max
(16, 'scaled', 48)
>>> spectrum_resolutions(2, "galerkin"), spectrum_resolutions(1, "fd")
((20, 110), (70, 240))
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from phdesign.core.errors import NumericError

__all__ = [
    "FD",
    "GALERKIN",
    "METHODS",
    "MethodDefaults",
    "band_resolution",
    "defaults_for",
    "spectrum_resolutions",
]


@dataclass(frozen=True)
class MethodDefaults:
    """Default resolutions of one method for one model order (one row of a table).

    Attributes
    ----------
    method : str
        ``"galerkin"`` or ``"fd"``.
    resolution : int
        Default resolution of :func:`~phdesign.numeric.discretization.registry.discretize` (and so
        of
        simulations and exports): Galerkin degree or finite-difference nodes per group.
    spectrum_start, spectrum_max : int
        First and largest resolution of the spectrum's refinement.
    tune_fallback : int
        Coarse resolution of tuning's pair when the spectrum at L = I did not converge.
    basis : str or None
        Galerkin basis (``"scaled"`` or ``"legendre"``); None for finite differences.
    legendre_max : int or None
        Largest refinement resolution when the plain Legendre basis is forced on this
        order (round-off grows with the degree); None when no cap applies.
    band_max : int
        Largest refinement resolution while the band does not reach the onset of the
        principal part (:mod:`phdesign.numeric.spectrum.branches`); at least ``spectrum_max``.
    resolved_rtol : float
        Relative drift under which an eigenvalue counts as resolved between two
        resolutions (spectral Galerkin 1e-6; second-order finite differences 1e-2).
    abscissa_tol : float
        Agreement of the spectral abscissa that counts as converged (1e-10; 1e-3).
    """

    method: str
    resolution: int
    spectrum_start: int
    spectrum_max: int
    tune_fallback: int
    basis: str | None = None
    legendre_max: int | None = None
    band_max: int = 0
    resolved_rtol: float = 1e-6
    abscissa_tol: float = 1e-10


GALERKIN: Mapping[int, MethodDefaults] = MappingProxyType(
    {
        1: MethodDefaults("galerkin", 40, 20, 100, 30, "legendre", band_max=330),
        2: MethodDefaults("galerkin", 40, 20, 110, 30, "legendre", band_max=240),
        3: MethodDefaults("galerkin", 16, 8, 110, 30, "scaled", legendre_max=48, band_max=110),
    }
)
FD: Mapping[int, MethodDefaults] = MappingProxyType(
    {
        1: MethodDefaults(
            "fd", 70, 70, 240, 70, band_max=240, resolved_rtol=1e-2, abscissa_tol=1e-3
        ),
        2: MethodDefaults(
            "fd", 70, 70, 240, 70, band_max=240, resolved_rtol=1e-2, abscissa_tol=1e-3
        ),
    }
)
METHODS: Mapping[str, Mapping[int, MethodDefaults]] = MappingProxyType(
    {"galerkin": GALERKIN, "fd": FD}
)


def defaults_for(method: str, order: int) -> MethodDefaults:
    """Return the row of ``method``'s table for a model of order ``order``.

    Orders beyond a table's last row use that row (the Galerkin N >= 3 row); finite
    differences exist for N = 1 and 2 only, and higher orders get the N = 2 row, so that
    the refusal comes from the method itself with its own message.
    """
    try:
        table = METHODS[method]
    except KeyError:
        raise NumericError(
            f"unknown discretization method {method!r}; expected one of {tuple(METHODS)}"
        ) from None
    return table[min(max(int(order), 1), max(table))]


def band_resolution(order: int, method: str, basis: str | None = None) -> int:
    """Return the largest resolution the refinement reaches for a band short of the onset.

    Forcing the plain Legendre basis on N >= 3 caps it as it caps the spectrum.
    """
    row = defaults_for(method, order)
    top = spectrum_resolutions(order, method, basis)[1]
    if basis == "legendre" and row.legendre_max is not None:
        return top
    return max(row.band_max, top)


def spectrum_resolutions(order: int, method: str, basis: str | None = None) -> tuple[int, int]:
    """Return the spectrum's first and largest resolution for ``method`` and ``order``.

    ``basis`` is the Galerkin basis actually used (default: the table's); forcing the
    plain Legendre basis on N >= 3 lowers the cap to ``legendre_max``.
    """
    row = defaults_for(method, order)
    top = row.spectrum_max
    if basis == "legendre" and row.legendre_max is not None:
        top = row.legendre_max
    return row.spectrum_start, top
