r"""The plant's own boundary feedback: the ``[feedback]`` section of a model, as data.

A model's ``[feedback]`` section closes the inputs :math:`u_c` (a subset of the
:math:`Nn` inputs of ``[ports]``) with a static output feedback

.. math::

    u_c = -K\, y_c, \qquad K + K^\top \succeq 0 ,

(dampers and impedances) and leaves the other inputs :math:`u_r` as the plant's external
inputs.  This module holds that data (:class:`Feedback`), reads it from a model file's
table and checks its indices and the shape of :math:`K`; the model's validation checks
:math:`K + K^\top \succeq 0` (:mod:`phdesign.symbolic.validation`), and the closed plant's
ports and the operations that close inputs live in :mod:`phdesign.symbolic.closing`.

Examples
--------
>>> feedback = feedback_from_mapping({"inputs": [2], "gain": [["k"]]}, ["k"])
>>> feedback.closed, external_indices(2, feedback)
((1,), (0,))
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import ModelError
from phdesign.symbolic.definition import parse_matrix

__all__ = [
    "Feedback",
    "check_feedback_indices",
    "check_input_index",
    "external_indices",
    "external_numbering",
    "feedback_from_mapping",
]


@dataclass(frozen=True)
class Feedback:
    r"""The plant's own boundary feedback :math:`u_c = -K y_c`.

    Parameters
    ----------
    inputs : tuple of int
        1-based indices into the model's ``[ports].inputs`` (and, for the collocated
        outputs, ``[ports].outputs``) that are closed.
    gain : sympy.ImmutableMatrix
        :math:`K`, ``c x c`` (``c = len(inputs)``), numbers or expressions in the
        parameters; row ``i`` belongs to ``inputs[i]``.
    """

    inputs: tuple[int, ...]
    gain: sympy.ImmutableMatrix

    @property
    def closed(self) -> tuple[int, ...]:
        """0-based indices of the closed ports."""
        return tuple(i - 1 for i in self.inputs)


def external_indices(n_ports: int, feedback: Feedback | None) -> tuple[int, ...]:
    """0-based indices of the open ports that stay external inputs, in order."""
    closed = set(feedback.closed) if feedback is not None else set()
    return tuple(j for j in range(n_ports) if j not in closed)


def external_numbering(n_ports: int, feedback: Feedback) -> str:
    """Say which of the model's ports each external index is after ``feedback``.

    Examples
    --------
    >>> import sympy
    >>> torque = Feedback((3,), sympy.ImmutableMatrix([[1]]))
    >>> closed, kept = external_numbering(4, torque).split(": ")
    >>> closed
    '[feedback] closes u3'
    >>> kept
    "the external u1, u2, u3 (and y1, y2, y3) are the model's u1, u2, u4 (y1, y2, y4)"
    """
    kept = external_indices(n_ports, feedback)
    closed = ", ".join(f"u{i}" for i in feedback.inputs)

    def names(letter: str, indices: Sequence[int]) -> str:
        return ", ".join(f"{letter}{j + 1}" for j in indices)

    external = range(len(kept))
    return (
        f"[feedback] closes {closed}: the external {names('u', external)} (and "
        f"{names('y', external)}) are the model's {names('u', kept)} ({names('y', kept)})"
    )


def check_input_index(what: str, index: object, n_inputs: int) -> None:
    """Refuse an ``index`` that is not a 1-based index into the model's ``[ports].inputs``.

    Raises
    ------
    ModelError
        Naming ``what`` (``feedback.inputs[1]``) with the expected range.
    """
    if isinstance(index, bool) or not isinstance(index, int):
        raise ModelError(f"{what} must be a 1-based input index; found {index!r}")
    if not 1 <= index <= n_inputs:
        raise ModelError(
            f"{what} = {index} is not an input of the model; "
            f"expected an index in 1..{n_inputs} into [ports].inputs"
        )


def check_feedback_indices(feedback: Feedback, n_inputs: int) -> None:
    """Refuse indices that are not inputs of the model, repeated ones and a misshapen K.

    Raises
    ------
    ModelError
        Naming the offending entry, with the expected range.
    """
    if not feedback.inputs:
        raise ModelError("feedback.inputs must name at least one input; found none")
    seen: set[int] = set()
    for position, index in enumerate(feedback.inputs, start=1):
        check_input_index(f"feedback.inputs[{position}]", index, n_inputs)
        if index in seen:
            raise ModelError(
                f"feedback.inputs[{position}] = {index} is repeated; expected distinct inputs"
            )
        seen.add(index)
    c = len(feedback.inputs)
    if feedback.gain.shape != (c, c):
        raise ModelError(
            f"Incompatible dimensions of feedback gain K matrix; expected {(c, c)} "
            f"(one row and column per closed input) but found {feedback.gain.shape}"
        )


def feedback_from_mapping(
    value: Feedback | Mapping[str, Any], parameters: Sequence[str]
) -> Feedback:
    """Read ``{"inputs": [2], "gain": [["k"]]}`` (a model file's table) into :class:`Feedback`.

    Raises
    ------
    ModelError
        If keys are missing or unknown, ``inputs`` is not a list of integers, or the
        gain is not a square matrix of numbers or expressions in the parameters.
    """
    if isinstance(value, Feedback):
        return value
    if not isinstance(value, Mapping) or set(value) != {"inputs", "gain"}:
        found = sorted(value) if isinstance(value, Mapping) else repr(value)
        raise ModelError(f"feedback must hold exactly inputs and gain; found {found}")
    inputs = value["inputs"]
    if isinstance(inputs, str) or not isinstance(inputs, Sequence):
        raise ModelError(
            f"feedback.inputs must be a list of 1-based input indices such as [2]; "
            f"found {inputs!r}"
        )
    return Feedback(tuple(inputs), parse_matrix(value["gain"], "feedback gain K", parameters))
