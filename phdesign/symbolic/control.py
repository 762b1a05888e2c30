r"""Observer-based boundary control: the loop's data, its checks and its certificates.

The plant is a BC-PHS with external inputs :math:`u` and power-conjugate outputs
:math:`y`.  A controller actuates some inputs :math:`u_a` (``actuate``) with the
*estimate* of their collocated outputs, the observer of :mod:`phdesign.symbolic.observer`
runs on the measured outputs, and the other inputs :math:`u_r` are free signals
(zero by default):

.. math::

    u_a = -K \hat y_a, \quad K + K^\top \succ 0, \qquad
    \hat u = u + C_m^\top L (y_m - \hat y_m) .

*Separation.*  With :math:`\tilde x = x - \hat x` and :math:`\tilde y = y - \hat y`,

.. math::

    u_a = -K \hat y_a = -K y_a + K \tilde y_a ,

so the plant is the **controlled plant** (the same PDE closed by :math:`u_a = -K y_a`,
again a BC-PHS, with the dissipative boundary of :mod:`phdesign.symbolic.closing`)
driven at the actuated port by :math:`K\tilde y_a`.  The observer computes :math:`u`
itself, so :math:`\tilde u = u - \hat u = -C_m^\top L C_m \tilde y` whatever :math:`u`
is: the **error system** is autonomous.  In the coordinates :math:`(x, \tilde x)` the
loop is block-triangular,

.. math::

    \frac{d}{dt}\begin{pmatrix} x \\ \tilde x \end{pmatrix}
    = \begin{pmatrix} \mathcal A_K & \mathcal B_a K \tilde{\mathcal C}_a \\
                      0 & \tilde{\mathcal A} \end{pmatrix}
      \begin{pmatrix} x \\ \tilde x \end{pmatrix},

and its spectrum is the controlled plant's together with the error system's.

*Stability of the cascade.*  Along the loop (:math:`u_r = 0`) the plant's energy obeys
:math:`\dot H \le u_a^\top y_a = -y_a^\top K y_a + \tilde y_a^\top K^\top y_a \le
-c|y_a|^2 + \|K\| |\tilde y_a| |y_a|` with :math:`c = \lambda_{\min}(\operatorname{sym}
K) > 0`, hence, from any time :math:`s`,

.. math::

    H(t) \le H(s) + \frac{\|K\|^2}{4c} \int_s^t |\tilde y_a|^2\, d\tau .

The error system has :math:`\dot{\tilde H} \le -\mathrm{LHS}`, and a holding variant
gives :math:`\mathrm{LHS} \ge \kappa\,\mathrm{RHS}`, so
:math:`\int_s^\infty (\mathrm{LHS} + \mathrm{RHS})\, d\tau \le (1 + 1/\kappa)\tilde H(s)`.
When :math:`|\tilde y_a|^2` is bounded by LHS + RHS of the holding variants on the
admissible traces (an exact kernel inclusion, :func:`error_output_bounded`), the input
:math:`K\tilde y_a` that drives the controlled plant is square-integrable with the error's
own decay.  Splitting :math:`x(t)` at :math:`s = t/2` into the free motion of the
controlled plant and the response to that input gives the loop's verdict
(:func:`loop_verdict`):

* both exponential: the loop converges exponentially;
* the controlled plant asymptotic or exponential and the error system exponential, or
  asymptotic with :math:`\tilde y_a` bounded as above: the loop converges
  asymptotically (the free motion tends to 0, the forced part's energy is bounded by the
  tail of :math:`\int|\tilde y_a|^2`);
* otherwise the certificates say nothing about the loop: *inconclusive* (never
  "unstable": the propositions are sufficient conditions).

When the error system is exponential but :math:`\tilde y_a` is not bounded by its
certificate, the argument uses that :math:`\tilde y_a` is an admissible output of the
error system: the model is well-posed, as every N = 1 model with Lipschitz H is (Zwart,
Le Gorrec, Maschke and Villegas, ESAIM COCV 2010, for a dissipative boundary), and the
verdict's reason says that it rests on this.
With ``source="measured"`` (:math:`u_a = -K y_a` from the sensors, possible only where
:math:`y_a` is measured) the plant does not see the observer at all and the loop is as
good as the weaker of the two.

Examples
--------
>>> from phdesign.models import load_builtin
>>> from phdesign.symbolic.observer import sensor_matrix
>>> beam = load_builtin("euler-bernoulli")
>>> # tip shear force u4 = -ŷ4 (the tip velocity's estimate), only the root moment y2 measured
>>> result = classify_loop(beam, [4], feedback_gain(1, 1), sensor_matrix([2], 4),
...                        sympy.Matrix([[1]]))
>>> result.plant.verdict, result.error.verdict, result.verdict
('exponential', 'exponential', 'exponential')
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import LoopError, ObserverError
from phdesign.core.text import html_table, matrix_text, sensors_text
from phdesign.symbolic import boundary_systems as bsys
from phdesign.symbolic.classify import Classification, classify
from phdesign.symbolic.closing import close_inputs
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.feedback import external_indices
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import ObserverDesign
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.propositions import VARIANTS
from phdesign.symbolic.sensors import gain_matrix

__all__ = [
    "FEEDBACK_SOURCES",
    "LoopClassification",
    "actuated_indices",
    "check_collocated",
    "check_measured",
    "classify_loop",
    "controlled_plant",
    "error_output_bounded",
    "feedback_gain",
    "loop_verdict",
    "parse_indices",
]

#: What the controller feeds back: the observer's estimate ŷ_a or the measured y_a.
FEEDBACK_SOURCES = ("estimate", "measured")

_RANK = {"exponential": 2, "asymptotic": 1, "inconclusive": 0}


# --------------------------------------------------------------------------- arguments
def parse_indices(text: str, option: str) -> list[int]:
    """Read ``"3"`` or ``"3,4"`` (1-based indices) for the command-line ``option``."""
    out = []
    for part in str(text).split(","):
        try:
            out.append(int(part.strip()))
        except ValueError:
            raise LoopError(
                f"{option}: expected comma-separated 1-based indices like 3 or 3,4; "
                f"found {part.strip()!r} in {text!r}"
            ) from None
    return out


def actuated_indices(actuate: Any, model: BCPHS) -> tuple[int, ...]:
    """Check ``actuate`` (1-based indices into the model's external inputs) and return it.

    Raises
    ------
    LoopError
        If an index is not an input of the model, is repeated, or none is given.
    """
    values = [actuate] if isinstance(actuate, int) else list(actuate)
    inputs = bsys.external_input_labels(model)  # the PDE's open inputs, then the boundary systems'
    if not values:
        raise LoopError("actuate: expected at least one input index; found none")
    seen: list[int] = []
    for value in values:
        index = getattr(value, "item", lambda v=value: v)()  # numpy integers
        if isinstance(index, bool) or not isinstance(index, int):
            raise LoopError(f"actuate: expected 1-based input indices; found {value!r}")
        if not 1 <= index <= len(inputs):
            listed = ", ".join(f"u{i + 1} = {u}" for i, u in enumerate(inputs))
            raise LoopError(
                f"actuate: u{index} is not an input of the model; expected an index in "
                f"1..{len(inputs)} ({listed})"
            )
        if index in seen:
            raise LoopError(f"actuate: input u{index} is repeated; expected distinct inputs")
        seen.append(index)
    return tuple(seen)


def feedback_gain(value: Any, k: int) -> sympy.ImmutableMatrix:
    r"""Return the feedback gain :math:`K` (``k x k``), exact, with :math:`K + K^\top \succ 0`.

    Read by the observer gain's reader (:func:`~phdesign.symbolic.sensors.gain_matrix`),
    whose messages then name ``feedback K``.

    Parameters
    ----------
    value : number, sequence of numbers or matrix
        One number (:math:`K = kI`), one per actuated input (the diagonal), or the matrix
        in full (nested lists, numpy or sympy).  Entries are read exactly.
    k : int
        The number of actuated inputs.

    Raises
    ------
    LoopError
        Wrong shape or count, an entry that is not a finite number, a symbolic gain, or
        :math:`K + K^\top` not positive definite (checked exactly, Sylvester).

    Examples
    --------
    >>> feedback_gain("0.5", 2)
    Matrix([
    [1/2,   0],
    [  0, 1/2]])
    """
    if isinstance(value, str) and value.strip() == "symbolic":
        raise LoopError(
            "feedback K: symbolic feedback gains are not supported (the controlled plant "
            "is a model whose K has values); give numbers such as 1 or [1, 2]"
        )
    try:
        K = gain_matrix(value, k, "actuated input", name="feedback K", symbol="K")
    except ObserverError as error:
        message = str(error)
        if not message.startswith("feedback K"):  # K + Kᵀ: the matrix, named as the gain
            message = f"feedback {message}"
        reason = ": u_a = -K ŷ_a damps the plant only then" if "definite" in message else ""
        raise LoopError(f"{message}{reason}") from None
    return sympy.ImmutableMatrix(K)


def check_collocated(
    actuate: Sequence[int], outputs: int | Sequence[int] | None, model: BCPHS
) -> None:
    """Refuse a feedback from outputs that are not the power conjugates of ``actuate``.

    Raises
    ------
    LoopError
        Naming the output, the actuated input and its collocated output.
    """
    if outputs is None:
        return
    picked = [outputs] if isinstance(outputs, int) else list(outputs)
    if picked == list(actuate):
        return
    names = [format_expression(y, model.interval) for y in model.external_outputs]
    for position, (a, j) in enumerate(zip(actuate, picked, strict=False)):
        if a != j:
            seen = f"y{j} = {names[j - 1]}" if 1 <= j <= len(names) else f"y{j}"
            raise LoopError(
                f"feedback: {seen} is not collocated with the actuated input u{a}; its power "
                f"conjugate is y{a} = {names[a - 1]} (feedback output {position + 1}): "
                f"u{a} = -K ŷ{j} would not damp the plant, feed back y{a}"
            )
    raise LoopError(
        f"feedback: expected one fed-back output per actuated input ({len(actuate)}); "
        f"found {len(picked)}"
    )


def check_measured(actuate: Sequence[int], C_m: sympy.MatrixBase, model: BCPHS) -> None:
    """Refuse ``source="measured"`` unless every actuated output is a measurement.

    :math:`y_a` is measured when its unit row lies in the row space of :math:`C_m`
    (then :math:`y_a = F y_m`), decided exactly.
    """
    C = sympy.Matrix(C_m)
    rank = C.rank()
    for a in actuate:
        unit = sympy.zeros(1, C.cols)
        unit[0, a - 1] = 1
        if sympy.Matrix.vstack(C, unit).rank() != rank:
            name = format_expression(model.external_outputs[a - 1], model.interval)
            raise LoopError(
                f"feedback source measured: y{a} = {name} (collocated with the actuated u{a}) "
                "is not measured by these sensors; feed back its estimate "
                "(`feedback_source='estimate'`) or measure it"
            )


def controlled_plant(model: BCPHS, actuate: Sequence[int], K: sympy.MatrixBase) -> BCPHS:
    r"""Return the plant closed by :math:`u_a = -K y_a`, a BC-PHS with dissipative boundary.

    Its external inputs are the others (:func:`~phdesign.symbolic.closing.close_inputs`).
    """
    trace, K_t, own, K_b = bsys.split_actuated(model, actuate, K)  # a motor's voltage: its own
    closed = bsys.close_boundary_inputs(model, own, K_b) if own else model
    return close_inputs(closed, trace, K_t.tolist()) if trace else closed


# --------------------------------------------------------------------------- certificates
def _variant_indices(result: Any, order: int, size: int) -> tuple[int, ...]:
    variant = next(
        v for v in VARIANTS if (v.proposition, v.variant) == (result.proposition, result.variant)
    )
    partition = None if result.partition is None else (result.partition.x1, result.partition.x2)
    return variant.indices(order, size, partition)


def error_output_bounded(error: Classification, actuate: Sequence[int]) -> bool:
    r"""Whether :math:`|\tilde y_a|^2 \le c\,(\mathrm{LHS} + \sum \mathrm{RHS})` on the traces.

    The sum runs over the holding variants of the error system's classification.  On the
    admissible traces :math:`v = K_{\mathcal K}\tilde y` the left-hand side vanishes
    exactly on :math:`\ker C_d` and a right-hand side on :math:`\ker S K_{\mathcal K}`;
    the bound holds iff :math:`\tilde y_a` vanishes on the intersection (exact linear
    algebra, gain-free: :math:`G n = 0` on :math:`\ker C_d`).  Then
    :math:`\int_s^\infty |\tilde y_a|^2 \le C \tilde H(s)` (module docstring).
    """
    model = error.model
    es = ObserverDesign(model, error.C_m, error.L).error_system()
    C_d, _ = es.dissipation
    nn = model.order * model.size
    rows = [C_d]
    for r in error.results:
        if r.holds:
            S = list(_variant_indices(r, model.order, model.size))
            rows.append(es.K.extract(S, list(range(nn))))
    stacked = sympy.Matrix.vstack(*rows)
    external = external_indices(nn, model.feedback)
    picked = sympy.Matrix([[1 if c == external[a - 1] else 0 for c in range(nn)] for a in actuate])
    return all(all(vanishes(x) for x in picked * n) for n in stacked.nullspace())


def loop_verdict(plant: str, error: str, source: str, bounded: bool) -> tuple[str, str]:
    """Combine the two verdicts into the loop's (module docstring); return (verdict, reason)."""
    if plant == "inconclusive" or error == "inconclusive":
        which = " and ".join(
            name
            for name, v in (("the controlled plant", plant), ("the error system", error))
            if v == "inconclusive"
        )
        return "inconclusive", (
            f"{which} is not certified, so the propositions say nothing about the loop "
            "(sufficient conditions: the spectrum may still show it converges)"
        )
    if source == "measured":
        weaker = min(plant, error, key=_RANK.__getitem__)
        return weaker, (
            f"the plant is fed its measured outputs and runs on its own ({plant}), the "
            f"error system too ({error}): the loop is {weaker}"
        )
    driven = (
        "the error system's certificate bounds ∫|ỹ_a|², the input K ỹ_a that drives the "
        "controlled plant"
        if bounded
        else "assuming ỹ_a is an admissible output of the error system (a well-posed "
        "model, as every N = 1 model with Lipschitz H is), K ỹ_a, the input that drives "
        "the controlled plant, decays with the error"
    )
    if plant == error == "exponential":
        return "exponential", f"both converge exponentially and {driven}: exponential"
    if error == "exponential" or bounded:
        return "asymptotic", (
            f"the controlled plant is {plant}, the error system {error}, and {driven}: "
            "the loop converges (asymptotic)"
        )
    return "inconclusive", (
        "the error system converges only asymptotically and its certificate does not bound "
        "∫|ỹ_a|², the input that drives the controlled plant: the certificates say nothing "
        "about the loop"
    )


def _plant_words(value: Any) -> Any:
    """Write a classification of the controlled plant in the plant's own notation.

    :func:`~phdesign.symbolic.classify.classify` speaks of the error system (ẽ, sensors);
    the controlled plant is classified as a plant with no sensors, whose traces are e.
    """
    if isinstance(value, str):
        return value.replace("ẽ", "e").replace("by these sensors", "by the boundary dissipation")
    if isinstance(value, dict):
        return {k: _plant_words(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plant_words(v) for v in value]
    return value


@dataclass(frozen=True)
class LoopClassification:
    """Certificates of an observer-based loop (module docstring).

    Attributes
    ----------
    model : BCPHS
        The plant.
    actuate : tuple of int
        1-based indices of the actuated external inputs.
    K : sympy.ImmutableMatrix
        The feedback gain.
    source : str
        ``"estimate"`` (u_a = −K ŷ_a) or ``"measured"`` (u_a = −K y_a).
    plant, error : Classification
        The controlled plant (classified with no sensors) and the observer error system.
    bounded : bool
        Whether the error's certificate bounds ∫|ỹ_a|² (:func:`error_output_bounded`).
    verdict, reason : str
        The loop's verdict and why (:func:`loop_verdict`).
    """

    model: BCPHS
    actuate: tuple[int, ...]
    K: sympy.ImmutableMatrix
    source: str
    plant: Classification
    error: Classification
    bounded: bool
    verdict: str
    reason: str

    def _design(self) -> str:
        feed = "ŷ" if self.source == "estimate" else "y"
        act = ",".join(f"u{a}" for a in self.actuate)
        outs = ",".join(f"{feed}{a}" for a in self.actuate)
        return f"{act} = -K {outs}, K = {self.K.tolist()}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: both classifications (classify's JSON) and the loop's verdict."""
        return {
            "model": self.model.name,
            "actuate": list(self.actuate),
            "feedback": [[str(x) for x in row] for row in self.K.tolist()],
            "feedback_source": self.source,
            "plant": _plant_words(self.plant.to_dict()),
            "error": self.error.to_dict(),
            "plant_verdict": self.plant.verdict,
            "error_verdict": self.error.verdict,
            "error_output_bounded": self.bounded,
            "verdict": self.verdict,
            "reason": self.reason,
        }

    def __repr__(self) -> str:
        return (
            f"LoopClassification(model={self.model.name!r}, {self._design()}, "
            f"plant={self.plant.verdict!r}, error={self.error.verdict!r}, "
            f"verdict={self.verdict!r})"
        )[:300]

    def __str__(self) -> str:
        """Return the text ``phdesign loop classify`` prints."""
        act = ",".join(f"y{a}" for a in self.actuate)
        lines = [
            f"model: {self.model.name}   loop: {self._design()}",
            f"controlled plant (u_a = -K {act}, no sensors): {self.plant.verdict}",
            *_variant_lines(self.plant, plant=True),
            f"observer error system (sensors {sensors_text(self.error.C_m)}, "
            f"L = {matrix_text(self.error.L)}): {self.error.verdict}",
            *_variant_lines(self.error, plant=False),
            f"loop: {self.verdict}: {self.reason}",
        ]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        rows = (
            ("design", self._design()),
            ("controlled plant", self.plant.verdict),
            ("error system", self.error.verdict),
            ("loop", self.verdict),
            ("why", self.reason),
        )
        return html_table((), rows, f"{self.model.name} loop")


def _variant_lines(result: Classification, plant: bool) -> list[str]:
    lines = []
    for r in result.results:
        if not r.applicable:
            continue
        status = "holds" if r.holds else "fails"
        reason = _plant_words(r.reason) if plant else r.reason
        lines.append(f"  {r.name} {status}: {reason}")
    return lines


def classify_loop(
    model: BCPHS,
    actuate: Sequence[int],
    K: sympy.MatrixBase,
    C_m: sympy.MatrixBase,
    L: sympy.MatrixBase,
    source: str = "estimate",
    method: str = "auto",
) -> LoopClassification:
    r"""Classify the controlled plant, the error system and the loop (module docstring).

    Parameters
    ----------
    model : BCPHS
    actuate : sequence of int
        1-based indices into the model's external inputs.
    K : sympy matrix
        The feedback gain (:func:`feedback_gain`).
    C_m, L : sympy matrix
        The observer's sensors and gain (as for :func:`~phdesign.symbolic.classify.classify`).
    source : {"estimate", "measured"}
    method : {"auto", "exact", "float"}
        How :math:`\kappa^*` is computed.

    Returns
    -------
    LoopClassification
    """
    actuate = actuated_indices(actuate, model)
    if source not in FEEDBACK_SOURCES:
        raise LoopError(f"feedback source must be one of {FEEDBACK_SOURCES}; found {source!r}")
    K = feedback_gain(K, len(actuate))
    if source == "measured":
        check_measured(actuate, C_m, model)
    closed = controlled_plant(model, actuate, K)
    plant = classify(closed, sympy.zeros(0, closed.n_ports), sympy.zeros(0, 0), method=method)
    error = classify(model, C_m, L, method=method)
    bounded = not model.boundary_systems and error.verdict != "inconclusive"  # coupled: no bound
    bounded = bounded and error_output_bounded(error, actuate)
    verdict, reason = loop_verdict(plant.verdict, error.verdict, source, bounded)
    return LoopClassification(model, actuate, K, source, plant, error, bounded, verdict, reason)
