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

The constants κ* of the holding pairs are computed in floating point
(:mod:`phdesign.symbolic.search_kappa`); the results are the objects of
:mod:`phdesign.symbolic.search_result`.

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

from typing import Any

import sympy

from phdesign.core import limits
from phdesign.core.errors import ObserverError
from phdesign.core.text import matrix_text, number_text
from phdesign.symbolic.assumption import model_assumption
from phdesign.symbolic.classify import classify
from phdesign.symbolic.closing import plant_feedback
from phdesign.symbolic.coupled_classify import classify_coupled
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.feedback import external_indices
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import gain_matrix, port_inverse, sensor_matrix
from phdesign.symbolic.propositions import VERDICTS, strength, variant_cases, verdict_of
from phdesign.symbolic.search_kappa import (
    Job,
    Progress,
    members,
    subset_kappas,
)
from phdesign.symbolic.search_result import Candidate, SensorSearch, SubsetResult
from phdesign.symbolic.sensors import gain_symbols
from phdesign.symbolic.system import require_model

__all__ = ["candidates", "search_sensors"]


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
    progress: Progress = None,
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
    nn = model.n_ports
    gains = _gain_vector(gain, nn)
    if model.boundary_systems:
        return _coupled_search(model, gains)
    cands = candidates(model)
    total = 2**nn - 1
    holds = _decisions(cands, total)
    kappa: dict[Job, float | None] = {}  # (mask, candidate) -> κ*, None = unbounded
    if gains is not None:
        jobs = [
            (mask, c) for mask in range(1, total + 1) for c in range(len(cands)) if holds[mask][c]
        ]
        kappa = subset_kappas(model, gains, cands, jobs, progress, total)
    verdict_code = [VERDICTS.index("inconclusive")] * (total + 1)
    results = []
    for mask in sorted(range(1, total + 1), key=lambda m: (bin(m).count("1"), members(m))):
        result = _subset_result(mask, cands, holds[mask], kappa)
        verdict_code[mask] = VERDICTS.index(result.verdict)
        results.append(result)
    return SensorSearch(
        model=model.name,
        order=model.order,
        size=model.size,
        gains=tuple("symbolic" for _ in range(nn))
        if gains is None
        else tuple(number_text(g) for g in gains),
        candidates=cands,
        subsets=tuple(results),
        minimal=_minimal_sets(verdict_code, VERDICTS, nn),
    )


def _coupled_search(model: BCPHS, gains: tuple[sympy.Expr, ...] | None) -> SensorSearch:
    """Classify every subset of a coupled model's outputs (the boundary systems' too).

    Each subset is classified by :func:`~phdesign.symbolic.coupled_classify.classify_coupled`
    with the diagonal gains it measures: numbers, or (``gains`` None) the positive symbols
    ``l_j`` of the outputs j it measures.
    """
    nn = model.n_ports
    symbolic = gains is None
    gains = gain_symbols(nn) if gains is None else gains
    total = 2**nn - 1
    verdict_code = [VERDICTS.index("inconclusive")] * (total + 1)
    results = []
    for mask in sorted(range(1, total + 1), key=lambda m: (bin(m).count("1"), members(m))):
        picked = members(mask)
        C_m = sensor_matrix(picked, nn)
        L = sympy.diag(*[gains[j - 1] for j in picked])
        found = classify_coupled(model, C_m, L, "auto", static=classify)
        best = found.best
        verdict_code[mask] = VERDICTS.index(found.verdict)
        results.append(
            SubsetResult(
                sensors=picked,
                verdict=found.verdict,
                best=None if best is None else best.name,
                kappa=None if best is None else best.kappa,
                unbounded=False,
                holding=tuple(r.convergence for r in found.results if r.holds),
            )
        )
    return SensorSearch(
        model=model.name,
        order=model.order,
        size=model.size,
        gains=tuple("symbolic" if symbolic else number_text(g) for g in gains),
        candidates=(),
        subsets=tuple(results),
        minimal=_minimal_sets(verdict_code, VERDICTS, nn),
    )


def _decisions(cands: tuple[Candidate, ...], total: int) -> list[list[bool]]:
    """Whether each candidate holds on each subset mask: exact and combinatorial.

    A candidate holds iff the subset contains its required set (module docstring).
    """
    required = [sum(1 << (j - 1) for j in c.required) for c in cands]
    return [
        [required[c] & ~mask == 0 and cands[c].attainable for c in range(len(cands))]
        for mask in range(total + 1)
    ]


def _subset_result(
    mask: int,
    cands: tuple[Candidate, ...],
    holds: list[bool],
    kappa: dict[Job, float | None],
) -> SubsetResult:
    """Return the verdict of one subset and its strongest holding variant, by κ*."""
    holding = [c for c in range(len(cands)) if holds[c]]
    verdict = verdict_of(cands[c].convergence for c in holding)
    best = None
    if holding:

        def key(c: int) -> tuple[int, float]:
            value = kappa.get((mask, c))
            unbounded = (mask, c) in kappa and value is None
            return strength(cands[c].convergence, value, unbounded)

        best = max(holding, key=key)
    value = None if best is None else kappa.get((mask, best))
    partition = None if best is None else cands[best].partition
    return SubsetResult(
        sensors=members(mask),
        verdict=verdict,
        best=None if best is None else cands[best].name,
        kappa=value,
        unbounded=best is not None and (mask, best) in kappa and value is None,
        holding=tuple(dict.fromkeys(cands[c].name for c in holding)),
        partition=None if partition is None else (partition.x1, partition.x2),
    )


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
            minimal[names[verdict[m]]].append(members(m))
    return {k: tuple(sorted(v, key=lambda s: (len(s), s))) for k, v in minimal.items()}
