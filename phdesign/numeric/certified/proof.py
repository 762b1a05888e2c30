r"""The proof file: every ingredient of a certificate, as exact text.

A proof file is JSON (written with :func:`phdesign.core.files` rules by the command line)
with the sections

``format``, ``version``
    ``"phdesign-proof"``, 1.
``system``
    The exact closed system (:meth:`~.exact_system.ExactClosedSystem.to_dict`): the
    :math:`P_k`, :math:`H`, interval, ports :math:`U, Y`, closing gain :math:`G` and
    boundary rows :math:`U + GY`, every number ``"p/q"``.
``characteristic``
    How :math:`\Delta` is built (:meth:`~.characteristic.Characteristic.to_dict`); the
    checker re-derives it from ``system`` instead of reading it.
``band``
    The rectangle (``left``, ``right``, ``omega``), its ``count`` of zeros, its upper
    half ``path`` as ``[x0, y0, x1, y1, label]`` rows (exact endpoints; ``label`` the
    half-plane of :data:`~.contour.LABELS`) with the flint enclosure as text beside each,
    and the ``enclosures`` (centre, half-width, count, symmetric, path).
``whole_plane``
    For an exponential polynomial (:mod:`.whole_plane`): the polynomial in
    :math:`\zeta = e^{\lambda\tau}` and its root squares.
``rate``
    The decay-rate proof (``to_json()`` of the rate prover), when asked for.
``claim``
    ``abscissa_interval`` (``["p/q", "p/q"]`` or ``null``), ``band`` (``"p/q"`` or
    ``null`` for the whole plane).
``assumptions``
    What the claim assumes, in words.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from phdesign.numeric.certified.band import BandCount
from phdesign.numeric.certified.characteristic import fraction_text
from phdesign.numeric.certified.contour import Segment
from phdesign.numeric.certified.enclosure import Enclosure

__all__ = ["FORMAT", "VERSION", "band_section", "path_rows"]

FORMAT = "phdesign-proof"
VERSION = 1


def path_rows(segments: Sequence[Segment]) -> list[list[Any]]:
    """Return the segments as ``[x0, y0, x1, y1, label, enclosure]`` rows."""
    return [[*(fraction_text(v) for v in (*s.start, *s.end)), s.label, s.value] for s in segments]


def _enclosure(e: Enclosure) -> dict[str, Any]:
    return {
        "center": [fraction_text(e.center[0]), fraction_text(e.center[1])],
        "radius": fraction_text(e.radius),
        "count": e.count,
        "symmetric": e.symmetric,
        "path": path_rows(e.segments),
    }


def band_section(result: BandCount) -> dict[str, Any]:
    """Return the ``band`` section of a proof file."""
    return {
        "omega": fraction_text(result.band),
        "left": fraction_text(result.left),
        "right": fraction_text(result.right),
        "count": result.count,
        "path": path_rows(result.segments),
        "enclosures": [_enclosure(e) for e in result.enclosures],
        "rightmost": [result.enclosures.index(e) for e in result.rightmost],
    }
