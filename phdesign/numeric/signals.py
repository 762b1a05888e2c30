r"""What each signal of an export is: its name, the trace it is, the model's own port.

Every export names its signals the same way: the plant inputs ``u1..`` and outputs ``y1..``
(the model's external ports), a measured output by the output it picks (``y3``; a row of
:math:`C_m` that combines outputs is ``y_m<j>``), the observer's estimates ``yhat1..`` and the
displacement ``w(z)``.  This module says what each name *is*, in the words of the model file:
``y3 = e1'(1)``.  After a ``[feedback]`` closure the external ports are renumbered (closing
u3 of four makes the model's u4 the external u3), and each description says so:
``u3 = e2'(1) (the model's u4)``.

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.numeric.bridge import to_numeric
>>> beam = to_numeric(load_builtin("euler-bernoulli"))
>>> port_description(beam, "y", 2)
"y3 = e1'(1)"
>>> sensor_descriptions(beam, np.array([[0, 0, 1, 0], [0, 0, 0, 1]]))
("y3 = e1'(1)", 'y4 = -e1(1)')
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from phdesign.core.text import number_text
from phdesign.numeric.bridge import NumericModel

__all__ = [
    "estimate_descriptions",
    "input_descriptions",
    "model_port",
    "port_description",
    "renumbering",
    "sensor_descriptions",
    "signal_lines",
]


def model_port(nm: NumericModel, index: int) -> int | None:
    """Return the model file's 1-based number of external port ``index`` (0-based).

    ``None`` for a boundary system's own port (they follow the PDE's open ports).
    """
    closed = set(() if nm.feedback is None else nm.feedback.closed)
    closed |= {j for b in nm.boundary for j in b.joined}
    kept = [j for j in range(nm.order * nm.size) if j not in closed]
    return kept[index] + 1 if index < len(kept) else None


def port_description(nm: NumericModel, letter: str, index: int) -> str:
    """``u3 = e2(1)``: external input (``letter="u"``) or output ``index`` (0-based) as a trace.

    After a ``[feedback]`` closure that renumbers it: ``u3 = e2'(1) (the model's u4)``.
    """
    traces = nm.input_traces if letter == "u" else nm.output_traces
    text = f"{letter}{index + 1} = {traces[index]}"
    original = model_port(nm, index)
    if original is None or original == index + 1:
        return text
    return f"{text} (the model's {letter}{original})"


def sensor_descriptions(nm: NumericModel, C_m: np.ndarray) -> tuple[str, ...]:
    """Each measured signal: ``y3 = e1'(1)`` for a unit row, ``y_m2 = 0.5·y3 + y4`` else."""
    out = []
    for j, row in enumerate(np.atleast_2d(np.asarray(C_m, dtype=float))):
        hits = np.flatnonzero(row)
        if hits.size == 1 and row[hits[0]] == 1:
            out.append(port_description(nm, "y", int(hits[0])))
            continue
        terms = [
            f"y{i + 1}" if row[i] == 1 else f"{number_text(float(row[i]))}·y{i + 1}" for i in hits
        ]
        out.append(f"y_m{j + 1} = " + " + ".join(terms).replace("+ -", "- "))
    return tuple(out)


def input_descriptions(nm: NumericModel, C_m: np.ndarray) -> tuple[str, ...]:
    """Return the observer's inputs v = (u; y_m): every external input, then every sensor."""
    inputs = tuple(port_description(nm, "u", i) for i in range(nm.n_ports))
    return inputs + sensor_descriptions(nm, C_m)


def estimate_descriptions(nm: NumericModel, points: Sequence[Any] = ()) -> tuple[str, ...]:
    """Return the observer's outputs: ``yhat3 = estimate of y3 = e1'(1)``, then each point's.

    ``points`` are point outputs (a ``Functional`` of kind ``"displacement"``: ``w(1) =
    estimated displacement at z = 1``, ``rotation(1) = estimated rotation at z = 1``).
    """
    out = [f"yhat{i + 1} = estimate of {port_description(nm, 'y', i)}" for i in range(nm.n_ports)]
    for f in points:
        what = "displacement" if f.field_name == "w" else f.field_name
        out.append(f"{f.name} = estimated {what} at z = {f.point:g}")
    return tuple(out)


def renumbering(nm: NumericModel) -> str | None:
    """Say how a ``[feedback]`` closure renumbered the external ports (None if it did not).

    ``"[feedback] closes u3: external u3 = the model's u4, y3 = y4"``.
    """
    if nm.feedback is None:
        return None
    moved = [
        (i + 1, model_port(nm, i))
        for i in range(nm.n_ports)
        if model_port(nm, i) not in (None, i + 1)
    ]
    closed = ", ".join(f"u{c + 1}" for c in nm.feedback.closed)
    if not moved:
        return f"[feedback] closes {closed}; the external ports keep the model's numbers"
    pairs = ", ".join(f"u{i} = the model's u{j} (y{i} = y{j})" for i, j in moved)
    return f"[feedback] closes {closed}: external {pairs}"


def signal_lines(
    inputs: Sequence[str], outputs: Sequence[str], renumbering: str | None = None
) -> list[str]:
    """Return ``inputs v: u1 = e1(0), ...`` and ``outputs: ...``, and the renumbering if any."""
    lines = [f"inputs v: {', '.join(inputs)}", f"outputs: {', '.join(outputs)}"]
    return lines + ([] if renumbering is None else [renumbering])
