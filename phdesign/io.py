"""Model files (TOML) in and out, and phdesign's one JSON writer (strict JSON).

A model file holds exactly the keys below; ``[matrices]`` entries are numbers or
expression strings in ``z`` and the parameters, and omitted ``P_k`` are zero::

    name = "Euler-Bernoulli beam, clamped at 0, free at 1"
    description = "optional text"
    interval = [0, 1]
    order = 2
    states = ["momentum", "curvature"]        # optional
    [parameters]
    d = 0.2
    [matrices]
    P0 = [["-d", 0], [0, 0]]                   # P0 may depend on z: [["-d*z", 0], [0, 0]]
    P2 = [[0, -1], [1, 0]]
    H  = [[1, 0], [0, 1]]
    [ports]
    inputs  = ["e1(0)", "e1'(0)", "e2(1)", "e2'(1)"]
    outputs = ["e2'(0)", "-e2(0)", "e1'(1)", "-e1(1)"]   # or "conjugate" (or omitted)
    [displacement]                             # optional: w = two antiderivatives of x2
    component = 2                              # (or terms = [{component = 1,
    integrations = 2                           #   integrations = 1}, ...]: any sum)
    [fields.curvature]                         # optional: named performance outputs
    component = 2
    integrations = 0
    [feedback]                                 # optional: u4 = -k y4, a tip damper
    inputs = [4]                               # 1-based indices into [ports].inputs
    gain = [["k"]]                             # K, K + K^T >= 0
    [units]                                    # optional: t, z, energy, displacement,
    t = "s"                                    # parameters and states
    [[boundary_systems]]                       # optional, repeatable: a tip mass m with a
    name = "mass"                              # damper c joined to input 2 (a velocity)
    ports = [2]                                # by u2 = -y_c, u_c = y2 (the gyrator)
    J = [[0]]                                  # dx_c/dt = (J - R) Q x_c + G u_c + B w
    R = [["c"]]                                # y_c = G^T Q x_c (+ D u_c)
    Q = [["1/m"]]
    G = [[-1]]
    B = [[1]]                                  # optional: an external force w on the mass
    [disturbances]                             # optional: dx/dt = ... + B(z) w
    B = [[1], [0]]                             # n x q, in z and the parameters
    [performance]                              # optional: the outputs a design is judged on
    outputs = ["integral(e1)", "e1(1)", "w(1)"]

``[ports]`` may also hold ``unknown = [2]``: external inputs that are disturbances
(:mod:`phdesign.symbolic.disturbances`).

Every model phdesign can read it can write, and ``read(write(model)) == model``.

Examples
--------
>>> from phdesign.models import load_builtin
>>> beam = load_builtin("euler-bernoulli")
>>> model_from_toml(model_to_toml(beam)) == beam
True
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.checks import require_path
from phdesign.core.errors import ExpressionError, ModelError, ModelFileError, PhdesignError
from phdesign.core.limits import MAX_MODEL_FILE_BYTES, check_file_size
from phdesign.symbolic.boundary_systems import boundary_system_to_dict
from phdesign.symbolic.disturbances import SECTION_KEYS, file_sections, read_sections
from phdesign.symbolic.expressions import exact_number, parse_scalar
from phdesign.symbolic.fields import Displacement, Field, Term, field_from_table
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.printing import format_expression

if TYPE_CHECKING:  # pragma: no cover - re-exported on first use (module __getattr__ below)
    from phdesign.core.files import atomic_write, check_output_path

__all__ = [
    "atomic_write",
    "check_output_path",
    "dumps_json",
    "json_value",
    "model_from_dict",
    "model_from_toml",
    "model_to_dict",
    "model_to_toml",
    "read_model",
    "write_model",
]

_REQUIRED = ("name", "interval", "order", "matrices", "ports")
_OPTIONAL = (
    "description",
    "states",
    "parameters",
    "displacement",
    "fields",
    "feedback",
    "units",
    "boundary_systems",
    *SECTION_KEYS,
)


def read_model(path: str | os.PathLike[str]) -> BCPHS:
    """Read a model file.

    Raises
    ------
    ArgumentError
        If ``path`` is not a file name (``str`` or :class:`os.PathLike`).
    ModelFileError
        If the file cannot be read or is not valid TOML or lacks keys; model errors
        (:class:`~phdesign.core.errors.ModelError`, ...) propagate with their own messages.
    """
    require_path(path, "path")  # an int would be opened as a file descriptor (0: stdin)
    source = str(path)
    try:
        with open(path, "rb") as stream:
            data = stream.read(MAX_MODEL_FILE_BYTES + 1)
        check_file_size(len(data), f"model file {source!r}")
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ModelFileError(f"cannot read model file {source!r}: {_reason(error)}") from None
    return model_from_toml(text, source=source)


def _reason(error: Exception) -> str:
    return error.strerror if isinstance(error, OSError) and error.strerror else str(error)


def model_from_toml(text: str, source: str = "model file") -> BCPHS:
    """Build a model from the text of a TOML model file."""
    if not isinstance(text, str):
        raise ModelFileError(f"{source} must be text; found {type(text).__name__}")
    check_file_size(len(text.encode("utf-8", "surrogatepass")), source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ModelFileError(f"{source} is not valid TOML: {error}") from None
    return model_from_dict(data, source=source)


def model_from_dict(data: Mapping[str, Any], source: str = "model file") -> BCPHS:
    """Build a model from the parsed content of a model file.

    Each section is read by its own reader, which refuses what the file format does not
    hold and names the section; :meth:`BCPHS.define` then checks the model itself.
    """
    _check_keys(data, source)
    matrices = _table(data, "matrices", source)
    ports = _table(data, "ports", source)
    parameters = _table(data, "parameters", source) if "parameters" in data else {}
    P = _read_P(matrices, source)
    outputs = _read_outputs(ports, source)  # checks that [ports] holds inputs
    feedback = _read_feedback(data, source)
    units = _table(data, "units", source) if "units" in data else None
    disturbances, performance = read_sections(data, ports, source)
    return BCPHS.define(
        name=data["name"],
        description=data.get("description", ""),
        interval=data["interval"],
        order=data["order"],
        P=P,
        H=matrices["H"],
        parameters=parameters,
        inputs=ports["inputs"],
        outputs=outputs,
        state_names=_read_states(data, source),
        displacement=_read_displacement(data, source),
        feedback=feedback,
        units=units,
        fields=_read_fields(data, source),
        boundary_systems=data.get("boundary_systems"),
        disturbances=disturbances,
        performance=performance,
    )


def _check_keys(data: Mapping[str, Any], source: str) -> None:
    """Refuse a file that is not a table, lacks a required key or has an unknown one."""
    if not isinstance(data, Mapping):
        raise ModelFileError(f"{source} must be a table; found {type(data).__name__}")
    _check_names(data, "the file", source)
    missing = [key for key in _REQUIRED if key not in data]
    if missing:
        raise ModelFileError(f"{source} lacks the key(s) {', '.join(missing)}")
    unknown = sorted(set(data) - set(_REQUIRED) - set(_OPTIONAL))
    if unknown:
        raise ModelFileError(
            f"{source} has unknown key(s) {', '.join(unknown)}; "
            f"expected only {', '.join(_REQUIRED + _OPTIONAL)}"
        )
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            raise ModelFileError(f"{source}: {key} must be text; found {data[key]!r}")


def _read_P(matrices: Mapping[str, Any], source: str) -> dict[int, Any]:
    """Return the P_k of [matrices] by k (H is read apart; it must be there)."""
    P = {}
    for key, value in matrices.items():
        if key == "H":
            continue
        if not (key.startswith("P") and key[1:].isdigit()):
            raise ModelFileError(
                f"{source}: unknown matrix {key!r} in [matrices]; expected H and P0..P<order>"
            )
        P[int(key[1:])] = value
    if "H" not in matrices:
        raise ModelFileError(f"{source}: [matrices] lacks H")
    return P


def _read_outputs(ports: Mapping[str, Any], source: str) -> Any:
    """Return the outputs of [ports]: trace expressions, or "conjugate" (also omitted)."""
    bad_ports = sorted(set(ports) - {"inputs", "outputs", "unknown"})
    if bad_ports or "inputs" not in ports:
        raise ModelFileError(
            f"{source}: [ports] must hold exactly inputs and outputs (outputs may be "
            f'"conjugate" or omitted), and optionally unknown; found '
            f"{', '.join(sorted(ports)) or 'nothing'}"
        )
    outputs = ports.get("outputs", "conjugate")
    if isinstance(outputs, str) and outputs != "conjugate":
        raise ModelFileError(
            f"{source}: [ports] outputs must be a list of trace expressions or "
            f'"conjugate"; found {outputs!r}'
        )
    return outputs


def _read_feedback(data: Mapping[str, Any], source: str) -> Mapping[str, Any] | None:
    """Return the [feedback] table (inputs and gain), or None."""
    feedback = _table(data, "feedback", source) if "feedback" in data else None
    if feedback is not None and set(feedback) != {"inputs", "gain"}:
        raise ModelFileError(
            f"{source}: [feedback] must hold exactly inputs and gain; found "
            f"{', '.join(sorted(feedback)) or 'nothing'}"
        )
    return feedback


def _read_displacement(data: Mapping[str, Any], source: str) -> Displacement | None:
    """Return the [displacement] table as a :class:`~phdesign.symbolic.fields.Field`."""
    if "displacement" not in data:
        return None
    return _read_field(data, _table(data, "displacement", source), "displacement", source)


def _read_fields(data: Mapping[str, Any], source: str) -> dict[str, Field] | None:
    """Return the named fields of [fields.<name>], or None."""
    if "fields" not in data:
        return None
    tables = _table(data, "fields", source)
    return {
        name: _read_field(
            data, _table(tables, name, source, f"fields.{name}"), f"fields.{name}", source
        )
        for name in tables
    }


def _read_field(data: Mapping[str, Any], table: Mapping[str, Any], key: str, source: str) -> Field:
    """Read one field's table; coefficients are numbers or text in the parameters."""
    parameters = data.get("parameters", {})
    names = list(parameters) if isinstance(parameters, Mapping) else []

    def coefficient(value: object, what: str) -> sympy.Expr:
        if isinstance(value, str):
            return parse_scalar(value, names, allow_z=False, what=what)
        return exact_number(value, what)

    try:
        return field_from_table(table, key, coefficient)
    except (ModelError, ExpressionError) as error:
        raise ModelFileError(f"{source}: {error}") from None


def _read_states(data: Mapping[str, Any], source: str) -> tuple[str, ...]:
    """Return the state labels (a list of names), or none."""
    states = data.get("states", ())
    if "states" in data and not (
        isinstance(states, list) and all(isinstance(s, str) for s in states)
    ):
        raise ModelFileError(f"{source}: states must be a list of names; found {states!r}")
    return tuple(states)


def _table(
    data: Mapping[str, Any], key: str, source: str, label: str | None = None
) -> Mapping[str, Any]:
    value = data[key]
    label = key if label is None else label
    if not isinstance(value, Mapping):
        raise ModelFileError(f"{source}: {label} must be a table; found {value!r}")
    _check_names(value, f"[{label}]", source)
    return value


def _check_names(table: Mapping[Any, Any], where: str, source: str) -> None:
    """Refuse keys that are not text: TOML's never are, a dict from code may hold any."""
    names = [k for k in table if not isinstance(k, str)]
    if names:
        raise ModelFileError(
            f"{source}: the keys of {where} must be names (text); found {names[0]!r}"
        )


def _toml_number(value: sympy.Expr) -> int | float | str:
    """Write exact numbers as TOML ints or floats when that is exact, else as text."""
    if value.is_Integer and abs(int(value)) < 2**63:  # TOML integers are 64-bit
        return int(value)
    if value.is_Rational:
        as_float = float(value)
        if math.isfinite(as_float) and sympy.Rational(repr(as_float)) == value:
            return as_float
    return format_expression(value)


def model_to_dict(model: BCPHS) -> dict[str, Any]:
    """Return the content of the model file of ``model``."""
    if not isinstance(model, BCPHS):
        raise ModelFileError(f"expected a model (a BCPHS); found {type(model).__name__}")
    data: dict[str, Any] = {"name": model.name}
    if model.description:
        data["description"] = model.description
    data["interval"] = [_toml_number(p) for p in model.interval]
    data["order"] = model.order
    if model.state_names != tuple(f"x{i + 1}" for i in range(model.size)):
        data["states"] = list(model.state_names)
    if model.parameters:
        data["parameters"] = {s.name: _toml_number(v) for s, v in model.parameters}

    def rows(matrix: sympy.MatrixBase) -> list[list[int | float | str]]:
        return [
            [_toml_number(x) if x.is_number else format_expression(x) for x in row]
            for row in matrix.tolist()
        ]

    matrices: dict[str, Any] = {}
    for k, P_k in enumerate(model.P):
        if not P_k.is_zero_matrix:
            matrices[f"P{k}"] = rows(P_k)
    matrices["H"] = rows(model.H)
    data["matrices"] = matrices
    data["ports"] = {
        "inputs": [format_expression(e, model.interval) for e in model.inputs],
        "outputs": "conjugate"
        if model.derived_outputs
        else [format_expression(e, model.interval) for e in model.outputs],
    }
    if model.displacement is not None:
        data["displacement"] = _field_to_dict(model.displacement)
    if model.fields:
        data["fields"] = {name: _field_to_dict(f) for name, f in model.fields}
    if model.feedback is not None:
        data["feedback"] = {
            "inputs": list(model.feedback.inputs),
            "gain": rows(model.feedback.gain),
        }
    if model.units:
        data["units"] = dict(model.units)
    if model.boundary_systems:
        data["boundary_systems"] = [
            boundary_system_to_dict(bs, rows) for bs in model.boundary_systems
        ]
    if model.disturbances is not None and model.disturbances.unknown:
        data["ports"]["unknown"] = list(model.disturbances.unknown)
    data.update(
        file_sections(model, lambda x: _toml_number(x) if x.is_number else format_expression(x))
    )
    return data


def _field_to_dict(f: Field) -> dict[str, Any]:
    """Return the table of a field: the short form when it is one term with coefficient 1."""
    out: dict[str, Any]
    if f.short:
        out = {"component": f.terms[0].component, "integrations": f.terms[0].integrations}
    else:
        out = {"terms": [_term_to_dict(t) for t in f.terms]}
    if f.start != "a":
        out["start"] = f.start
    return out


def _term_to_dict(t: Term) -> dict[str, Any]:
    out: dict[str, Any] = {"component": t.component, "integrations": t.integrations}
    if t.coefficient != 1:
        c = t.coefficient
        out["coefficient"] = _toml_number(c) if c.is_number else format_expression(c)
    return out


def model_to_toml(model: BCPHS) -> str:
    """Return the text of the TOML model file of ``model``.

    The text is read back before it is returned: phdesign never writes a model file it
    cannot read, or one that reads as another model.

    Raises
    ------
    ModelFileError
        If the model holds something the file format cannot express exactly.
    """
    import tomli_w  # a writer only: reading a model (every command) needs none

    text = tomli_w.dumps(model_to_dict(model))
    try:
        again = model_from_toml(text, source="the written model file")
    except PhdesignError as error:
        raise ModelFileError(f"model {model.name!r} cannot be written readably: {error}") from None
    if again != model:
        raise ModelFileError(f"model {model.name!r} cannot be written exactly as a model file")
    return text


def write_model(model: BCPHS, path: str | os.PathLike[str], force: bool = False) -> None:
    """Write ``model`` as a TOML file (atomically; refuses to overwrite unless ``force``)."""
    from phdesign.core.files import atomic_write

    atomic_write(path, model_to_toml(model), force=force)


def json_value(value: Any) -> Any:
    """Convert sympy, numpy and dataclass-free containers to JSON-ready values.

    Exact sympy expressions become strings; sympy numbers that are integers become
    ints; floats that are not finite become ``None``.
    """
    if isinstance(value, sympy.MatrixBase):
        return [[format_expression(x) for x in row] for row in value.tolist()]
    if isinstance(value, sympy.Basic):
        return format_expression(value)
    if isinstance(value, Mapping):
        return {str(k): json_value(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_value(v) for v in value]
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return json_value(value.tolist())
    return value


def dumps_json(value: Any, indent: int | None = 2) -> str:
    """Serialize ``value`` (through :func:`json_value`) as strict JSON.

    This is phdesign's one JSON writer: non-finite floats become ``null`` and
    ``allow_nan=False`` guarantees that no bare ``NaN`` or ``Infinity`` is ever printed.
    """
    import json  # only a --json run writes JSON (``phdesign classify`` starts without it)

    return json.dumps(json_value(value), indent=indent, ensure_ascii=False, allow_nan=False)


def __getattr__(name: str) -> Any:
    """Return the output-file helpers of :mod:`phdesign.core.files` when first asked.

    Reading a model (what every command does) writes nothing, so its start does not import
    them.
    """
    if name in ("atomic_write", "check_output_path"):
        from phdesign.core import files

        return getattr(files, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
