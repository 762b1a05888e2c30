r"""Export of plant, observer and error system as ``control.StateSpace`` objects.

All three are written in standard form with the discrete efforts ê as states
(:mod:`phdesign.numeric.discretization.registry`); the feedback loop is solved once, by
:meth:`~phdesign.numeric.discretization.phs.DiscretePHS.close` (:math:`K = C_m^\top L C_m`,
:math:`M = (I + K D)^{-1}`, :math:`G = M K`):

* plant: :math:`A = E^{-1}(J - R)`, :math:`B_s = E^{-1} B`, :math:`C = B^\top`, :math:`D`;
  inputs ``u1..``, outputs ``y1..`` (the model's outputs, in its order).
* observer: inputs (u, y_m), named as the export names them (``u1..``, then ``y3`` for
  a sensor that picks y3, ``y_m<j>`` for a combination), since
  :math:`\hat u = M(u + C_m^\top L y_m - K B^\top \hat e)`:
  :math:`A_o = E^{-1}(J - R - B G B^\top)`, :math:`B_o = E^{-1} B M [I, C_m^\top L]`;
  outputs the estimated model outputs ``yhat1..`` (:math:`(I - D G)B^\top \hat e + D M
  [I, C_m^\top L]`) and physical estimates at named points (below).
* error system: :math:`A_e = A_o`, no input, outputs ỹ (``y_err1..``) and optionally the
  estimation error of a physical quantity at named points.

**Physical outputs** (``quantity`` at the points ``z``): ``"state"`` (x = H⁻¹e,
labelled ``x1_hat(z=0p5)``: the decimal point of z is written ``p`` because
python-control refuses '.' in signal names), ``"effort"`` (``e1_hat(z=1)``),
``"displacement"`` (``w_hat(z=1)``, models with a displacement), or
``"coefficients"`` (the discrete states themselves, ``hat_e1[3]``).  ``at`` appends
point outputs of any field the model declares, named as the displacement is:
``at=["rotation(1)"]`` gives ``rotation(z=1)`` (plant), ``rotation_hat(z=1)`` (observer),
``rotation_err(z=1)`` (error) (:mod:`phdesign.numeric.discretization.points`; a number is
the displacement there).

**Untrustworthy modes.**  ``modes="resolved"`` returns the modal truncation to the
eigenvalues resolved under refinement (:mod:`phdesign.numeric.sampled.modal`: eigenvalues at p
against :math:`\lceil 1.5p \rceil`, the spectrum's drift rule); its states are modal
coordinates ``mode1..`` and the record of what was removed is attached as the attribute
``truncation`` (:class:`~phdesign.numeric.sampled.modal.ModalTruncation`).  The removed modes'
static gain is kept as a feedthrough, so the DC gain is exact; at low frequency the
input-output map then moves by a few percent for boundary inputs (beam, degree 24: 1.2 %
at s = 0.3i), the price of poles that can be trusted.  ``modes="all"`` (default) keeps
every discrete mode, including the unresolved high frequencies whose real parts are
artefacts (error system of a graded string at degree 30: max Re -0.012 against the
resolved abscissa -0.36).

Every system carries ``signal_descriptions`` (``{"inputs": ..., "outputs": ...}``): what
each signal is as a trace of the model, ``y3 = e1'(1)`` (:mod:`phdesign.numeric.signals`).

``control`` is imported lazily, inside the functions, so importing phdesign never pays
for it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from phdesign.core.errors import NumericError
from phdesign.numeric.discretization.phs import DiscretePHS, feedback_matrix
from phdesign.numeric.discretization.points import point_outputs as read_point_outputs
from phdesign.numeric.discretization.points import point_rows
from phdesign.numeric.sampled.samplers import sensor_names
from phdesign.numeric.signals import estimate_descriptions, input_descriptions, port_description

__all__ = [
    "MODES",
    "QUANTITIES",
    "control_signal_name",
    "design_statespace",
    "error_statespace",
    "observer_statespace",
    "plant_statespace",
    "point_outputs",
    "state_labels",
]

QUANTITIES = ("state", "effort", "displacement", "coefficients")
MODES = ("all", "resolved")


def state_labels(d: DiscretePHS, prefix: str = "") -> list[str]:
    """Names of the discrete states: ``<prefix>e<i>[<j>]`` (effort i, basis index/node j).

    The pairs (component, index) are the discretization's ``info["coordinates"]``, which
    every registered method gives; a system without them is read as n equal blocks.  A
    model's boundary-system efforts e_c = Q_c x_c follow, ``e(<label>)`` by the labels of
    their states (``info["boundary_labels"]``).
    """
    boundary = [f"{prefix}e({control_signal_name(b)})" for b in d.info.get("boundary_labels", ())]
    coords = d.info.get("coordinates")
    if coords is None:
        per = (d.dim - len(boundary)) // d.model.size
        coords = [(i, j) for i in range(d.model.size) for j in range(per)]
    return [f"{prefix}e{i + 1}[{j}]" for i, j in coords] + boundary


def control_signal_name(label: str) -> str:
    """Return ``label`` as python-control accepts a signal name: '.' is written 'p'.

    >>> control_signal_name("w(0.5)")
    'w(0p5)'
    """
    return label.replace(".", "p")


def _point_name(z: float) -> str:
    return control_signal_name(f"{z:g}")


def point_outputs(
    d: DiscretePHS, quantity: str, z: Sequence[float] | np.ndarray | None, suffix: str = ""
) -> tuple[np.ndarray, list[str]]:
    """Rows mapping ê to ``quantity`` at the points ``z`` and their labels.

    Parameters
    ----------
    d : DiscretePHS
    quantity : {"state", "effort", "displacement", "coefficients"}
    z : sequence of float, optional
        Points in the model's interval; default its two ends and its midpoint.
    suffix : str
        Appended to the quantity's name (``"_hat"``, ``"_err"``).

    Returns
    -------
    rows : ndarray (k, dim)
    labels : list of str
    """
    if quantity not in QUANTITIES:
        raise NumericError(f"unknown output quantity {quantity!r}; expected one of {QUANTITIES}")
    if quantity == "coefficients":
        prefix = {"_hat": "hat_", "_err": "err_"}.get(suffix, suffix)
        return np.eye(d.dim), state_labels(d, prefix)
    a, b = d.model.interval
    pts = np.array([a, 0.5 * (a + b), b] if z is None else z, dtype=float).reshape(-1)
    if pts.size == 0 or not np.all(np.isfinite(pts)) or np.any((pts < a) | (pts > b)):
        raise NumericError(
            f"output points z must be finite and lie in the interval [{a:g}, {b:g}]; "
            f"found {pts.tolist()}"
        )
    names = [_point_name(float(p)) for p in pts]
    if quantity == "displacement":
        if d.displacement_basis is None:
            raise NumericError(
                f"model {d.model.name!r} defines no displacement; use quantity 'state' or 'effort'"
            )
        return np.asarray(d.displacement_basis(pts)), [f"w{suffix}(z={s})" for s in names]
    values = d.effort_basis(pts)  # (k, n, dim)
    if quantity == "state":
        values = np.linalg.solve(d.model.H_at(pts), values)
    n = d.model.size
    letter = "x" if quantity == "state" else "e"
    rows = values.reshape(pts.size * n, d.dim)
    labels = [f"{letter}{i + 1}{suffix}(z={s})" for s in names for i in range(n)]
    return rows, labels


def _ss(A: Any, B: Any, C: Any, D: Any, **names: Any) -> Any:
    import control

    return control.ss(A, B, C, D, **names)


def _build(
    d: DiscretePHS,
    K: np.ndarray | None,
    B: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    modes: str,
    states: list[str],
    **names: Any,
) -> Any:
    """StateSpace of ``E x' = A_K x + B v, y = C x + D v`` (all or resolved modes)."""
    if modes not in MODES:
        raise NumericError(f"unknown modes {modes!r}; expected one of {MODES}")
    if modes == "all":
        A = np.linalg.solve(d.E, d.close(K).A)
        return _ss(A, np.linalg.solve(d.E, B), C, D, states=states, **names)
    from phdesign.numeric.sampled.modal import truncate_to_resolved

    cut = truncate_to_resolved(d, K, B, C, D)
    sys = _ss(
        cut.A, cut.B, cut.C, cut.D, states=[f"mode{i + 1}" for i in range(len(cut.kept))], **names
    )
    sys.truncation = cut
    return sys


def _described(inputs: Sequence[str], outputs: Sequence[str], system: Any) -> Any:
    """Attach what each signal is (``y3 = e1'(1)``) as ``system.signal_descriptions``."""
    system.signal_descriptions = {"inputs": tuple(inputs), "outputs": tuple(outputs)}
    return system


def _extra_outputs(
    d: DiscretePHS, quantity: str | None, z: Any, suffix: str, at: Any = None
) -> tuple[np.ndarray, list[str]]:
    """Rows and labels of ``quantity`` at ``z`` (none without it), then of ``at``."""
    rows, labels = (
        (np.zeros((0, d.dim)), []) if quantity is None else point_outputs(d, quantity, z, suffix)
    )
    fields = read_point_outputs(d.model, at, "at")
    named = [f"{f.field_name}{suffix}(z={_point_name(float(f.point or 0))})" for f in fields]
    return np.vstack([rows, point_rows(d, fields)]), labels + named


def plant_statespace(
    d: DiscretePHS,
    name: str = "plant",
    *,
    modes: str = "all",
    quantity: str | None = None,
    z: Sequence[float] | np.ndarray | None = None,
    at: Any = None,
) -> Any:
    """Return the discretized plant as ``control.StateSpace`` (inputs u, outputs y).

    ``quantity``/``z`` append physical outputs, ``at`` point outputs of the model's fields
    (module docstring); ``modes="resolved"`` keeps the resolved modes only.
    """
    m = d.n_ports
    rows, labels = _extra_outputs(d, quantity, z, "", at)
    ports = [port_description(d.model, "u", i) for i in range(m)]
    outputs = [port_description(d.model, "y", i) for i in range(m)] + labels
    return _described(
        ports,
        outputs,
        _build(
            d,
            None,
            d.B,
            np.vstack([d.B.T, rows]),
            np.vstack([d.D, np.zeros((rows.shape[0], m))]),
            modes,
            state_labels(d),
            inputs=[f"u{i + 1}" for i in range(m)],
            outputs=[f"y{i + 1}" for i in range(m)] + labels,
            name=name,
        ),
    )


def observer_statespace(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    name: str = "observer",
    *,
    modes: str = "all",
    quantity: str = "state",
    z: Sequence[float] | np.ndarray | None = None,
    at: Any = None,
) -> Any:
    """Return the observer as ``control.StateSpace``: inputs (u, y_m), outputs (ŷ, estimates).

    The outputs are the estimated model outputs ``yhat1..`` followed by the estimate of
    ``quantity`` at the points ``z`` (default: the state x at both ends and the
    midpoint; ``quantity="coefficients"`` gives the discrete states ê_obs), then the
    estimates of the point outputs ``at`` (``rotation_hat(z=1)``).
    """
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    K = feedback_matrix(C, Lm, d.n_ports)
    loop = d.close(K)
    m, q = d.n_ports, C.shape[0]
    In = np.hstack([np.eye(m), C.T @ Lm])  # v = u + C_m^T L y_m = In [u; y_m]
    rows, labels = _extra_outputs(d, quantity, z, "_hat", at)
    outputs = [*estimate_descriptions(d.model), *labels]
    return _described(
        input_descriptions(d.model, C),
        outputs,
        _build(
            d,
            K,
            loop.B @ In,
            np.vstack([loop.C, rows]),
            np.vstack([loop.D @ In, np.zeros((rows.shape[0], m + q))]),
            modes,
            state_labels(d, "hat_"),
            inputs=[f"u{i + 1}" for i in range(m)] + list(sensor_names(C)),
            outputs=[f"yhat{i + 1}" for i in range(m)] + labels,
            name=name,
        ),
    )


def error_statespace(
    d: DiscretePHS,
    C_m: np.ndarray,
    L: np.ndarray,
    name: str = "error",
    *,
    modes: str = "all",
    quantity: str | None = None,
    z: Sequence[float] | np.ndarray | None = None,
    at: Any = None,
) -> Any:
    """Return the observer error system as ``control.StateSpace`` (no input, output ỹ).

    ``quantity``/``z`` append the estimation error of a physical quantity at points, ``at``
    that of point outputs of the model's fields (``rotation_err(z=1)``).
    """
    K = feedback_matrix(np.atleast_2d(np.asarray(C_m, dtype=float)), L, d.n_ports)
    loop = d.close(K)
    m, n = d.n_ports, d.dim
    rows, labels = _extra_outputs(d, quantity, z, "_err", at)
    errors = [f"y_err{i + 1} = error of {port_description(d.model, 'y', i)}" for i in range(m)]
    return _described(
        [],
        errors + labels,
        _build(
            d,
            K,
            np.zeros((n, 0)),
            np.vstack([loop.C, rows]),
            np.zeros((m + rows.shape[0], 0)),
            modes,
            state_labels(d, "err_"),
            inputs=[],
            outputs=[f"y_err{i + 1}" for i in range(m)] + labels,
            name=name,
        ),
    )


def design_statespace(
    d: DiscretePHS,
    system: str,
    C_m: np.ndarray | None,
    L: np.ndarray | None,
    *,
    modes: str = "all",
    at: Any = None,
) -> Any:
    """Return ``"plant"``, ``"observer"`` or ``"error"`` of a design (``Observer.statespace``).

    The plant needs no ``C_m`` and ``L``; ``at`` appends point outputs (module docstring).
    """
    if system == "plant":
        return plant_statespace(d, modes=modes, at=at)
    if C_m is None or L is None:
        raise NumericError(f"the {system} system needs the sensors C_m and the gain L")
    if system == "observer":
        return observer_statespace(d, C_m, L, modes=modes, at=at)
    return error_statespace(d, C_m, L, modes=modes, at=at)
