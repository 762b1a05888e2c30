r"""Certified spectra of the design objects: ``Observer.certify`` and ``Plant.certify``.

A mixin of :class:`~phdesign.design.observer.Observer` (as
:mod:`phdesign.design.export` is), and the one function both it and
:meth:`phdesign.Plant.certify` call, :func:`certify_design`: it builds the exact closed
system (:func:`phdesign.numeric.certified.exact_system.closed_system`, the plant's
overrides substituted exactly), asks the converged spectrum for the eigenvalue estimates
a band certificate starts from (and for what it extrapolates above the band, an
assumption's words), and hands both to
:func:`phdesign.numeric.certified.certificate.certify`.  ``phdesign certify`` asks these
methods.  python-flint is imported only here, when a certificate is asked for.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from phdesign.core.errors import CertificateError

if TYPE_CHECKING:  # pragma: no cover - typing only
    import sympy

    from phdesign.design.plant import Plant
    from phdesign.numeric.certified.certificate import Certificate

__all__ = ["ObserverCertify", "certify_design", "require_flint"]


def require_flint() -> None:
    """Refuse with one line when python-flint (the extra ``certify``) is not installed."""
    try:
        import flint  # noqa: F401
    except ImportError:
        raise CertificateError(
            "certificates need python-flint: pip install 'phdesign[certify]'"
        ) from None


def certify_design(
    plant: Plant,
    C_m: sympy.MatrixBase | None,
    L: sympy.MatrixBase | None,
    band: float | None,
    rate: bool,
) -> Certificate:
    """Certify the plant (no ``C_m``) or the error system of ``(C_m, L)`` on ``plant``."""
    require_flint()
    from phdesign.core.checks import positive_number
    from phdesign.numeric.certified.certificate import certify
    from phdesign.numeric.certified.characteristic import characteristic
    from phdesign.numeric.certified.exact_system import closed_system
    from phdesign.numeric.certified.whole_plane import travel_time

    if band is not None:
        positive_number(band, "band")
    system = closed_system(plant.design_model, C_m, L)
    if rate:  # refused before the spectrum's work
        from phdesign.numeric.certified.rate_problem import require_first_order

        require_first_order(system.name, system.order)
    if rate and not system.constant:  # the decay rate alone (no spectrum certificate)
        return certify(system, band=band, rate=rate)
    estimates: list[complex] = []
    beyond = ""
    whole = travel_time(characteristic(system), system.P[0].is_zero_matrix) is not None
    if not whole and band is not None:
        C, gain = (None, None) if C_m is None else _floats(C_m, L)
        report = plant.closed_spectrum(C, gain)
        estimates = [complex(z) for z in report.eigenvalues]
        limit = None if report.branches is None else report.branches.limit
        if limit is not None:
            beyond = f"high-frequency chains whose real parts tend to {limit.limit:.4g}"
    return certify(system, band=band, rate=rate, estimates=estimates, beyond=beyond)


def _floats(C_m: Any, L: Any) -> tuple[Any, Any]:
    from phdesign.design.plant import numeric_matrix

    return numeric_matrix(C_m, "C_m", "certify"), numeric_matrix(L, "L", "certify")


class ObserverCertify:
    """The certificate of :class:`~phdesign.design.observer.Observer` (reads its design)."""

    plant: Plant
    C_m: sympy.ImmutableMatrix

    def certify(self, band: float | None = None, *, rate: bool = False) -> Certificate:
        r"""Prove the spectral abscissa of the error system (and a decay rate with ``rate``).

        The error system is the plant with :math:`\tilde u = -C_m^\top L C_m \tilde y`,
        every number exact.  For strings and other first-order systems with one travel
        time and :math:`P_0 = 0` the certificate covers the whole plane (``band`` is not
        needed); otherwise it covers :math:`|\operatorname{Im}\lambda| \le` ``band``
        (:mod:`phdesign.numeric.certified.certificate`).  ``str()`` of the result is what
        ``phdesign certify`` prints, ``.to_dict()`` the proof file that ``phdesign check``
        re-verifies.

        Raises
        ------
        CertificateError
            Without python-flint, for z-dependent or irrational data, or when a step of the
            proof fails (the message says which).
        """
        self._need_sensors("certify")  # type: ignore[attr-defined]
        L = self._gain("certify")  # type: ignore[attr-defined]
        if L.free_symbols:
            raise CertificateError("certify needs a numeric gain; found a symbolic one")
        return certify_design(self.plant, self.C_m, L, band, rate)
