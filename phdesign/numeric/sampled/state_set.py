r"""The initial states a sampled observer is verified on: the export's x0 and smooth states.

One initial state and one window is no specification: the ratio of a sampled observer's
error floor to the continuous one's depends on both (docs/sampled.rst, "The sampled limit"). The
default verification set is the export's own initial state followed by
:func:`boundary_states`: for each state component i, a few polynomial efforts

.. math::

    e(z) = p(s)\,\mathbf e_i, \qquad s = \frac{z - a}{b - a}, \qquad x(z) = H(z)^{-1} e(z),

of the lowest degrees whose traces meet the plant's boundary conditions with the inputs at
rest: :math:`U v = 0` on the external ports, :math:`(U_c + K Y_c) v = 0` on the ports a
model's ``[feedback]`` closes (:math:`u_c = -K y_c`), with v the trace vector of e
(:func:`~phdesign.symbolic.ports.trace_index`), and :math:`(U_p + K Y_p) v = 0` on the
ports a boundary system joins, at rest (:math:`u_p = -K y_p + F e_c` with
:math:`e_c = 0`). At each new degree q the state is the
polynomial of degree q, top coefficient 1, that meets them with the smallest coefficient
norm (unique: a least-norm solution). Such states are smooth and in the domain of the
plant's operator, so the plant resolves them: their floors measure the observer, not the
plant's unresolved tail (an x0 that violates the boundary conditions excites it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sl

from phdesign.numeric.bridge import NumericModel
from phdesign.symbolic.ports import trace_index

__all__ = ["InitialState", "boundary_states", "verification_states"]

#: States per component in the default verification set.
PER_COMPONENT = 2


@dataclass(frozen=True)
class InitialState:
    """A plant initial state ``x0(z) -> (m, n)`` and how the reports name it."""

    text: str
    function: Callable[[np.ndarray], np.ndarray] = field(repr=False, compare=False)


def _boundary_rows(nm: NumericModel) -> np.ndarray:
    """Rows over the trace vector that vanish when the inputs are at rest (module docstring)."""
    rows = np.array(nm.U, dtype=float)
    Y = np.asarray(nm.Y, dtype=float)
    closures = [] if nm.feedback is None else [(list(nm.feedback.closed), nm.feedback.gain)]
    # a boundary system at rest (e_c = 0) leaves its static part u_p = -K y_p
    closures += [(list(b.joined), b.K) for b in nm.boundary]
    for closed, K in closures:
        rows[closed] = rows[closed] + K @ Y[closed]
    return rows


def _trace_matrix(nm: NumericModel, component: int, degree: int) -> np.ndarray:
    """Map the coefficients of p (in s, degree ``degree``) to the trace vector of p e_i."""
    N, n = nm.order, nm.size
    a, b = nm.interval
    T = np.zeros((2 * N * n, degree + 1))
    for k in range(N):
        for j in range(k, degree + 1):
            falling = float(np.prod(np.arange(j - k + 1, j + 1)))  # j!/(j-k)!
            scale = falling / (b - a) ** k
            T[trace_index(component, k, "b", N, n), j] = scale  # s = 1
            if j == k:
                T[trace_index(component, k, "a", N, n), j] = scale  # s = 0
    return T


def _polynomial_text(coefficients: np.ndarray, variable: str) -> str:
    """Return ``c0 + c1 s + ...`` with four significant digits, zero terms left out."""
    terms = []
    for j, c in enumerate(coefficients):
        if abs(c) < 1e-12 * np.max(np.abs(coefficients)):
            continue
        power = "" if j == 0 else variable if j == 1 else f"{variable}**{j}"
        value = f"{c:.4g}"
        if power and value in ("1", "-1"):
            terms.append(power if value == "1" else f"-{power}")
        else:
            terms.append(f"{value}*{power}" if power else value)
    return " + ".join(terms).replace("+ -", "- ")


def _state(nm: NumericModel, component: int, c: np.ndarray) -> InitialState:
    a, b = nm.interval
    n = nm.size

    def x0(z: np.ndarray) -> np.ndarray:
        zz = np.atleast_1d(np.asarray(z, dtype=float))
        e = np.zeros((zz.size, n))
        e[:, component - 1] = np.polynomial.polynomial.polyval((zz - a) / (b - a), c)
        return np.linalg.solve(nm.H(zz), e[:, :, None])[:, :, 0]

    variable = "z" if (a, b) == (0.0, 1.0) else "s"
    where = "" if variable == "z" else f", s = (z - {a:g})/{b - a:g}"
    text = f"e{component} = {_polynomial_text(c, variable)}{where} (meets the boundary conditions)"
    return InitialState(text, x0)


def boundary_states(
    nm: NumericModel, per_component: int = PER_COMPONENT
) -> tuple[InitialState, ...]:
    """Return ``per_component`` smooth states per component that meet the boundary conditions.

    Degrees up to 2N + 2 + ``per_component`` are tried; a component with fewer such states
    contributes fewer (module docstring).

    Examples
    --------
    The paper's beam: e1 and its derivative vanish at 0, e2 and its derivative at 1.

    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> beam = to_numeric(load_builtin("euler-bernoulli"))
    >>> [s.text.split(" (")[0] for s in boundary_states(beam)]
    ['e1 = z**2', 'e1 = z**3', 'e2 = 1 - 2*z + z**2', 'e2 = 0.6667 - 0.3333*z - 1.333*z**2 + z**3']
    """
    rows = _boundary_rows(nm)
    out: list[InitialState] = []
    for component in range(1, nm.size + 1):
        found = 0
        for degree in range(2 * nm.order + 2 + per_component + 1):
            if found == per_component:
                break
            null = sl.null_space(rows @ _trace_matrix(nm, component, degree))
            if null.shape[1] == 0 or np.max(np.abs(null[degree])) < 1e-10:
                continue  # nothing of this degree meets them
            # least-norm coefficients with top coefficient 1, in the null space
            weights = null[degree] / float(null[degree] @ null[degree])
            c = null @ weights
            out.append(_state(nm, component, c))
            found += 1
    return tuple(out)


def verification_states(
    nm: NumericModel, given: tuple[InitialState, ...], default_x0: InitialState
) -> tuple[InitialState, ...]:
    """Return the verification set: the ``given`` states, else x0 and :func:`boundary_states`."""
    if given:
        return given
    return (default_x0, *boundary_states(nm))
