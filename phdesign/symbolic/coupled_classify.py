r"""The verdict for an observer of a model with boundary systems: what is proved, and by what.

The observer copies the coupled plant and injects :math:`C_m^\top L(y_m - \hat y_m)` at the
external ports: the PDE's open inputs and the boundary systems' own inputs :math:`w`
(measured outputs may include their conjugates :math:`z_c`, a mass's velocity).  The error
system is the coupled plant with :math:`\tilde u_{ext} = -C_m^\top L C_m \tilde y_{ext}`, and
its energy identity (:mod:`phdesign.symbolic.boundary_systems`) is

.. math::

    \frac{d}{dt}(\tilde{\mathcal E} + \tilde H_c) = \tfrac12\int_a^b \tilde e^\top(P_0 +
    P_0^\top)\tilde e\,dz - \tilde e_c^\top R_c \tilde e_c - \tilde y_p^\top
    \operatorname{sym}(K)\tilde y_p - \tilde y_f^\top \operatorname{sym}(K_f)\tilde y_f
    - \tilde y_m^\top \operatorname{sym}(L)\tilde y_m \le 0 .

The paper's propositions concern static boundary conditions; here two theorems decide.

*Asymptotic* (any N).  The error system is a contraction semigroup with compact resolvent
(the PDE's resolvent is compact and the boundary systems add finitely many states), so it
is asymptotically stable iff it has no eigenvalue on the imaginary axis (Arendt–Batty,
Lyubich–Vũ; the LaSalle-type argument of Augner and Jacob, Evol. Equ. Control Theory 3,
2014).  On an eigenvector with :math:`\lambda \in i\mathbb R` every dissipation term above
vanishes: :math:`C_m\tilde y_{ext} = 0`, :math:`\operatorname{sym}(K)\tilde y_p = 0`,
:math:`\operatorname{sym}(K_f)\tilde y_f = 0`, :math:`R_c\tilde e_c = 0`.  These, with the
boundary conditions, are linear in the traces and :math:`\tilde e_c`; when they force
:math:`\tilde e_c = 0` the boundary systems' equations add the λ-free
:math:`G_c S_{cp} \tilde y_p = 0`.  If then all traces at one end vanish, the eigenfunction
has zero Cauchy data and vanishes (:math:`P_N` invertible), and what is left is a mode of the
boundary systems alone that their coupling, dissipation and sensors do not see: none, when
that pair is observable (Kalman's rank test, exact).  Then "asymptotic"; otherwise
"inconclusive" with the reason.

*Exponential* (N = 1).  The dynamic-feedback theorem of Ramirez, Le Gorrec, Macchelli and
Zwart (IEEE Trans. Autom. Control 59, 2014; also Augner and Jacob 2014): a BC-PHS joined to
finite-dimensional linear port-Hamiltonian systems that are strictly input passive
(:math:`\operatorname{sym}(K) \succ 0` on their ports: :math:`D_c + D_c^\top \succ 0` for
the gyrator) and exponentially stable on their own (:math:`(J_c - R_c)Q_c` Hurwitz) is
exponentially stable when the PDE with the static part :math:`u_p = -K y_p` satisfies the
dissipation inequality of Proposition 3.2.  Each hypothesis is checked exactly, and
phdesign asks besides that the asymptotic test below excludes eigenvalues on the
imaginary axis (the static part then governs the high frequencies and the finitely many
others lie strictly left); a tip mass
damped only through the mass (:math:`D_c = 0`) is not strictly input passive, and is known
not to be exponentially stable: the verdict there is never "exponential".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.text import html_table, matrix_text, sensors_text
from phdesign.symbolic.boundary_systems import coupling
from phdesign.symbolic.closing import close_inputs
from phdesign.symbolic.feedback import external_indices
from phdesign.symbolic.ports import trace_list
from phdesign.symbolic.sensors import sensors_and_gain

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = [
    "ASYMPTOTIC",
    "EXPONENTIAL",
    "CoupledClassification",
    "TheoremResult",
    "classify_coupled",
]

EXPONENTIAL = (
    "dynamic boundary feedback, exponential (Ramirez, Le Gorrec, Macchelli, Zwart, IEEE TAC "
    "2014; Augner, Jacob 2014)"
)
ASYMPTOTIC = (
    "no eigenvalue on the imaginary axis, asymptotic (Arendt-Batty-Lyubich-Vu; LaSalle-type, "
    "Augner, Jacob 2014)"
)

#: The static classifier (:func:`phdesign.symbolic.classify.classify`), passed in by it.
StaticClassifier = Callable[[Any, Any, Any, str], Any]


@dataclass(frozen=True)
class TheoremResult:
    """One theorem tried on the coupled error system: whether its hypotheses hold, and why.

    ``name`` is short (``"RLMZ"``, ``"ABLV"``: the authors' initials, as a sweep stores
    it), ``theorem`` the citation (:data:`EXPONENTIAL`, :data:`ASYMPTOTIC`).
    """

    name: str
    theorem: str
    convergence: str
    applicable: bool
    holds: bool
    reason: str
    kappa: float | None = None

    def kappa_json(self) -> float | None:
        r""":math:`\kappa^*` of the static part's Proposition 3.2 (None when not proved)."""
        return self.kappa if self.holds else None

    def to_dict(self) -> dict[str, Any]:
        """JSON form (the keys of a proposition's row, and the theorem's words)."""
        return {
            "proposition": self.name,
            "variant": 1,
            "theorem": self.theorem,
            "applicable": self.applicable,
            "holds": self.holds if self.applicable else None,
            "kappa": self.kappa,
            "convergence": self.convergence,
            "reason": self.reason,
        }


@dataclass(frozen=True, repr=False)
class CoupledClassification:
    """The verdict on an observer of a coupled model: ``str()`` is the CLI's text."""

    model: BCPHS
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix
    results: tuple[TheoremResult, ...]
    verdict: str

    @property
    def best(self) -> TheoremResult | None:
        """The strongest theorem whose hypotheses hold."""
        holding = [r for r in self.results if r.holds]
        return holding[0] if holding else None

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON of ``phdesign classify --json`` for a coupled model."""
        return {
            "model": self.model.name,
            "order": self.model.order,
            "size": self.model.size,
            "sensors": [[float(x) for x in row] for row in self.C_m.tolist()],
            "gain": [[_entry(x) for x in row] for row in self.L.tolist()],
            "partitioned": False,
            "boundary_systems": [bs.name for bs in self.model.boundary_systems],
            "results": [r.to_dict() for r in self.results],
            "verdict": self.verdict,
            "best": None if self.best is None else self.best.name,
        }

    def _header(self) -> list[str]:
        names = ", ".join(bs.name for bs in self.model.boundary_systems)
        lines = [f"model {self.model.name}: N = {self.model.order}, n = {self.model.size}"]
        lines.append(
            f"boundary systems: {names} (the propositions' static conditions do not apply)"
        )
        if self.C_m.rows:
            lines += [f"sensors: {sensors_text(self.C_m)}", f"gain L = {matrix_text(self.L)}"]
        else:
            lines.append("sensors: none")
        return lines

    def __str__(self) -> str:
        lines = [*self._header(), ""]
        for r in self.results:
            state = "holds" if r.holds else ("not applicable" if not r.applicable else "fails")
            lines.append(f"{r.convergence}: {state}: {r.theorem}")
            lines.append(f"  ↳ {r.reason}")
        best = self.best
        tail = f" (by {best.theorem})" if best is not None else ""
        lines += ["", f"verdict: {self.verdict}{tail}"]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return (
            f"CoupledClassification(model={self.model.name!r}, sensors="
            f"{sensors_text(self.C_m)!r}, verdict={self.verdict!r})"
        )

    def _repr_html_(self) -> str:
        rows = [
            [r.convergence, "yes" if r.holds else "no", r.name, r.reason] for r in self.results
        ]
        return html_table(
            ["kind", "holds", "theorem", "reason"],
            rows,
            caption=" · ".join(self._header()),
            footer=f"verdict: {self.verdict}",
        )


def classify_coupled(
    model: BCPHS, C_m: Any, L: Any, method: str, static: StaticClassifier
) -> CoupledClassification:
    r"""Classify the observer ``(C_m, L)`` of the coupled ``model`` (module docstring).

    ``static`` classifies the static part (the PDE with :math:`u_p = -K y_p`) by the
    propositions.

    Symbolic gains (``"symbolic"``: positive :math:`l_i`) are classified as the
    propositions classify them: the asymptotic test does not involve L (on an
    imaginary-axis eigenvector :math:`\tilde y_m^\top \operatorname{sym}(L)\tilde y_m = 0`
    gives :math:`C_m \tilde y_{ext} = 0` for every :math:`L + L^\top \succ 0`), and the
    exponential theorem's static part is Proposition 3.2 with the symbolic gain, whose
    range of gains the reason states.

    Raises
    ------
    ObserverError
        Bad sensors or gain.
    """
    C, Lm = sensors_and_gain(C_m, L, model.n_ports)
    defaults = model.parameter_defaults
    C, Lm = (sympy.Matrix(M).xreplace(defaults) for M in (C, Lm))
    asymptotic = _asymptotic(model, C, Lm)
    if Lm.free_symbols and asymptotic.holds:  # its conditions do not involve L
        asymptotic = replace(asymptotic, reason=f"{asymptotic.reason} (for all positive gains)")
    exponential = _exponential(model, C, Lm, method, static)
    if exponential.holds and not asymptotic.holds:  # a hypothesis kept for safety: no iR mode
        exponential = replace(
            exponential,
            holds=False,
            reason=f"{exponential.reason}; but an eigenvalue on the imaginary axis is not "
            "excluded (the asymptotic test fails)",
        )
    results = (exponential, asymptotic)
    verdict = next((r.convergence for r in results if r.holds), "inconclusive")
    return CoupledClassification(
        model, sympy.ImmutableMatrix(C), sympy.ImmutableMatrix(Lm), results, verdict
    )


# ---------------------------------------------------------------------- the pieces
@dataclass(frozen=True)
class _Rows:
    """The linear conditions on X = (v, e_c) and the column layout."""

    traces: int  # 2 N n
    states: int  # total boundary states
    rows: list[sympy.Matrix]

    def null(self) -> sympy.Matrix:
        M = sympy.Matrix.vstack(*self.rows) if self.rows else sympy.zeros(0, self.width)
        basis = (
            M.nullspace() if M.rows else [sympy.eye(self.width)[:, j] for j in range(self.width)]
        )
        return sympy.Matrix.hstack(*basis) if basis else sympy.zeros(self.width, 0)

    @property
    def width(self) -> int:
        return self.traces + self.states


def _conditions(model: BCPHS, C: sympy.Matrix, L: sympy.Matrix) -> tuple[_Rows, list[Any]]:
    """Return the λ-free conditions an imaginary-axis eigenvector satisfies (module docstring)."""
    defaults = model.parameter_defaults
    U, Y = (sympy.Matrix(M).xreplace(defaults) for M in (model.ports.U, model.ports.Y))
    nn = model.order * model.size
    k = sum(bs.size for bs in model.boundary_systems)
    pad = sympy.zeros(1, k)
    rows: list[sympy.Matrix] = []
    joined = {j for bs in model.boundary_systems for j in bs.joined}
    open_ports = [j for j in external_indices(nn, model.feedback) if j not in joined]
    # the external outputs over X: the open traces, then each system's z_c = B_c^T e_c
    y_ext = [sympy.Matrix.hstack(Y.row(j), pad) for j in open_ports]
    parts, offset = [], 0
    for bs in model.boundary_systems:
        block = _placer(2 * nn, offset, bs.size, k)
        y_ext.append(block(sympy.Matrix(bs.external).T.xreplace(defaults)))
        parts.append((bs, coupling(bs), offset, block))
        offset += bs.size
    Y_ext = sympy.Matrix.vstack(*y_ext) if y_ext else sympy.zeros(0, 2 * nn + k)
    if C.rows:
        rows.append(C * Y_ext)  # no dissipation through the sensors: C_m y_ext = 0
    for j in open_ports:  # then u_ext = -C^T L C y_ext = 0 at the open traces
        rows.append(sympy.Matrix.hstack(U.row(j), pad))
    if model.feedback is not None:
        Kf = sympy.Matrix(model.feedback.gain).xreplace(defaults)
        f = list(model.feedback.closed)
        Uf, Yf = U.extract(f, list(range(2 * nn))), Y.extract(f, list(range(2 * nn)))
        rows.append(sympy.Matrix.hstack(Uf + Kf * Yf, sympy.zeros(len(f), k)))
        rows.append(sympy.Matrix.hstack((Kf + Kf.T) * Yf, sympy.zeros(len(f), k)))
    for bs, c, _, block in parts:
        p = list(bs.joined)
        Up, Yp = U.extract(p, list(range(2 * nn))), Y.extract(p, list(range(2 * nn)))
        K, F = (sympy.Matrix(M).xreplace(defaults) for M in (c.K, c.to_pde))
        rows.append(sympy.Matrix.hstack(Up + K * Yp, sympy.zeros(len(p), k)) - block(F))
        rows.append(sympy.Matrix.hstack((K + K.T) * Yp, sympy.zeros(len(p), k)))
        rows.append(block(sympy.Matrix(bs.R).xreplace(defaults)))
    return _Rows(2 * nn, k, rows), parts


def _placer(
    traces: int, offset: int, size: int, total: int
) -> Callable[[sympy.Matrix], sympy.Matrix]:
    """Return ``M -> [0 | M | 0]``: a boundary system's columns placed among X's."""

    def place(M: sympy.Matrix) -> sympy.Matrix:
        left = sympy.zeros(M.rows, traces + offset)
        return sympy.Matrix.hstack(left, M, sympy.zeros(M.rows, total - offset - size))

    return place


def _asymptotic(model: BCPHS, C: sympy.Matrix, L: sympy.Matrix) -> TheoremResult:
    """Exclude eigenvalues on the imaginary axis by λ-free linear conditions, exactly."""
    system, parts = _conditions(model, C, L)
    nn, width = model.order * model.size, system.width
    E, A, drive = _dynamics(model, parts)
    for _ in range(width + 1):  # each pass adds independent rows, or stops
        rows = sympy.Matrix.vstack(*system.rows) if system.rows else sympy.zeros(0, width)
        N = system.null()
        new = []
        if any(N[r, :].is_zero_matrix for r in (slice(0, nn), slice(nn, 2 * nn))):
            # zero Cauchy data at one end: the eigenfunction vanishes, and all its traces
            new.append(sympy.Matrix.hstack(sympy.eye(2 * nn), sympy.zeros(2 * nn, system.states)))
        V = N[system.traces :, :]
        if V.cols and V.rank() < system.states:
            # lambda E e_c lies in E V: the rows annihilating E V make the dynamics lambda-free
            W = sympy.Matrix.hstack(*((E * V).T.nullspace())).T
            new.append(W * sympy.Matrix.hstack(drive, A))
        if not new or sympy.Matrix.vstack(rows, *new).rank() == rows.rank():
            break
        system.rows.extend(new)
    N = system.null()
    if not N.cols:
        return TheoremResult(
            "ABLV",
            ASYMPTOTIC,
            "asymptotic",
            True,
            True,
            "on the imaginary axis the dissipation terms vanish; with the boundary conditions "
            "and the boundary systems' equations they force the traces at one end, hence the "
            "field, and the boundary states to 0: no eigenvalue there",
        )
    if N[: system.traces, :].is_zero_matrix:
        names = [
            bs.name
            for bs, _, o, _ in parts
            if not N[system.traces + o : system.traces + o + bs.size, :].is_zero_matrix
        ]
        return TheoremResult(
            "ABLV",
            ASYMPTOTIC,
            "asymptotic",
            True,
            False,
            f"boundary system {names[0]!r} may keep a mode that its coupling, dissipation and "
            "the sensors do not see: an eigenvalue on the imaginary axis is not excluded",
        )
    return TheoremResult(
        "ABLV",
        ASYMPTOTIC,
        "asymptotic",
        True,
        False,
        f"the dissipation leaves traces at both ends free ({_free_traces(model, N)}): an "
        "eigenvalue on the imaginary axis is not excluded",
    )


def _dynamics(model: BCPHS, parts: list[Any]) -> tuple[sympy.Matrix, sympy.Matrix, sympy.Matrix]:
    r"""Return ``(E, A, drive)``: :math:`\lambda E e_c = A e_c + \mathrm{drive}\, v` (w = 0)."""
    defaults = model.parameter_defaults
    nn = model.order * model.size
    Y = sympy.Matrix(model.ports.Y).xreplace(defaults)
    E = sympy.diag(*[sympy.Matrix(bs.Q).xreplace(defaults).inv() for bs, *_ in parts])
    A = sympy.diag(
        *[(sympy.Matrix(c.J_eff) - sympy.Matrix(bs.R)).xreplace(defaults) for bs, c, *_ in parts]
    )
    drive = sympy.Matrix.vstack(
        *[
            sympy.Matrix(c.from_pde).xreplace(defaults)
            * Y.extract(list(bs.joined), list(range(2 * nn)))
            for bs, c, *_ in parts
        ]
    )
    return E, A, drive


def _exponential(
    model: BCPHS, C: sympy.Matrix, L: sympy.Matrix, method: str, static: StaticClassifier
) -> TheoremResult:
    def no(reason: str, applicable: bool = True) -> TheoremResult:
        return TheoremResult("RLMZ", EXPONENTIAL, "exponential", applicable, False, reason)

    if model.order != 1:
        return no(f"stated for N = 1 (N = {model.order})", applicable=False)
    defaults = model.parameter_defaults
    for bs in model.boundary_systems:
        c = coupling(bs)
        K = sympy.Matrix(c.K).xreplace(defaults)
        if not (K + K.T).is_positive_definite:
            return no(
                f"boundary system {bs.name!r} is not strictly input passive (sym(K) = "
                f"sym(S_cp^T D_c S_cp) is not > 0; D_c + D_c^T > 0 for the gyrator), a "
                "hypothesis of the theorem"
            )
        A = (sympy.Matrix(bs.Q) * (sympy.Matrix(c.J_eff) - sympy.Matrix(bs.R))).xreplace(defaults)
        if not all(sympy.re(ev) < 0 for ev in A.eigenvals()):
            return no(
                f"boundary system {bs.name!r} is not exponentially stable on its own "
                "((J_c - R_c) Q_c is not Hurwitz)"
            )
    t = len(model.external_inputs)
    trace_rows = [i for i in range(C.rows) if C[i, t:].is_zero_matrix]
    if len(trace_rows) < C.rows and any(
        not C[i, :t].is_zero_matrix for i in range(C.rows) if i not in trace_rows
    ):
        return no("a sensor row mixes PDE traces and boundary-system outputs")
    other = [i for i in range(C.rows) if i not in trace_rows]
    if (
        not L.extract(trace_rows, other).is_zero_matrix
        or not L.extract(other, trace_rows).is_zero_matrix
    ):
        return no("L couples trace sensors with boundary-system sensors")
    surrogate = _static_part(model)
    result = static(
        surrogate, C.extract(trace_rows, list(range(t))), L.extract(trace_rows, trace_rows), method
    )
    holding = [r for r in result.results if r.holds and r.proposition == "3.2"]
    if not holding:
        return no(
            "Proposition 3.2 fails for the static part u_p = -K y_p (the dissipation inequality)"
        )
    best = max(holding, key=lambda r: r.kappa_float or 0.0)
    conditions = f"; {best.conditions}" if best.conditions else ""
    return TheoremResult(
        "RLMZ",
        EXPONENTIAL,
        "exponential",
        True,
        True,
        f"boundary systems strictly input passive and Hurwitz; the static part satisfies "
        f"Proposition 3.2 variant {best.variant} (κ* = {best.kappa_text}{conditions})",
        kappa=best.kappa_float,
    )


def _static_part(model: BCPHS) -> BCPHS:
    """Return the PDE with every boundary system replaced by its static part u_p = -K y_p."""
    bare = replace(model, boundary_systems=())
    nn = model.order * model.size
    external = list(external_indices(nn, bare.feedback))
    inputs = [external.index(j) + 1 for bs in model.boundary_systems for j in bs.joined]
    K = sympy.diag(*[sympy.Matrix(coupling(bs).K) for bs in model.boundary_systems])
    return close_inputs(bare, inputs, K)


def _free_traces(model: BCPHS, N: sympy.Matrix) -> str:
    traces = trace_list(model.order, model.size)
    free = [
        t.label(model.interval, tilde=True)
        for i, t in enumerate(traces)
        if not N.row(i).is_zero_matrix
    ]
    return ", ".join(free[:6]) + (", ..." if len(free) > 6 else "")


def _end(model: BCPHS, end: str) -> str:
    a, b = model.interval
    return str(a if end == "a" else b)


def _entry(x: sympy.Expr) -> float | str:
    """Return a gain entry for the JSON: a float, or the expression as text (symbolic)."""
    return str(x) if x.free_symbols else float(x)
