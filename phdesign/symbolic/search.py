r"""Sensor search: classify every non-empty subset of the outputs.

For unit-row sensors the decision of :mod:`phdesign.symbolic.certificate` is
combinatorial and exact.  Let :math:`t_j = T^{-1}(0; e_j)` be the trace vector with
all inputs and outputs zero except :math:`\tilde y_j = 1`, and :math:`\mathcal S` the
traces a variant selects.  The variant holds for the sensor set :math:`M` iff every
unmeasured output :math:`j \notin M` has :math:`t_j` vanishing on :math:`\mathcal S`,
i.e. iff :math:`M \supseteq B_{\text{variant}} = \{j : \operatorname{supp} t_j \cap
\mathcal S \ne \emptyset\}`.  So each variant has exactly one minimal sensor set,
:math:`B_{\text{variant}}`, computed once from the exact :math:`T^{-1}`, and the
2^(Nn) - 1 subsets are decided with bit masks.

The constants use the float path: with :math:`L = \mathrm{diag}(g_M)`,
:math:`K_m = T^{-1}(-C_m^\top L; C_m^\top)` and :math:`\kappa^* =
1/\sigma_{\max}(S K_m L^{-1/2})^2`: Jacobi rotations in pure Python for small
searches (numpy would cost more to import than the work), batched LAPACK
``eigvalsh`` over subsets otherwise.  "Unbounded" (RHS ≡ 0 on K) is read from the
exact zero pattern, never from a tolerance.

A set is *minimal* for a verdict when it has that verdict and no proper subset has.
The variants tried and the verdict rule are those of the classifier
(:func:`~phdesign.symbolic.propositions.variant_cases`,
:func:`~phdesign.symbolic.propositions.verdict_of`), so the search and
:func:`~phdesign.symbolic.classify.classify` agree subset by subset.

A plant with its own boundary feedback (``[feedback]``) is searched over its external
outputs.  The closed ports are dissipated by the plant's dampers whatever the sensors,
so the combinatorial decision stays exact: an unmeasured external output :math:`j` still
gives the trace vector :math:`t_j = T^{-1}(0; e_j)` (its column of :math:`G` is zero), and
when :math:`K + K^\top` is singular the directions of its kernel give fixed trace
vectors that must vanish on :math:`\mathcal S` for the variant to hold at all.  The
constants then come from :func:`~phdesign.symbolic.certificate.certify` on each
subset's error system (float path): the closed ports' block :math:`K` is not diagonal
in general.

Examples
--------
>>> from phdesign.models import load_builtin
>>> found = search_sensors(load_builtin("euler-bernoulli"))
>>> found.minimal["exponential"]
((2,), (4,))
>>> found.subset([4]).best, found.subset([4]).kappa
('3.4.4', 0.5)
>>> found  # doctest: +NORMALIZE_WHITESPACE
SensorSearch(model='euler-bernoulli', sets=15, gains='diag(1, 1, 1, 1)',
             minimal_exponential=[[2], [4]])
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core import limits
from phdesign.core.errors import ObserverError
from phdesign.core.text import (
    REPR_LIMIT,
    html_table,
    kappa_text,
    matrix_text,
    number_text,
    shorten,
)
from phdesign.symbolic.assumption import Partition, model_assumption
from phdesign.symbolic.closing import plant_feedback
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.feedback import external_indices
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, port_inverse
from phdesign.symbolic.propositions import VERDICTS, Case, strength, variant_cases, verdict_of
from phdesign.symbolic.system import require_model

__all__ = ["Candidate", "SensorSearch", "SubsetResult", "candidates", "search_sensors"]

#: Above this many subsets the search reports progress (when a callback is given).
PROGRESS_THRESHOLD = 512


@dataclass(frozen=True)
class Candidate:
    r"""One case (variant, partition) with the unique minimal sensor set that makes it hold.

    Attributes
    ----------
    case : Case
        The variant, its partition and the traces it selects.
    required : tuple of int
        1-based outputs that must be measured (:math:`B_{\text{variant}}`).
    attainable : bool
        False when no sensor set makes it hold (a direction the plant's own feedback
        leaves undamped breaks it).
    """

    case: Case
    required: tuple[int, ...]
    attainable: bool = True

    @property
    def name(self) -> str:
        """``"3.4.3"``-style name."""
        return self.case.variant.name

    @property
    def partition(self) -> Partition | None:
        """The partition of Assumption 3.1 the case uses (3.4 only)."""
        return self.case.partition

    @property
    def convergence(self) -> str:
        """``"asymptotic"`` or ``"exponential"``."""
        return self.case.variant.convergence


@dataclass(frozen=True)
class SubsetResult:
    """Classification of one sensor subset.

    Attributes
    ----------
    sensors : tuple of int
        1-based measured outputs.
    verdict : str
    best : str or None
        Strongest holding variant (``"3.3.3"``), largest κ* among the same kind.
    kappa : float or None
        κ* of ``best`` (``None`` when unbounded, symbolic gains, or nothing holds).
    unbounded : bool
    holding : tuple of str
        Every holding variant.
    partition : tuple of (tuple, tuple) or None
        The partition (x1, x2) of ``best`` when it is a 3.4 variant.
    """

    sensors: tuple[int, ...]
    verdict: str
    best: str | None
    kappa: float | None
    unbounded: bool
    holding: tuple[str, ...]
    partition: tuple[tuple[int, ...], tuple[int, ...]] | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form of one subset."""
        out: dict[str, Any] = {
            "sensors": list(self.sensors),
            "verdict": self.verdict,
            "best": self.best,
            "kappa": self.kappa,
            "unbounded": self.unbounded,
            "holding": list(self.holding),
        }
        if self.partition is not None:
            out["partition"] = {"x1": list(self.partition[0]), "x2": list(self.partition[1])}
        return out


@dataclass(frozen=True, repr=False)
class SensorSearch:
    """Result of :func:`search_sensors`; ``str()`` is the table of ``classify --all-sensors``.

    Attributes
    ----------
    model : str
    order, size : int
    gains : tuple of str
        Diagonal gain per output (reused for every subset that measures it).
    candidates : tuple of Candidate
        The variants tried, each with its minimal sensor set.
    subsets : tuple of SubsetResult
        Every non-empty subset, by size then lexicographically.
    minimal : dict
        For each verdict, the minimal sensor sets reaching it.
    """

    model: str
    order: int
    size: int
    gains: tuple[str, ...]
    candidates: tuple[Candidate, ...]
    subsets: tuple[SubsetResult, ...]
    minimal: dict[str, tuple[tuple[int, ...], ...]]

    @property
    def symbolic(self) -> bool:
        """Whether the gains are symbolic (the constants are then not computed)."""
        return all(g == "symbolic" for g in self.gains)

    def subset(self, sensors: Sequence[int]) -> SubsetResult:
        """Return the result of one sensor set."""
        key = tuple(sorted(sensors))
        for s in self.subsets:
            if s.sensors == key:
                return s
        raise ObserverError(
            f"no sensor set {list(key)}; expected distinct outputs in 1..{self.order * self.size}"
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON: every subset with its verdict, and the minimal sets per verdict."""
        return {
            "model": self.model,
            "order": self.order,
            "size": self.size,
            "gain": list(self.gains),
            "decision_path": "exact (combinatorial, gain-independent)",
            "kappa_path": None if self.symbolic else "float",
            "required": {c.name + _partition_suffix(c): list(c.required) for c in self.candidates},
            "subsets": [s.to_dict() for s in self.subsets],
            "minimal": {k: [list(s) for s in v] for k, v in self.minimal.items()},
        }

    # ------------------------------------------------------------------ display
    def _gain_text(self) -> str:
        if self.symbolic:
            return f"diag({', '.join(f'l{j + 1}' for j in range(len(self.gains)))})"
        return f"diag({', '.join(self.gains)})"

    def _kappa(self, s: SubsetResult) -> str:
        if s.best is None:
            return "—"
        if self.symbolic:
            return "depends on L"
        return kappa_text(None, s.kappa, s.unbounded)

    def _minimal_lines(self) -> list[str]:
        lines = []
        for verdict, sets in self.minimal.items():
            shown = ", ".join("{" + ",".join(map(str, s)) + "}" for s in sets) or "none"
            lines.append(f"minimal {verdict} sets: {shown}")
        return lines

    def __str__(self) -> str:
        lines = [
            f"model {self.model}: N = {self.order}, n = {self.size}, "
            f"{len(self.subsets)} sensor sets, gains L = {self._gain_text()} "
            "restricted to each set",
        ]
        if self.symbolic:
            lines.append(
                "κ* is not computed for symbolic gains (the verdicts do not depend on them); "
                "classify one set with symbolic gains for κ* as an expression"
            )
        lines += ["", f"{'sensors':<24} {'verdict':<13} {'best':<7} κ*"]
        for s in self.subsets:
            sensors = ",".join(map(str, s.sensors))
            lines.append(f"{sensors:<24} {s.verdict:<13} {s.best or '—':<7} {self._kappa(s)}")
        return "\n".join([*lines, "", *self._minimal_lines()])

    def __repr__(self) -> str:
        minimal = [list(s) for s in self.minimal.get("exponential", ())]
        text = (
            f"SensorSearch(model={self.model!r}, sets={len(self.subsets)}, "
            f"gains={shorten(self._gain_text(), 80)!r}, "
            f"minimal_exponential={shorten(str(minimal), 120)})"
        )
        return shorten(text, REPR_LIMIT)

    def _repr_html_(self) -> str:
        rows = [
            [",".join(map(str, s.sensors)), s.verdict, s.best or "—", self._kappa(s)]
            for s in self.subsets
        ]
        return html_table(
            ["sensors", "verdict", "best", "κ*"],
            rows,
            caption=f"{self.model}: every sensor set, gains L = {self._gain_text()}",
            footer="; ".join(self._minimal_lines()),
        )


def _partition_suffix(c: Candidate) -> str:
    if c.partition is None:
        return ""
    return f" x1={list(c.partition.x1)}"


def candidates(model: BCPHS) -> tuple[Candidate, ...]:
    """Return every applicable (variant, partition) of ``model`` with its minimal sensor set."""
    require_model(model)
    nn = model.order * model.size
    T_inv = port_inverse(model)
    external = external_indices(nn, model.feedback)
    support = [{i for i in range(2 * nn) if not vanishes(T_inv[i, nn + j])} for j in external]
    undamped = _undamped_directions(model, T_inv)
    found: list[Candidate] = []
    for entry in variant_cases(model.order, model.size, model_assumption(model)):
        for case in entry.cases:
            selected = set(case.selected)
            required = tuple(j + 1 for j in range(len(external)) if support[j] & selected)
            attainable = not any(selected & s for s in undamped)
            found.append(Candidate(case, required, attainable))
    return tuple(found)


def _undamped_directions(model: BCPHS, T_inv: sympy.MatrixBase) -> list[set[int]]:
    r"""Return the supports of the undamped trace vectors of the plant's own feedback.

    :math:`v = T^{-1}(-E_c^\top K w; E_c^\top w)` for :math:`w \in \ker(K + K^\top)`.
    """
    feedback = plant_feedback(model)
    if feedback is None:
        return []
    closed, K = feedback
    nn = model.order * model.size
    out = []
    for w in (K + K.T).nullspace():
        y = sympy.zeros(nn, 1)
        u = sympy.zeros(nn, 1)
        Kw = K * w
        for row, port in enumerate(closed):
            y[port], u[port] = w[row], -Kw[row]
        v = T_inv * sympy.Matrix.vstack(u, y)
        out.append({i for i in range(2 * nn) if not vanishes(v[i])})
    return out


def _gain_vector(gain: Any, nn: int) -> tuple[sympy.Expr, ...] | None:
    """Diagonal gain per output; ``None`` for symbolic gains (constants not computed)."""
    if isinstance(gain, str) and gain.strip() == "symbolic":
        return None
    L = gain_matrix(1 if gain is None else gain, nn, per="output")
    if any(L[i, j] != 0 for i in range(nn) for j in range(nn) if i != j):
        raise ObserverError(
            "gain: the sensor search takes diagonal gains (one number, or one per output); "
            f"found the full matrix {matrix_text(L)}"
        )
    return tuple(L[j, j] for j in range(nn))


def search_sensors(
    model: BCPHS,
    gain: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> SensorSearch:
    """Classify every non-empty subset of the outputs of ``model``.

    Parameters
    ----------
    model : BCPHS
        The plant.
    gain : None, number, sequence of numbers, diagonal matrix or "symbolic"
        Diagonal gains: ``None`` (identity), one number for every output, or one per
        output (``[0.5, 1, 1, 2]``, a numpy array); a subset uses the entries of the
        outputs it measures.  ``"symbolic"`` skips the constants (the verdicts do not
        depend on the gain).
    progress : callable(done, total), optional
        Called as the subsets are processed, when there are more than
        :data:`PROGRESS_THRESHOLD` of them.

    Returns
    -------
    SensorSearch
    """
    require_model(model)
    if progress is not None and not callable(progress):
        raise ObserverError(f"progress must be callable(done, total); found {progress!r}")
    limits.check_sensor_outputs(model.n_ports)
    order, size = model.order, model.size
    nn = model.n_ports
    gains = _gain_vector(gain, nn)
    cands = candidates(model)
    total = 2**nn - 1
    required = [sum(1 << (j - 1) for j in c.required) for c in cands]
    # decision: exact and combinatorial (module docstring)
    holds = [
        [required[c] & ~mask == 0 and cands[c].attainable for c in range(len(cands))]
        for mask in range(total + 1)
    ]
    kappa: dict[tuple[int, int], float | None] = {}  # (mask, candidate) -> κ*, None = unbounded
    if gains is not None:
        jobs = [
            (mask, c) for mask in range(1, total + 1) for c in range(len(cands)) if holds[mask][c]
        ]
        kappas = _kappas if model.feedback is None else _kappas_with_plant_feedback
        kappa = kappas(model, gains, cands, jobs, progress, total)
    verdict_code = [VERDICTS.index("inconclusive")] * (total + 1)
    results = []
    for mask in sorted(range(1, total + 1), key=lambda m: (bin(m).count("1"), _members(m))):
        holding = [c for c in range(len(cands)) if holds[mask][c]]
        verdict = verdict_of(cands[c].convergence for c in holding)
        verdict_code[mask] = VERDICTS.index(verdict)
        best = None
        if holding:

            def key(c: int, mask: int = mask) -> tuple[int, float]:
                value = kappa.get((mask, c))
                unbounded = (mask, c) in kappa and value is None
                return strength(cands[c].convergence, value, unbounded)

            best = max(holding, key=key)
        value = None if best is None else kappa.get((mask, best))
        partition = None if best is None else cands[best].partition
        results.append(
            SubsetResult(
                sensors=_members(mask),
                verdict=verdict,
                best=None if best is None else cands[best].name,
                kappa=value,
                unbounded=best is not None and (mask, best) in kappa and value is None,
                holding=tuple(dict.fromkeys(cands[c].name for c in holding)),
                partition=None if partition is None else (partition.x1, partition.x2),
            )
        )
    minimal = _minimal_sets(verdict_code, VERDICTS, nn)
    return SensorSearch(
        model=model.name,
        order=order,
        size=size,
        gains=tuple("symbolic" for _ in range(nn))
        if gains is None
        else tuple(number_text(g) for g in gains),
        candidates=cands,
        subsets=tuple(results),
        minimal=minimal,
    )


#: Up to this many (subset, variant) pairs κ* is computed in pure Python (Jacobi
#: eigenvalues): importing numpy would cost more than the whole computation.
PURE_PYTHON_JOBS = 600


def _kappas(
    model: BCPHS,
    gains: tuple[sympy.Expr, ...],
    cands: tuple[Candidate, ...],
    jobs: list[tuple[int, int]],
    progress: Callable[[int, int], None] | None,
    total: int,
) -> dict[tuple[int, int], float | None]:
    r"""κ* per (subset mask, candidate): :math:`1/\lambda_{\max}(B)`, ``None`` when RHS ≡ 0.

    Column ``j`` of :math:`S K_m L^{-1/2}` for a measured output ``j`` is
    :math:`(-g_j T^{-1}_{:, j} + T^{-1}_{:, Nn + j}) / \sqrt{g_j}` on the selected rows;
    its exact zero pattern decides "unbounded" (RHS vanishes on K) without a tolerance.
    """
    nn = model.order * model.size
    T_inv = port_inverse(model)
    exact_columns = [
        [-gains[j] * T_inv[i, j] + T_inv[i, nn + j] for j in range(nn)] for i in range(2 * nn)
    ]
    nonzero = [[not vanishes(x) for x in row] for row in exact_columns]
    root = [math.sqrt(float(g)) for g in gains]
    columns = [[float(x) / root[j] for j, x in enumerate(row)] for row in exact_columns]
    out: dict[tuple[int, int], float | None] = {}
    todo: list[tuple[int, int, list[int], list[int]]] = []
    for mask, c in jobs:
        rows = list(cands[c].case.selected)
        pick = [j for j in range(nn) if mask >> j & 1]
        if not any(nonzero[i][j] for i in rows for j in pick):
            out[mask, c] = None
        else:
            todo.append((mask, c, rows, pick))
    if len(todo) <= PURE_PYTHON_JOBS:
        for mask, c, rows, pick in todo:
            M = [[columns[i][j] for j in pick] for i in rows]
            B = [[sum(r[a] * r[b] for r in M) for b in range(len(pick))] for a in range(len(pick))]
            out[mask, c] = 1.0 / max(_jacobi_eigenvalues(B))
        if progress is not None and total > PROGRESS_THRESHOLD:
            progress(total, total)
        return out
    import numpy as np

    cols = np.array(columns)
    by_shape: dict[tuple[int, int], list[tuple[int, int, list[int], list[int]]]] = {}
    for job in todo:
        by_shape.setdefault((job[1], len(job[3])), []).append(job)
    done = 0
    for (c, _q), group in sorted(by_shape.items(), key=lambda item: item[0][1]):
        selected = np.array(cands[c].case.selected)
        picks = np.array([job[3] for job in group])
        M = cols[selected][:, picks].transpose(1, 0, 2)  # (subsets, |S|, q)
        top = np.linalg.eigvalsh(np.einsum("kia,kib->kab", M, M))[:, -1]
        for job, mu in zip(group, top, strict=True):
            out[job[0], job[1]] = float(1.0 / mu)
        done += len(group)
        if progress is not None and total > PROGRESS_THRESHOLD:
            progress(min(total, round(total * done / len(todo))), total)
    return out


def _kappas_with_plant_feedback(
    model: BCPHS,
    gains: tuple[sympy.Expr, ...],
    cands: tuple[Candidate, ...],
    jobs: list[tuple[int, int]],
    progress: Callable[[int, int], None] | None,
    total: int,
) -> dict[tuple[int, int], float | None]:
    """κ* per (subset mask, candidate) through each subset's error system (module docstring)."""
    from phdesign.symbolic.certificate import certify
    from phdesign.symbolic.observer import error_system, port_matrices, sensor_matrix

    U, Y = port_matrices(model)
    feedback = plant_feedback(model)
    out: dict[tuple[int, int], float | None] = {}
    systems: dict[int, Any] = {}
    for done, (mask, c) in enumerate(jobs, start=1):
        if mask not in systems:
            pick = _members(mask)
            L = sympy.diag(*[gains[j - 1] for j in pick])
            C_m = sensor_matrix(pick, model.n_ports)
            systems[mask] = error_system(model.order, model.size, U, Y, C_m, L, feedback)
        cert = certify(systems[mask], cands[c].case.selected, "float")
        out[mask, c] = None if cert.unbounded else cert.kappa_float
        if progress is not None and total > PROGRESS_THRESHOLD:
            progress(round(total * done / len(jobs)), total)
    return out


def _jacobi_eigenvalues(B: list[list[float]]) -> list[float]:
    """Eigenvalues of a small symmetric matrix by cyclic Jacobi rotations (pure Python)."""
    A = [row[:] for row in B]
    n = len(A)
    for _sweep in range(50):
        off = sum(A[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        scale = sum(A[i][i] ** 2 for i in range(n))
        if off <= 1e-32 * scale or off == 0.0:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if A[p][q] == 0.0:
                    continue
                theta = (A[q][q] - A[p][p]) / (2.0 * A[p][q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                cos = 1.0 / math.sqrt(t * t + 1.0)
                sin = t * cos
                for k in range(n):
                    akp, akq = A[k][p], A[k][q]
                    A[k][p], A[k][q] = cos * akp - sin * akq, sin * akp + cos * akq
                for k in range(n):
                    apk, aqk = A[p][k], A[q][k]
                    A[p][k], A[q][k] = cos * apk - sin * aqk, sin * apk + cos * aqk
    return [A[i][i] for i in range(n)]


def _members(mask: int) -> tuple[int, ...]:
    return tuple(j + 1 for j in range(mask.bit_length()) if mask >> j & 1)


def _minimal_sets(
    verdict_code: list[int], names: tuple[str, ...], nn: int
) -> dict[str, tuple[tuple[int, ...], ...]]:
    """Return the sets with a verdict no proper subset has (DP over bit masks)."""
    total = 1 << nn
    verdict = list(verdict_code)
    verdict[0] = -1  # the empty set has no verdict
    # below[v][m]: some proper non-empty subset of m has verdict v
    minimal: dict[str, list[tuple[int, ...]]] = {name: [] for name in names}
    below = [[False] * total for _ in names]
    for m in range(1, total):
        for v in range(len(names)):
            flag = False
            for j in range(nn):
                if m >> j & 1:
                    smaller = m & ~(1 << j)
                    if smaller and (verdict[smaller] == v or below[v][smaller]):
                        flag = True
                        break
            below[v][m] = flag
        if not below[verdict[m]][m]:
            minimal[names[verdict[m]]].append(_members(m))
    return {k: tuple(sorted(v, key=lambda s: (len(s), s))) for k, v in minimal.items()}
