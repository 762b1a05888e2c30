r"""The one crossing from the symbolic layer to the numeric one.

:func:`to_numeric` takes a validated symbolic :class:`~phdesign.symbolic.model.BCPHS`,
substitutes its parameters (defaults, overridden by the caller), refuses any symbol
left free, and returns a :class:`NumericModel`: floats and a vectorized callable for
the Hamiltonian density, nothing symbolic.  Everything else in :mod:`phdesign.numeric`
works on :class:`NumericModel` only, so this module and :mod:`phdesign.numeric.inputs`
(the user's initial states, input signals and boundary traces, read against a model) are
the numeric layer's only modules that import sympy (lazily, inside functions).

The port matrices follow the fixed trace ordering of the contract,

.. math::

    v = (\phi(b); \phi(a)), \quad
    \phi = (e, e', \dots, e^{(N-1)}), \quad u = U v, \quad y = Y v,

so that the index of :math:`e_i^{(k)}(\text{side})` in ``v`` is
``(0 if side == "b" else N*n) + k*n + (i - 1)``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.checks import found_text
from phdesign.core.errors import ArgumentError, ModelError, ParameterError, check_shape
from phdesign.numeric.boundary import NumericBoundary, numeric_boundaries
from phdesign.symbolic.ports import trace_index
from phdesign.symbolic.printing import format_expression

__all__ = [
    "DisplacementSpec",
    "NumericModel",
    "PortFeedback",
    "constant_H",
    "gain_to_numeric",
    "require_numeric_model",
    "to_numeric",
    "trace_index",
]


@dataclass(frozen=True)
class DisplacementSpec:
    r"""A field with numbers: :math:`f = \sum_j c_j \mathcal I_s^{k_j} x_{i_j}`.

    ``terms`` are ``(component, integrations, coefficient)`` with 1-based components of x
    (not of e); every integration runs from the end ``start`` (``"a"`` or ``"b"``) with
    value zero there (:mod:`phdesign.symbolic.fields`).  The beam has
    :math:`x_2 = w_{zz}`, so ``DisplacementSpec(((2, 2, 1.0),))`` gives
    :math:`w(z) = \int_a^z \int_a^s x_2(r)\, dr\, ds`.
    """

    terms: tuple[tuple[int, int, float], ...]
    start: str = "a"


@dataclass(frozen=True)
class PortFeedback:
    r"""The plant's own boundary feedback :math:`u_c = -K y_c`, with numbers.

    ``closed`` are 0-based indices into the open ports (the rows of ``U`` and ``Y``);
    ``gain`` is :math:`K` (``c x c``, :math:`K + K^\top \succeq 0`).
    """

    closed: tuple[int, ...]
    gain: np.ndarray = field(compare=False)


@dataclass(frozen=True)
class NumericModel:
    r"""A BC-PHS with every parameter substituted: the numeric layer's input.

    .. math::

        \partial_t x = \sum_{k=0}^N P_k \partial_z^k (H(z) x), \quad
        u = U v, \quad y = Y v,

    with ``P[k]`` of shape ``(n, n)``, ``U`` and ``Y`` of shape ``(N n, 2 N n)`` over the
    trace vector ``v`` (see the module docstring) and ``H(z)`` a vectorized callable that
    maps an array of ``m`` points to an array of shape ``(m, n, n)``.  ``U`` and ``Y`` are
    the open plant's ports; with ``feedback`` the inputs ``feedback.closed`` are closed by
    :math:`u_c = -K y_c` and the model's external ports are the others (:attr:`n_ports`
    of them): every discretization returns the closed plant.  When :math:`P_0` depends on
    z, ``P0`` is its vectorized callable and ``P[0]`` is filled with NaN, so that no code
    can use a constant :math:`P_0` by mistake (:meth:`P0_at` serves both cases).

    Parameters
    ----------
    name : str
        Model name (for labels).
    interval : tuple of float
        ``(a, b)`` with ``a < b``.
    order, size : int
        N and n.
    P : tuple of ndarray
        ``P_0 .. P_N``.
    H : callable
        ``H(z) -> (m, n, n)``; symmetric positive definite at every point.
    U, Y : ndarray
        Input and output maps over the trace vector.
    input_labels, output_labels, state_names : tuple of str
        Names used in exports and CSV headers.
    input_traces, output_traces : tuple of str
        The external ports as trace expressions at the endpoints (``e1'(1)``), how the
        exports describe their signals (:mod:`phdesign.numeric.signals`); default the labels.
    displacement : DisplacementSpec or None
        How to reconstruct a physical displacement, if the model has one.
    fields : tuple of (str, DisplacementSpec)
        The named fields (rotations, strains) of ``[fields.<name>]``.
    boundary : tuple of NumericBoundary
        The boundary systems joined to some open ports (:mod:`phdesign.numeric.boundary`);
        their external inputs follow the PDE's external ports.
    H_constant : bool
        True when H does not depend on z (lets discretizations skip quadrature work).
    feedback : PortFeedback or None
        The plant's own boundary feedback.
    P0 : callable or None
        ``P0(z) -> (m, n, n)`` when :math:`P_0` depends on z, else ``None``.
    units : mapping
        Units stated by the model (``t``, ``z``, ``energy``, ``displacement``, parameters,
        states).
    parameters : mapping of str to float
        The parameter values substituted (defaults with the caller's overrides), by name:
        the values an initial state or an input written in the parameters is evaluated with.
    """

    name: str
    interval: tuple[float, float]
    order: int
    size: int
    P: tuple[np.ndarray, ...]
    H: Callable[[np.ndarray], np.ndarray]
    U: np.ndarray
    Y: np.ndarray
    input_labels: tuple[str, ...] = ()
    output_labels: tuple[str, ...] = ()
    state_names: tuple[str, ...] = ()
    displacement: DisplacementSpec | None = None
    H_constant: bool = False
    input_traces: tuple[str, ...] = field(default=(), compare=False, repr=False)
    output_traces: tuple[str, ...] = field(default=(), compare=False, repr=False)
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    feedback: PortFeedback | None = None
    P0: Callable[[np.ndarray], np.ndarray] | None = field(default=None, compare=False)
    units: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)
    parameters: Mapping[str, float] = field(default_factory=dict, compare=False, repr=False)
    fields: tuple[tuple[str, DisplacementSpec], ...] = ()
    boundary: tuple[NumericBoundary, ...] = field(default=(), compare=False, repr=False)

    def field_spec(self, name: str) -> DisplacementSpec | None:
        """Return the field ``name`` (``"w"`` is the displacement), or None."""
        if name == "w":
            return self.displacement
        return dict(self.fields).get(name)

    def __post_init__(self) -> None:
        a, b = (float(s) for s in self.interval)
        if not a < b:
            raise ModelError(f"interval must satisfy a < b; found a = {a}, b = {b}")
        N, n = int(self.order), int(self.size)
        if N < 1 or n < 1:
            raise ModelError(f"order and size must be >= 1; found N = {N}, n = {n}")
        if len(self.P) != N + 1:
            raise ModelError(f"expected {N + 1} matrices P_0..P_{N}; found {len(self.P)}")
        for k, Pk in enumerate(self.P):
            check_shape(f"P{k}", np.asarray(Pk), (n, n))
        check_shape("U", np.asarray(self.U), (N * n, 2 * N * n))
        check_shape("Y", np.asarray(self.Y), (N * n, 2 * N * n))
        object.__setattr__(self, "interval", (a, b))
        object.__setattr__(self, "P", tuple(np.asarray(Pk, dtype=float) for Pk in self.P))
        object.__setattr__(self, "U", np.asarray(self.U, dtype=float))
        object.__setattr__(self, "Y", np.asarray(self.Y, dtype=float))
        if self.feedback is not None:
            closed = self.feedback.closed
            if len(set(closed)) != len(closed) or not all(0 <= c < N * n for c in closed):
                raise ModelError(
                    f"feedback must close distinct ports in 0..{N * n - 1}; found {closed}"
                )
            check_shape("feedback gain K", np.asarray(self.feedback.gain), (len(closed),) * 2)
        self._check_dissipative()
        m = self.n_ports
        if not self.input_labels:
            object.__setattr__(self, "input_labels", tuple(f"u{i + 1}" for i in range(m)))
        if not self.output_labels:
            object.__setattr__(self, "output_labels", tuple(f"y{i + 1}" for i in range(m)))
        if not self.state_names:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(n)))
        for traces, labels in (
            ("input_traces", "input_labels"),
            ("output_traces", "output_labels"),
        ):
            if not getattr(self, traces):
                object.__setattr__(self, traces, getattr(self, labels))

    def _check_dissipative(self) -> None:
        r"""Refuse a model that is not dissipative.

        The checks of :mod:`phdesign.numeric.discretization.invariants`:
        :math:`H(z) \succ 0` (the energy is positive) and :math:`P_0 + P_0^\top \preceq 0`
        on a grid of the interval, and the plant's own feedback :math:`K + K^\top \succeq
        0`, to round-off.
        """
        from phdesign.numeric.discretization.invariants import (
            GRID_POINTS,
            require_definite,
            require_semidefinite,
        )

        z = np.linspace(self.interval[0], self.interval[1], GRID_POINTS)
        require_definite("H(z)", self.H_at(z), ModelError, points=z)

        def _size(M: np.ndarray) -> float:  # round-off is relative to the matrix summed
            return float(np.max(np.abs(M))) if M.size and np.all(np.isfinite(M)) else 0.0

        if self.P0 is None:
            P0 = self.P[0]
            require_semidefinite(
                "P0 + P0^T", P0 + P0.T, negative=True, reference=_size(P0), error=ModelError
            )
        else:
            P0 = self.P0_at(z)
            require_semidefinite(
                "P0(z) + P0(z)^T",
                P0 + P0.transpose(0, 2, 1),
                negative=True,
                points=z,
                reference=_size(P0),
                error=ModelError,
            )
        if self.feedback is not None:
            K = np.asarray(self.feedback.gain, dtype=float)
            require_semidefinite(
                "feedback gain K + K^T", K + K.T, reference=_size(K), error=ModelError
            )

    @property
    def n_ports(self) -> int:
        """Number of external inputs (= outputs).

        ``N n`` less those closed by the feedback or joined to a boundary system, then the
        boundary systems' external inputs.
        """
        closed = 0 if self.feedback is None else len(self.feedback.closed)
        joined = sum(len(b.joined) for b in self.boundary)
        extra = sum(b.n_external for b in self.boundary)
        return self.order * self.size - closed - joined + extra

    @property
    def P0_constant(self) -> bool:
        """True when :math:`P_0` does not depend on z (then ``P[0]`` holds it)."""
        return self.P0 is None

    def P0_at(self, z: np.ndarray | float) -> np.ndarray:
        """Evaluate :math:`P_0` at the points ``z``; returns shape ``(m, n, n)``."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        n = self.size
        if self.P0 is None:
            return np.broadcast_to(self.P[0], (zz.size, n, n)).copy()
        out = np.asarray(self.P0(zz), dtype=float)
        return np.broadcast_to(out, (zz.size, n, n)).copy()

    def H_at(self, z: np.ndarray | float) -> np.ndarray:
        """Evaluate H at the points ``z``; returns shape ``(m, n, n)``."""
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        out = np.asarray(self.H(zz), dtype=float)
        n = self.size
        if out.shape != (zz.size, n, n):
            out = np.broadcast_to(out, (zz.size, n, n)).copy()
        return out


def constant_H(
    matrix: Sequence[Sequence[float]] | np.ndarray,
) -> Callable[[np.ndarray], np.ndarray]:
    """Return a vectorized callable for a constant Hamiltonian density.

    Examples
    --------
    >>> constant_H([[1.0, 0.0], [0.0, 2.0]])(np.array([0.0, 0.5])).shape
    (2, 2, 2)
    """
    Hm = np.asarray(matrix, dtype=float)

    def H(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        return np.broadcast_to(Hm, (zz.size, *Hm.shape)).copy()

    return H


def _free_symbols_message(what: str, symbols: set[Any]) -> str:
    names = ", ".join(sorted(str(s) for s in symbols))
    first = min(str(s) for s in symbols)
    return (
        f"{what} still contains free symbols after substitution: {names}; give them values "
        f"(`parameters={{{first!r}: ...}}`)"
    )


def _parameter_values(model: Any, parameters: Mapping[str, Any] | None) -> dict[Any, Any]:
    """Defaults of ``model`` overridden by ``parameters`` (keys by name), checked by the model."""
    if parameters:
        model = model.with_parameters({str(k): v for k, v in parameters.items()})
    return dict(model.parameter_defaults)


def to_numeric(model: Any, parameters: Mapping[str, Any] | None = None) -> NumericModel:
    """Substitute parameters into a symbolic BC-PHS and return a :class:`NumericModel`.

    Parameters
    ----------
    model : phdesign.symbolic.model.BCPHS
        The validated symbolic model.
    parameters : mapping of str to number or expression, optional
        Overrides of the model's parameter defaults, by name.

    Returns
    -------
    NumericModel

    Raises
    ------
    ParameterError
        When a parameter is unknown or a symbol other than z stays free (the message
        names them).
    """
    from phdesign.symbolic.system import require_model

    require_model(model)
    if parameters is not None and not isinstance(parameters, Mapping):
        raise ParameterError(
            f"parameters must be a mapping of names to values; found {type(parameters).__name__}"
        )
    values = _parameter_values(model, parameters)
    sub = _Substitution(values)
    n = int(model.size)
    P, P0fun = _numeric_P(sub, model.P, n)
    Hs = sub.matrix("H", model.H, allow_z=True)
    H_constant = not sub.depends_on_z(Hs)
    ports = model.ports
    inputs = getattr(model, "external_inputs", model.inputs)
    outputs = getattr(model, "external_outputs", model.outputs)
    boundary = numeric_boundaries(model, sub.matrix, sub.array)
    extra_in = tuple(x for b in boundary for x in b.input_labels)
    extra_out = tuple(x for b in boundary for x in b.output_labels)
    d = getattr(model, "displacement", None)
    # H > 0, P0 + P0^T <= 0 and K + K^T >= 0 after substitution are checked by NumericModel
    # itself (its invariants)
    return NumericModel(
        name=str(model.name),
        interval=sub.interval(model.interval),
        order=int(model.order),
        size=n,
        P=P,
        H=constant_H(sub.array(Hs)) if H_constant else _matrix_function(Hs, n),
        U=sub.array(sub.matrix("U", ports.U)),
        Y=sub.array(sub.matrix("Y", ports.Y)),
        input_labels=(*(str(e) for e in inputs), *extra_in),
        output_labels=(*(str(e) for e in outputs), *extra_out),
        input_traces=(*(format_expression(e, model.interval) for e in inputs), *extra_in),
        output_traces=(*(format_expression(e, model.interval) for e in outputs), *extra_out),
        state_names=tuple(model.state_names),
        displacement=None if d is None else _numeric_field(sub, d),
        fields=tuple((name, _numeric_field(sub, f)) for name, f in getattr(model, "fields", ())),
        H_constant=H_constant,
        feedback=_numeric_feedback(sub, getattr(model, "feedback", None)),
        P0=P0fun,
        units=dict(getattr(model, "units", ())),
        parameters={str(k): float(v) for k, v in values.items()},
        boundary=boundary,
    )


class _Substitution:
    """The parameters' values put into a model's matrices, refusing any other symbol."""

    def __init__(self, values: dict[Any, Any]) -> None:
        from phdesign.symbolic.model import Z

        self.values, self.z = values, Z

    def matrix(self, name: str, mat: Any, allow_z: bool = False) -> Any:
        """Return the exact matrix with the values in; only z may stay free (when allowed)."""
        from phdesign.symbolic.expressions import exact_matrix

        out = exact_matrix(mat, name, symbols=True).xreplace(self.values)
        free = set(out.free_symbols) - ({self.z} if allow_z else set())
        if free:
            raise ParameterError(_free_symbols_message(name, free))
        return out

    def depends_on_z(self, mat: Any) -> bool:
        """Tell whether a substituted matrix still holds z."""
        return self.z in mat.free_symbols

    @staticmethod
    def array(mat: Any) -> np.ndarray:
        """Return a substituted matrix without z as floats."""
        return np.array(mat.evalf(), dtype=float)

    def interval(self, ends: Any) -> tuple[float, float]:
        """Return the interval's ends as floats (they may be parameters)."""
        from phdesign.symbolic.expressions import exact_number

        a_s, b_s = (exact_number(s, "interval endpoint") for s in ends)
        for name, s in (("interval start a", a_s), ("interval end b", b_s)):
            if s.free_symbols:
                raise ParameterError(_free_symbols_message(name, set(s.free_symbols)))
        return float(a_s), float(b_s)


def _numeric_P(
    sub: _Substitution, P_sym: Sequence[Any], n: int
) -> tuple[tuple[np.ndarray, ...], Callable[[np.ndarray], np.ndarray] | None]:
    """Return P_0..P_N as floats, and a z-dependent P_0 as a callable (NaN in its slot)."""
    P = [sub.array(sub.matrix(f"P{k}", Pk)) for k, Pk in enumerate(P_sym) if k > 0]
    P0s = sub.matrix("P0", P_sym[0], allow_z=True)
    if sub.depends_on_z(P0s):
        return (np.full((n, n), np.nan), *P), _matrix_function(P0s, n)
    return (sub.array(P0s), *P), None


def _numeric_field(sub: _Substitution, f: Any) -> DisplacementSpec:
    """Return a field with its coefficients as floats."""
    import sympy

    values = sub.array(
        sub.matrix("field coefficients", sympy.Matrix([[t.coefficient for t in f.terms]]))
    )
    terms = tuple(
        (int(t.component), int(t.integrations), float(c))
        for t, c in zip(f.terms, values[0], strict=True)
    )
    return DisplacementSpec(terms, str(f.start))


def _numeric_feedback(sub: _Substitution, feedback: Any) -> PortFeedback | None:
    """Return the plant's own feedback with its gain as floats (None without one)."""
    if feedback is None:
        return None
    K = sub.array(sub.matrix("feedback gain K", feedback.gain))
    return PortFeedback(tuple(feedback.closed), K)


def _matrix_function(matrix: Any, n: int) -> Callable[[np.ndarray], np.ndarray]:
    """Return a vectorized callable ``f(z) -> (m, n, n)`` of a sympy matrix in z."""
    from phdesign.symbolic.evaluation import evaluate

    entries = [matrix[i, j] for i in range(n) for j in range(n)]

    def values(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        vals = [evaluate(entry, zz) for entry in entries]  # no code generation
        return np.stack(vals, axis=-1).reshape(zz.size, n, n)

    return values


def gain_to_numeric(matrix: Any, name: str = "L") -> np.ndarray:
    """Convert a sympy (or nested list) matrix of numbers to a float array.

    Raises :class:`ParameterError` when a symbol is left (e.g. ``--gain symbolic``).
    """
    import sympy

    if isinstance(matrix, sympy.MatrixBase):
        if matrix.free_symbols:
            raise ParameterError(_free_symbols_message(name, set(matrix.free_symbols)))
        return np.array(matrix.evalf(), dtype=float)
    try:
        return np.array(matrix, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name}: cannot convert to a numeric matrix ({exc})") from exc


def require_numeric_model(value: object, name: str = "nm") -> None:
    """Raise :class:`ArgumentError` unless ``value`` is a numeric model (the bridge's output)."""
    if not isinstance(value, NumericModel):
        hint = ""
        if isinstance(value, str) or type(value).__name__ == "BCPHS":
            hint = " (phdesign.numeric.bridge.to_numeric(model) makes one from a model)"
        raise ArgumentError(f"{name}: expected a NumericModel{hint}; found {found_text(value)}")
