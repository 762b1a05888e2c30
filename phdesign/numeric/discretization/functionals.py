r"""Performance outputs: linear functionals of the state whose estimation error is scored.

A performance output is a linear functional :math:`z = c(x)` of the state; the noise
figures report the steady-state variance of its estimation error
:math:`\tilde z = c(x) - c(\hat x) = c(\tilde x)`.  Three kinds:

``"w(z0)"`` (:func:`displacement_at`)
    The model's physical displacement at a point (the beam's deflection
    :math:`w(z_0) = \int_a^{z_0} (z_0 - s)\, x_2(s)\, ds`, two integrations of the
    curvature from the clamped end); needs a model that defines one.
``"rotation(1)"`` (:func:`displacement_at` too)
    A named field of the model (``[fields.rotation]``: a linear combination of state
    components and their antiderivatives, :mod:`phdesign.symbolic.fields`) at a point,
    e.g. the Timoshenko beam's rotation :math:`\phi(z_0) = \int_a^{z_0} x_3\, ds`.
``"e1(1)"``, ``"(e1(0) - e2(0))/sqrt(2)"`` (:func:`trace_functional`)
    A combination of boundary traces of the efforts, in the model-file syntax.
``"x2: sin(pi*z)"`` (:func:`integral_functional`)
    :math:`\int_a^b \sum_i w_i(z)\, x_i(z)\, dz` for weights given per state component,
    in the initial-state syntax (``"x1: 1, x2: z"`` weighs two components).

On a discretization each becomes a row ``c`` with :math:`z = c\, \hat e`
(:meth:`Functional.row`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.polynomial import legendre as leg

from phdesign.core.cache import OwnerCache
from phdesign.core.errors import NumericError, ParameterError
from phdesign.core.limits import MAX_CACHE_BYTES, MAX_CACHED_ROWS
from phdesign.core.text import did_you_mean
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.inputs import initial_state_function, trace_row

__all__ = [
    "Functional",
    "default_performance",
    "displacement_at",
    "disturbance_matrix",
    "field_names",
    "integral_functional",
    "parse_functional",
    "parse_functionals",
    "performance_functional",
    "trace_functional",
]

_DISPLACEMENT = re.compile(r"\s*(?P<field>[^\W\d]\w*)\s*\((?P<point>[^()]*)\)\s*\Z")

#: The displacement rows of each discretization (a Legendre-Vandermonde row of degree 159
#: each, about 1 ms): the noise figures read them at every call.
_ROWS = OwnerCache("displacement rows", entries=MAX_CACHED_ROWS, nbytes=MAX_CACHE_BYTES)


@dataclass(frozen=True)
class Functional:
    """A named linear functional of the state (see the module docstring).

    Attributes
    ----------
    name : str
        How reports name it: ``"w(1)"``, ``"e1(1)"``, ``"int(x2: sin(pi*z))"``.
    kind : {"displacement", "trace", "integral", "sum"}
    point : float or None
        The point of a displacement or named field.
    field_name : str
        ``"w"`` for the displacement, else the name of a field of ``[fields.<name>]``.
    trace : ndarray or None
        The row over the trace vector v of a trace combination.
    weight : callable or None
        ``weight(z) -> (m, n)`` of an integral (weights on the state components).
    parts : tuple of (Functional, float)
        The terms of a sum (a ``[performance]`` output such as ``integral(e1) + e1(1)``).
    """

    name: str
    kind: str
    point: float | None = None
    field_name: str = "w"
    trace: np.ndarray | None = field(default=None, compare=False, repr=False)
    weight: Callable[[np.ndarray], np.ndarray] | None = field(
        default=None, compare=False, repr=False
    )
    parts: tuple[tuple[Functional, float], ...] = field(default=(), compare=False, repr=False)

    def row(self, d: DiscretePHS) -> np.ndarray:
        """Return ``c`` with the functional equal to ``c @ ê`` on the discretization ``d``.

        A displacement's row is built once per discretization and point, an integral's
        against a weight with a ``key`` (a :class:`~phdesign.numeric.inputs.Profile`) once
        per discretization and weight, and shared (read-only).
        """
        if self.kind == "displacement":
            basis = _basis(d, self.field_name, self.name)
            point = self.point
            build = lambda: _read_only(basis(np.array([point])))  # noqa: E731
            return _ROWS.get(d, ("displacement", self.field_name, point), build)
        if self.kind == "trace":
            T = d.info.get("T")
            if T is None or self.trace is None:
                raise NumericError(
                    f"{self.name}: boundary traces need the trace map of the Galerkin "
                    f"discretization; the {d.method!r} method has none (use galerkin)"
                )
            return np.asarray(self.trace @ T, dtype=float)
        if self.kind == "integral" and self.weight is not None:
            weight = self.weight
            key = getattr(weight, "key", None)  # a Profile: the same weight, the same row
            if key is None:
                return _integral_row(d, weight)
            build = lambda: _read_only(_integral_row(d, weight)[None, :])  # noqa: E731
            return _ROWS.get(d, ("integral", key), build)
        if self.kind == "sum":
            return np.asarray(sum(c * f.row(d) for f, c in self.parts))
        raise NumericError(f"unknown kind of functional {self.kind!r}")  # pragma: no cover


def _basis(d: DiscretePHS, name: str, label: str) -> Callable[[np.ndarray], np.ndarray]:
    """Return the rows of the field ``name`` (``"w"``: the displacement) on a discretization."""
    if name == "w":
        if d.displacement_basis is None:
            raise NumericError(
                f"{label}: the model {d.model.name!r} defines no displacement; "
                "give a trace or an integral of a state component instead"
            )
        return d.displacement_basis
    spec = d.model.field_spec(name)
    if spec is None or d.field_basis is None:
        raise NumericError(f"{label}: the model {d.model.name!r} defines no field {name!r}")
    return d.field_basis(spec)


def _read_only(rows: np.ndarray) -> np.ndarray:
    """Return the first row of ``rows`` as a read-only float array (a shared cache entry)."""
    row = np.array(rows[0], dtype=float)
    row.flags.writeable = False
    return row


def field_names(nm: NumericModel) -> tuple[str, ...]:
    """Return the fields a point output may name: ``w`` (with a displacement), then the model's."""
    return (("w",) if nm.displacement is not None else ()) + tuple(name for name, _ in nm.fields)


def displacement_at(nm: NumericModel, point: float | str, name: str = "w") -> Functional:
    """Return the displacement ``w(point)``, or the named field ``name(point)``.

    Raises
    ------
    NumericError
        The model defines no displacement (no such field), or the point is not a number
        of [a, b].
    """
    a, b = nm.interval
    text = str(point).strip()
    value = {"a": a, "b": b}.get(text)
    if value is None:
        try:
            value = float(text)
        except ValueError:
            raise NumericError(
                f"displacement point: expected a number in [{a:g}, {b:g}]; found {text!r}"
            ) from None
    if not math.isfinite(value) or not a <= value <= b:
        raise NumericError(
            f"displacement point {text} is outside the interval [{a:g}, {b:g}]; "
            "expected a point of it"
        )
    if name != "w" and nm.field_spec(name) is None:
        known = field_names(nm)
        raise NumericError(
            f"{name}({text}): the model {nm.name!r} defines no field {name!r}"
            f"{did_you_mean(name, known)}; its fields are {', '.join(known) or 'none'}"
        )
    if nm.displacement is None and name == "w":
        raise NumericError(
            f"w({text}): the model {nm.name!r} defines no displacement; give a boundary "
            "trace (e.g. e1(1)) or an integral of a state component (e.g. 'x2: 1') instead"
        )
    return Functional(f"{name}({value:g})", "displacement", point=value, field_name=name)


def trace_functional(nm: NumericModel, text: str, model: Any = None) -> Functional:
    """Return a combination of boundary traces, e.g. ``"e1(1)"`` (parsed by the bridge)."""
    return Functional(" ".join(str(text).split()), "trace", trace=trace_row(text, nm, model))


def integral_functional(nm: NumericModel, text: str, model: Any = None) -> Functional:
    """Return the integral of state components against weights, e.g. ``"x2: sin(pi*z)"``."""
    key = str(text).split(":", 1)[0].strip()
    efforts = {f"e{i + 1}" for i in range(nm.size)}
    if key in efforts:
        raise ParameterError(
            f"integral {text!r}: {key!r} is an effort; weigh state components "
            f"({', '.join(f'x{i + 1}' for i in range(nm.size))} or the model's state names)"
        )
    weight = initial_state_function(text, nm, model=model, what="integral weight")
    return Functional(f"int({' '.join(str(text).split())})", "integral", weight=weight)


def parse_functional(text: str, nm: NumericModel, model: Any = None) -> Functional:
    """Read a performance output: ``"w(1)"``, a named field, a trace, or ``"x2: weight"``.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> beam = load_builtin("euler-bernoulli")
    >>> [parse_functional(t, to_numeric(beam), beam).name for t in ("w(1)", "e1(1)", "x2: 1")]
    ['w(1)', 'e1(1)', 'int(x2: 1)']
    """
    if not isinstance(text, str) or not text.strip():
        raise NumericError(f"performance output: expected text like 'w(1)'; found {text!r}")
    match = _DISPLACEMENT.match(text)
    if match and not re.fullmatch(r"e[0-9]+", match.group("field")):
        return displacement_at(nm, match.group("point"), match.group("field"))
    if ":" in text:
        return integral_functional(nm, text, model)
    return trace_functional(nm, text, model)


def parse_functionals(
    items: Sequence[Functional | str] | None, nm: NumericModel, model: Any = None
) -> tuple[Functional, ...]:
    """Read a list of performance outputs; ``None`` gives :func:`default_performance`."""
    if items is None:
        return default_performance(nm)
    if isinstance(items, (str, Functional)) or not isinstance(items, Iterable):
        items = [items]  # one output; a non-text one is refused by parse_functional
    out = tuple(
        item if isinstance(item, Functional) else parse_functional(item, nm, model)
        for item in items
    )
    names = [f.name for f in out]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise NumericError(f"performance outputs: {', '.join(repeated)} given twice")
    return out


def default_performance(nm: NumericModel) -> tuple[Functional, ...]:
    """Return the displacement at b when the model defines one, else no output."""
    if nm.displacement is None:
        return ()
    return (displacement_at(nm, "b"),)


def performance_functional(
    nm: NumericModel,
    name: str,
    weight: Callable[[np.ndarray], np.ndarray] | None,
    trace: np.ndarray | None,
    points: Sequence[tuple[str, float, float]],
) -> Functional:
    r"""Return a ``[performance]`` output: its integral, traces and fields at points, summed.

    The pieces are those of :func:`phdesign.numeric.inputs.performance_terms`; one piece
    with coefficient 1 is that functional itself, renamed.
    """
    parts: list[tuple[Functional, float]] = []
    if weight is not None:
        parts.append((Functional(name, "integral", weight=weight), 1.0))
    if trace is not None:
        parts.append((Functional(name, "trace", trace=trace), 1.0))
    parts += [(displacement_at(nm, point, field), c) for field, point, c in points]
    if len(parts) == 1 and parts[0][1] == 1.0:
        return replace(parts[0][0], name=name)
    return Functional(name, "sum", parts=tuple(parts))


def disturbance_matrix(d: DiscretePHS, B: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    r"""Return :math:`B_d = \int_a^b \Psi(z)^\top B(z)\, dz`, ``(dim, q)``, by Gauss.

    Testing :math:`\partial_t x = \dots + B w` with the effort basis (the Galerkin weak
    form, :math:`E = \int \Psi^\top \mathcal H^{-1} \Psi`) gives
    :math:`E \dot{\hat e} = \dots + B_d w`, and :math:`\hat e^\top B_d w = \int e_h^\top
    B w\, dz` is the supplied power of the discrete energy balance.  A ``B`` with a
    hashable ``key`` (a :class:`~phdesign.numeric.inputs.Profile`) is integrated once per
    discretization and shared (read-only).
    """

    def build() -> np.ndarray:
        z, wq = _gauss(d)
        values = np.asarray(B(z), dtype=float)  # (nq, n, q)
        out = np.asarray(np.einsum("q,qid,qij->dj", wq, d.effort_basis(z), values))
        out.flags.writeable = False
        return out

    key = getattr(B, "key", None)
    return np.asarray(build() if key is None else _ROWS.get(d, ("disturbance", key), build))


def _gauss(d: DiscretePHS) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on the model's interval, enough for the basis."""
    a, b = d.model.interval
    t, wq = leg.leggauss(max(64, 2 * d.dim))
    return 0.5 * (a + b) + 0.5 * (b - a) * t, 0.5 * (b - a) * wq


def _integral_row(d: DiscretePHS, weight: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    r"""Row of :math:`\int \sum_i w_i x_i \, dz` with :math:`x = \mathcal H^{-1} e`, by Gauss.

    The rule has enough points to be exact for a polynomial weight against the Galerkin
    efforts (degree p) when H is constant; for a smooth weight it converges spectrally.
    """
    z, wq = _gauss(d)
    W = np.asarray(weight(z), dtype=float).reshape(z.size, d.model.size)
    Hinv_W = np.linalg.solve(d.model.H_at(z), W[:, :, None])[:, :, 0]  # H symmetric
    basis = d.effort_basis(z)  # (nq, n, dim)
    return np.asarray(np.einsum("q,qi,qid->d", wq, Hinv_W, basis))
