r"""κ* of every holding (sensor set, variant) pair of the sensor search, in floating point.

With unit-row sensors :math:`C_m` on the outputs :math:`M` and :math:`L = \mathrm{diag}(g_M)`,
the admissible traces are :math:`K_m = T^{-1}(-C_m^\top L; C_m^\top)` and

.. math::

    \kappa^* = 1/\sigma_{\max}(S K_m L^{-1/2})^2 ,

:math:`S` the rows a variant selects: Jacobi rotations in pure Python for small searches
(numpy would cost more to import than the work), batched LAPACK ``eigvalsh`` over subsets
otherwise.  "Unbounded" (RHS ≡ 0 on K) is read from the exact zero pattern, never from a
tolerance.  A plant with its own boundary feedback goes through each subset's error system
and :func:`~phdesign.symbolic.certificate.certify` instead: the closed ports' block
:math:`K` is not diagonal in general.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.progress import report as report_stage
from phdesign.symbolic.certificate import certify
from phdesign.symbolic.closing import plant_feedback
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import error_system, port_inverse, port_matrices, sensor_matrix
from phdesign.symbolic.search_result import Candidate

__all__ = ["PROGRESS_THRESHOLD", "PURE_PYTHON_JOBS", "members", "subset_kappas"]

#: Above this many subsets the search reports progress (when a callback is given).
PROGRESS_THRESHOLD = 512

#: A job: (subset mask, candidate index).
Job = tuple[int, int]
Progress = Callable[[int, int], None] | None
Gains = tuple[sympy.Expr, ...]
Kappas = dict[Job, float | None]


@dataclass(frozen=True)
class _Report:
    """Reports ``progress(done, total)``, for searches of more than PROGRESS_THRESHOLD sets.

    The stage goes to the progress callback in force as well (:mod:`phdesign.core.progress`).
    """

    progress: Progress
    total: int

    def __call__(self, done: int) -> None:
        report_stage(f"classify: sensor sets {done} of {self.total}")
        if self.progress is not None and self.total > PROGRESS_THRESHOLD:
            self.progress(done, self.total)


def members(mask: int) -> tuple[int, ...]:
    """Return the 1-based outputs of a sensor set given as a bit mask (bit j: output j+1)."""
    return tuple(j + 1 for j in range(mask.bit_length()) if mask >> j & 1)


def subset_kappas(
    model: BCPHS,
    gains: Gains,
    cands: tuple[Candidate, ...],
    jobs: list[Job],
    progress: Progress,
    total: int,
) -> Kappas:
    """Return κ* per (subset mask, candidate), ``None`` when unbounded (module docstring).

    ``progress(done, total)`` is called when there are more than
    :data:`PROGRESS_THRESHOLD` subsets.
    """
    kappas = _kappas if model.feedback is None else _kappas_with_plant_feedback
    return kappas(model, gains, cands, jobs, _Report(progress, total))


#: Up to this many (subset, variant) pairs κ* is computed in pure Python (Jacobi
#: eigenvalues): importing numpy would cost more than the whole computation.
PURE_PYTHON_JOBS = 600

#: A bounded job: (subset mask, candidate index, selected trace rows, measured outputs).
_Todo = tuple[int, int, list[int], list[int]]


def _kappas(
    model: BCPHS, gains: Gains, cands: tuple[Candidate, ...], jobs: list[Job], report: _Report
) -> Kappas:
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
    out: Kappas = {}
    todo: list[_Todo] = []
    for mask, c in jobs:
        rows = list(cands[c].case.selected)
        pick = [j for j in range(nn) if mask >> j & 1]
        if not any(nonzero[i][j] for i in rows for j in pick):
            out[mask, c] = None
        else:
            todo.append((mask, c, rows, pick))
    if len(todo) <= PURE_PYTHON_JOBS:
        out.update(_pure_python(columns, todo))
        report(report.total)
        return out
    out.update(_batched(columns, cands, todo, report))
    return out


def _pure_python(columns: list[list[float]], todo: list[_Todo]) -> dict[Job, float]:
    """κ* of each job from its Gram matrix's largest eigenvalue (Jacobi rotations)."""
    out: dict[Job, float] = {}
    for mask, c, rows, pick in todo:
        M = [[columns[i][j] for j in pick] for i in rows]
        B = [[sum(r[a] * r[b] for r in M) for b in range(len(pick))] for a in range(len(pick))]
        out[mask, c] = 1.0 / max(_jacobi_eigenvalues(B))
    return out


def _batched(
    columns: list[list[float]],
    cands: tuple[Candidate, ...],
    todo: list[_Todo],
    report: _Report,
) -> dict[Job, float]:
    """κ* of the jobs grouped by (variant, number of sensors): one LAPACK call per group."""
    import numpy as np

    out: dict[Job, float] = {}
    cols = np.array(columns)
    by_shape: dict[tuple[int, int], list[_Todo]] = {}
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
        report(min(report.total, round(report.total * done / len(todo))))
    return out


def _kappas_with_plant_feedback(
    model: BCPHS, gains: Gains, cands: tuple[Candidate, ...], jobs: list[Job], report: _Report
) -> Kappas:
    """κ* per (subset mask, candidate) through each subset's error system (module docstring)."""
    U, Y = port_matrices(model)
    feedback = plant_feedback(model)
    out: Kappas = {}
    systems: dict[int, Any] = {}
    for done, (mask, c) in enumerate(jobs, start=1):
        if mask not in systems:
            pick = members(mask)
            L = sympy.diag(*[gains[j - 1] for j in pick])
            C_m = sensor_matrix(pick, model.n_ports)
            systems[mask] = error_system(model.order, model.size, U, Y, C_m, L, feedback)
        cert = certify(systems[mask], cands[c].case.selected, "float")
        out[mask, c] = None if cert.unbounded else cert.kappa_float
        report(round(report.total * done / len(jobs)))
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
