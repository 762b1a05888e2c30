r"""The observer-based loop, assembled: plant, observer and feedback as one LTI system.

With the discretization :math:`E\dot{\hat e} = (J - R)\hat e + B u`,
:math:`y = B^\top \hat e + D u` (:mod:`phdesign.numeric.discretize`), the observer is the
same system with :math:`\hat u = u + C_m^\top L (y_m - \hat y_m)`; plant and observer
together are :func:`~phdesign.numeric.simulate.coupled_system`,
:math:`E_2 \dot X = A_2 X + B_2 u` with :math:`X = (\hat e, \hat e_{obs})`, and the
observer output is :math:`\hat y = C_{\hat y} X + D u` with :math:`C_{\hat y} =
(D\Gamma B^\top,\ B^\top - D\Gamma B^\top)`, :math:`\Gamma = (I + GD)^{-1}G`,
:math:`G = C_m^\top L C_m` (solve :math:`\hat u - u = G(y - \hat y)` for
:math:`\hat u`).  The controller closes

.. math::

    u = -S_a^\top K S_a\, (C_f X + D u) + S_r^\top v, \qquad
    C_f = C_{\hat y}\ (\text{estimate}) \text{ or } (B^\top\ 0)\ (\text{measured}),

:math:`S_a`, :math:`S_r` the selections of the actuated and of the other inputs, so with
:math:`K_a = S_a^\top K S_a` and :math:`M = (I + K_a D)^{-1}`,

.. math::

    u = F X + P v, \quad F = -M K_a C_f, \quad P = M S_r^\top, \qquad
    E_2 \dot X = (A_2 + B_2 F) X + B_2 P v .

This is the assembled loop in the original coordinates :math:`(\hat e, \hat e_{obs})`.
In :math:`Z = T X = (\hat e, \tilde e)`, :math:`T = \left[\begin{smallmatrix} I & 0 \\
I & -I \end{smallmatrix}\right] = T^{-1}` (and :math:`T E_2 T = E_2`), it is
block upper-triangular: the error block is the error system
:math:`E\dot{\tilde e} = (J - R - B\Gamma B^\top)\tilde e`, the plant block the plant
closed by :math:`u_a = -K y_a` (:mod:`phdesign.symbolic.loop` derives it); the lower-left
block vanishes to round-off, and :attr:`LoopSystem.triangular_residual` says by how much.

:func:`loop_spectrum` refines the assembled pencil with the two-resolution drift rule of
:mod:`phdesign.numeric.spectrum` and reports it beside the converged spectra of the two
blocks; :func:`loop_statespace` exports the loop to python-control.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.errors import LoopError, NumericError, check_shape
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretize import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.simulate import coupled_system
from phdesign.numeric.spectrum import (
    SpectrumReport,
    default_resolutions,
    in_band_unresolved,
    match_resolved,
    spectrum,
)

__all__ = [
    "LoopSpectrum",
    "LoopSystem",
    "NumericLoop",
    "assemble",
    "loop_spectrum",
    "loop_statespace",
    "pencil_eigen",
]

ILL_CONDITION = 1e4  # condition number above which the rightmost eigenvalue is flagged


@dataclass(frozen=True)
class NumericLoop:
    r"""The loop's numbers: which ports are actuated, K, the sensors and L.

    Parameters
    ----------
    actuated : tuple of int
        0-based indices into the discretization's (external) ports.
    K : ndarray (k, k)
        Feedback gain, :math:`K + K^\top \succ 0`.
    C_m, L : ndarray
        Sensors (``q x m``) and observer gain (``q x q``).
    source : {"estimate", "measured"}
        Feed back :math:`\hat y_a` or the measured :math:`y_a`.
    """

    actuated: tuple[int, ...]
    K: np.ndarray = field(compare=False)
    C_m: np.ndarray = field(compare=False)
    L: np.ndarray = field(compare=False)
    source: str = "estimate"

    def selection(self, m: int) -> np.ndarray:
        """:math:`S_a` (``k x m``): the actuated rows of the identity."""
        return np.eye(m)[list(self.actuated)]

    def check(self, m: int) -> None:
        """Check shapes and indices against ``m`` ports (the library's last guard)."""
        k = len(self.actuated)
        if k == 0 or len(set(self.actuated)) != k or not all(0 <= a < m for a in self.actuated):
            raise LoopError(f"actuated ports must be distinct indices in 0..{m - 1}")
        check_shape("feedback gain K", np.asarray(self.K), (k, k))
        if self.source not in ("estimate", "measured"):
            raise LoopError(f"source must be 'estimate' or 'measured'; found {self.source!r}")
        if self.source == "measured":  # y_a = F y_m: the unit rows lie in the rows of C_m
            C = np.atleast_2d(np.asarray(self.C_m, dtype=float))
            rank = np.linalg.matrix_rank(C)
            for a in self.actuated:
                if np.linalg.matrix_rank(np.vstack([C, np.eye(m)[a]])) != rank:
                    raise LoopError(
                        f"feedback source measured: y{a + 1} (collocated with the actuated "
                        f"u{a + 1}) is not measured by these sensors"
                    )


@dataclass(frozen=True)
class LoopSystem:
    r"""The assembled loop :math:`E_2\dot X = A X + B v` and its output maps (module docstring).

    ``X = (ê, ê_obs)``; ``u = C_u X + D_u v``, ``y = C_y X + D_y v``,
    ``ŷ = C_yhat X + D_yhat v``; ``v`` are the inputs in :attr:`others`.
    """

    discrete: DiscretePHS = field(repr=False)
    loop: NumericLoop
    E: np.ndarray = field(repr=False)
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C_u: np.ndarray = field(repr=False)
    D_u: np.ndarray = field(repr=False)
    C_y: np.ndarray = field(repr=False)
    D_y: np.ndarray = field(repr=False)
    C_yhat: np.ndarray = field(repr=False)
    D_yhat: np.ndarray = field(repr=False)
    others: tuple[int, ...] = ()

    @property
    def dim(self) -> int:
        """Number of states of the discretized plant (the loop has twice as many)."""
        return self.discrete.dim

    def error_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(A_Z, B_Z)`` in ``Z = (ê, ẽ)``: block upper-triangular (module docstring)."""
        n = self.dim
        T = np.block([[np.eye(n), np.zeros((n, n))], [np.eye(n), -np.eye(n)]])
        return T @ self.A @ T, T @ self.B

    @property
    def triangular_residual(self) -> float:
        """Largest entry of the lower-left block of ``A_Z`` relative to ``max |A_Z|``."""
        A_Z, _ = self.error_coordinates()
        n = self.dim
        return float(np.max(np.abs(A_Z[n:, :n])) / max(np.max(np.abs(A_Z)), 1e-300))

    def blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """Right-hand matrices of the controlled plant and of the error system (pencil E)."""
        A_Z, _ = self.error_coordinates()
        n = self.dim
        return A_Z[:n, :n], A_Z[n:, n:]


def _observer_gain(d: DiscretePHS, G: np.ndarray) -> np.ndarray:
    """Γ = (I + G D)⁻¹ G: the injection û − u = Γ Bᵀ ẽ with the feedthrough loop solved."""
    return np.linalg.solve(np.eye(d.n_ports) + G @ d.D, G)


def assemble(d: DiscretePHS, loop: NumericLoop) -> LoopSystem:
    """Assemble plant, observer and feedback of ``loop`` on the discretization ``d``.

    Raises
    ------
    LoopError
        If an index or a shape does not fit ``d``.
    NumericError
        If the feedthrough makes the loop ill-posed (I + K_a D singular).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> d = discretize(to_numeric(load_builtin("euler-bernoulli")), "galerkin", 10)
    >>> tip_torque = NumericLoop((2,), np.eye(1), np.array([[0, 0, 0, 1.0]]), np.eye(1))
    >>> system = assemble(d, tip_torque)
    >>> system.A.shape, system.others, system.triangular_residual < 1e-14
    ((44, 44), (0, 1, 3), True)
    """
    m, n = d.n_ports, d.dim
    loop.check(m)
    G = feedback_matrix(loop.C_m, loop.L, m)  # checks C_m, L shapes and L + Lᵀ ≻ 0
    E2, A2, B2 = coupled_system(d, G)
    Gamma = _observer_gain(d, G)
    DGB = d.D @ Gamma @ d.B.T
    C_yhat = np.hstack([DGB, d.B.T - DGB])
    C_y = np.hstack([d.B.T, np.zeros((m, n))])
    S_a = loop.selection(m)
    others = tuple(j for j in range(m) if j not in set(loop.actuated))
    S_r_T = np.eye(m)[:, list(others)]
    K_a = S_a.T @ np.asarray(loop.K, dtype=float) @ S_a
    C_f = C_yhat if loop.source == "estimate" else C_y
    feedthrough = np.eye(m) + K_a @ d.D
    if np.linalg.cond(feedthrough) > 1e12:
        raise NumericError("the loop is ill-posed: I + K_a D is singular for this feedthrough")
    F = -np.linalg.solve(feedthrough, K_a @ C_f)
    P = np.linalg.solve(feedthrough, S_r_T)
    return LoopSystem(
        discrete=d,
        loop=loop,
        E=E2,
        A=A2 + B2 @ F,
        B=B2 @ P,
        C_u=F,
        D_u=P,
        C_y=C_y + d.D @ F,
        D_y=d.D @ P,
        C_yhat=C_yhat + d.D @ F,
        D_yhat=d.D @ P,
        others=others,
    )


#: Shift of the shift-and-invert eigensolve: every eigenvalue of the loop has Re λ <= 0
#: (both blocks are dissipative), so a positive real shift is never one of them.
SHIFT = 1.0


def pencil_eigen(
    A: np.ndarray, E: np.ndarray, condition: bool = True, shift: float = SHIFT
) -> tuple[np.ndarray, np.ndarray | None]:
    r"""Eigenvalues of the pencil (A, E) by shift and invert, and their condition numbers.

    With :math:`S = (A - \sigma E)^{-1} E`, :math:`S v = 	heta v` iff
    :math:`A v = (\sigma + 1/	heta) E v`, and the left eigenvectors are
    :math:`y = (A - \sigma E)^{-*} w` for :math:`w^* S = 	heta w^*`.  The slow eigenvalues
    are the large :math:`	heta`, computed with a backward error
    :math:`\epsilon\|S\|`, so their error is about :math:`\epsilon |\lambda - \sigma|^2
    \|S\| \kappa` whatever :math:`\|A\|` is.  This matters for the assembled loop: its
    coupling block :math:`B_a K 	ilde C_a` carries the large entries of a damper on a
    derivative trace, and the QZ algorithm on :math:`(A, E)` loses five to eight digits
    on the slow modes (beam, tip torque, degree 30 to 100: 2e-8 to 4e-5 against 4e-13 to
    9e-12 here).  The condition number is the energy-norm one of
    :func:`phdesign.numeric.spectrum.eigen`,
    :math:`\kappa = \|x\|_E \|y\|_E / |y^* E x|`.
    """
    shifted = A - shift * E
    S = np.linalg.solve(shifted, E)
    if not condition:
        theta = np.linalg.eigvals(S)
        return _unshift(theta, shift), None
    theta, W, X = sl.eig(S, left=True, right=True)
    Y = np.linalg.solve(shifted.conj().T, W)
    EX = E @ X
    num = np.sqrt(np.abs(np.einsum("ij,ij->j", X.conj(), EX)))
    num *= np.sqrt(np.abs(np.einsum("ij,ij->j", Y.conj(), E @ Y)))
    den = np.abs(np.einsum("ij,ij->j", Y.conj(), EX))
    with np.errstate(divide="ignore", invalid="ignore"):
        return _unshift(theta, shift), np.where(den > 0, num / den, np.inf)


def _unshift(theta: np.ndarray, shift: float) -> np.ndarray:
    out = np.full(theta.shape, complex(np.inf, 0.0))
    finite = theta != 0
    out[finite] = shift + 1.0 / theta[finite]
    return out


@dataclass(frozen=True)
class _Pair:
    """One resolution pair of the assembled loop, through the drift test."""

    resolutions: tuple[int, int]
    lam: np.ndarray
    kappa: np.ndarray
    counted: np.ndarray  # indices of resolved and kept in-band eigenvalues
    n_tight: int
    alpha: float | None
    d_alpha: float
    lead_loose: bool


def _drift_pair(
    solve: Callable[[int], tuple[np.ndarray, np.ndarray | None]],
    coarse: np.ndarray,
    p: int,
    rtol: float,
) -> _Pair:
    fine_res = math.ceil(1.5 * p)
    fine, kappa = solve(fine_res)
    assert kappa is not None  # solve computes condition numbers unless told otherwise
    idx, _ = match_resolved(fine, coarse, rtol)
    loose, _ = in_band_unresolved(fine, idx, kappa)
    counted = np.concatenate([idx, loose]).astype(int)
    alpha, d_alpha, lead_loose = None, math.inf, False
    if idx.size:
        lam = fine[counted]
        nearest = coarse[np.argmin(np.abs(coarse[None, :] - lam[:, None]), axis=1)]
        drifts = np.abs(lam.real - nearest.real)
        # as spectrum(): the largest real part less its drift stands for the abscissa
        j = int(np.argmax(lam.real - drifts))
        alpha, d_alpha = float(lam.real[j]), float(drifts[j])
        lead_loose = j >= idx.size
    return _Pair((p, fine_res), fine, kappa, counted, int(idx.size), alpha, d_alpha, lead_loose)


@dataclass(frozen=True)
class LoopSpectrum:
    """Converged spectrum of the assembled loop, with those of its two blocks.

    Attributes
    ----------
    spectral_abscissa : float or None
        Of the assembled loop (plant and observer states together).
    converged : bool
        The loop's abscissa agrees to ``tol`` between the last two resolutions.
    digits : float or None
        Agreeing digits of the loop's abscissa.
    rightmost : list of complex
        Resolved loop eigenvalues with the largest real parts (conjugates kept).
    condition_numbers : list of float
        Their energy-norm condition numbers.
    origin : list of str
        For each of ``rightmost``, the block whose discrete spectrum holds it (``"plant"``
        or ``"error"``) at the same resolution.
    n_resolved, n_total : int
        Resolved and all eigenvalues of the loop at the finer resolution.
    resolutions : tuple of int
    plant, error : SpectrumReport
        The controlled plant (u_a = −K y_a) and the error system, each refined on its own.
    separation_gap : float or None
        ``spectral_abscissa − max(plant, error)``: zero to the resolved digits.
    triangular_residual : float
        The lower-left block of the loop in (ê, ẽ), relative (round-off).
    warnings : list of str
    """

    spectral_abscissa: float | None
    converged: bool
    digits: float | None
    rightmost: list[complex]
    condition_numbers: list[float]
    origin: list[str]
    n_resolved: int
    n_total: int
    resolutions: tuple[int, int]
    method: str
    plant: SpectrumReport = field(repr=False)
    error: SpectrumReport = field(repr=False)
    separation_gap: float | None
    triangular_residual: float
    unbounded_below: bool = False
    ill_conditioned: bool = False
    warnings: list[str] = field(default_factory=list)
    model: str = ""
    design: str = ""

    @property
    def plant_abscissa(self) -> float | None:
        """Converged abscissa of the controlled plant (u_a = −K y_a)."""
        return self.plant.spectral_abscissa

    @property
    def error_abscissa(self) -> float | None:
        """Converged abscissa of the observer error system."""
        return self.error.spectral_abscissa

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (strict JSON: None for what is not a number)."""
        return {
            "model": self.model,
            "design": self.design,
            "spectral_abscissa": _finite(self.spectral_abscissa),
            "converged": self.converged,
            "digits": _finite(self.digits),
            "plant_abscissa": _finite(self.plant_abscissa),
            "plant_converged": self.plant.converged,
            "error_abscissa": _finite(self.error_abscissa),
            "error_converged": self.error.converged,
            "separation_gap": _finite(self.separation_gap),
            "triangular_residual": _finite(self.triangular_residual),
            "rightmost": [[float(z.real), float(z.imag)] for z in self.rightmost],
            "condition_numbers": [_finite(c) for c in self.condition_numbers],
            "origin": list(self.origin),
            "n_resolved": self.n_resolved,
            "n_total": self.n_total,
            "resolutions": list(self.resolutions),
            "method": self.method,
            "unbounded_below": self.unbounded_below,
            "ill_conditioned": self.ill_conditioned,
            "warnings": list(self.warnings),
        }

    def __repr__(self) -> str:
        return (
            f"LoopSpectrum(model={self.model!r}, spectral_abscissa={self.spectral_abscissa}, "
            f"converged={self.converged}, plant={self.plant_abscissa}, "
            f"error={self.error_abscissa})"
        )[:300]

    def __str__(self) -> str:
        """Return the text ``phdesign loop spectrum`` prints."""
        lines = [f"model: {self.model}   loop: {self.design}   method: {self.method}"]
        if self.spectral_abscissa is None:
            lines.append("loop spectral abscissa: unbounded below (no eigenvalue converges)")
        else:
            lines.append(
                f"loop spectral abscissa: {self.spectral_abscissa:.12g}   converged: "
                f"{self.converged}   digits: {_digits(self.digits)}   resolved: "
                f"{self.n_resolved}/{self.n_total} at resolutions {self.resolutions[0]}, "
                f"{self.resolutions[1]}"
            )
        for name, rep in (
            ("controlled plant (u_a = -K y_a)", self.plant),
            ("observer error system", self.error),
        ):
            value = (
                "unbounded below"
                if rep.spectral_abscissa is None
                else (f"{rep.spectral_abscissa:.12g}")
            )
            lines.append(
                f"{name}: {value}   converged: {rep.converged}   digits: {_digits(rep.digits)}"
            )
        if self.separation_gap is not None:
            lines.append(
                f"separation: loop - max(plant, error) = {self.separation_gap:.2g}; "
                f"lower-left block in (x, x̃) {self.triangular_residual:.1g} (relative)"
            )
        if self.rightmost:
            lines.append("rightmost eigenvalues of the loop:")
            for z, c, o in zip(self.rightmost, self.condition_numbers, self.origin, strict=True):
                lines.append(f"  {z.real:+.10g} {z.imag:+.10g}i   (condition {c:.3g}, {o})")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        from html import escape

        rows = "".join(
            f"<tr><td>{escape(k)}</td><td>{escape(str(v))}</td></tr>"
            for k, v in (
                ("loop abscissa", self.spectral_abscissa),
                ("converged", self.converged),
                ("digits", _digits(self.digits)),
                ("controlled plant", self.plant_abscissa),
                ("error system", self.error_abscissa),
                ("separation gap", self.separation_gap),
            )
        )
        return f"<table><caption>{escape(self.model)} loop spectrum</caption>{rows}</table>"

    def plot(self, ax: Any = None) -> Any:
        """Draw the rightmost resolved loop eigenvalues, marked by the block they belong to."""
        from phdesign.plots import new_figure

        if ax is None:
            _, ax = new_figure(figsize=(5, 4))
        for kind, marker in (("plant", "o"), ("error", "x")):
            z = np.array(
                [w for w, o in zip(self.rightmost, self.origin, strict=True) if o == kind]
            )
            if z.size:
                ax.plot(z.real, z.imag, marker, ls="none", label=f"{kind} block")
        if self.spectral_abscissa is not None:
            ax.axvline(self.spectral_abscissa, color="k", lw=0.8, label="loop abscissa")
        ax.set_xlabel("Re λ")
        ax.set_ylabel("Im λ")
        ax.legend()
        return ax.figure


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _digits(x: float | None) -> str:
    return "—" if x is None else f"{x:.1f}"


def _tag(values: Sequence[complex], blocks: tuple[np.ndarray, np.ndarray]) -> list[str]:
    plant, error = blocks
    out = []
    for z in values:
        dp = np.min(np.abs(plant - z)) if plant.size else np.inf
        de = np.min(np.abs(error - z)) if error.size else np.inf
        out.append("plant" if dp <= de else "error")
    return out


def loop_spectrum(
    nm: NumericModel,
    loop: NumericLoop,
    *,
    method: str = "galerkin",
    resolution: int | None = None,
    max_resolution: int | None = None,
    tol: float | None = None,
    rtol_resolved: float | None = None,
    count: int = 6,
    design: str = "",
) -> LoopSpectrum:
    r"""Converged spectrum of the assembled loop, and of the controlled plant and error system.

    The two blocks are refined by :func:`~phdesign.numeric.spectrum.spectrum` (the
    controlled plant as the discretization closed by :math:`S_a^\top K S_a`, the same
    matrix as the model closed by ``[feedback]``).  The assembled pencil
    :math:`(A, E_2)` is refined from the finer of their starting resolutions with the same
    drift rule (:func:`~phdesign.numeric.spectrum.match_resolved`, in-band clusters kept),
    until its abscissa agrees to ``tol``.

    Parameters
    ----------
    nm : NumericModel
    loop : NumericLoop
    method, resolution, max_resolution, tol, rtol_resolved, count
        As for :func:`~phdesign.numeric.spectrum.spectrum`.
    design : str
        A label of the design for the report.

    Returns
    -------
    LoopSpectrum
    """
    m = nm.n_ports
    loop.check(m)
    S_a = loop.selection(m)
    options: dict[str, Any] = {
        "method": method,
        "max_resolution": max_resolution,
        "tol": tol,
        "rtol_resolved": rtol_resolved,
        "count": count,
    }
    plant = replace(
        spectrum(nm, S_a, np.asarray(loop.K, float), resolution=resolution, **options),
        system="controlled plant (u_a = -K y_a)",
    )
    error = spectrum(nm, loop.C_m, loop.L, resolution=resolution, **options)
    if tol is None:
        tol = 1e-10 if method == "galerkin" else 1e-3
    if rtol_resolved is None:
        rtol_resolved = 1e-6 if method == "galerkin" else 1e-2
    p0, pmax = default_resolutions(nm, method)
    if resolution is None:  # where both blocks converged: usually one pair suffices
        p0 = max(plant.resolutions[0], error.resolutions[0])
    p = int(resolution) if resolution is not None else p0
    pmax = int(max_resolution) if max_resolution is not None else max(pmax, p)
    systems: dict[int, LoopSystem] = {}

    def solve(res: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        systems[res] = system = assemble(discretize(nm, method, res), loop)
        return pencil_eigen(system.A, system.E, condition)

    coarse = solve(p, condition=False)[0]
    best: _Pair | None = None
    previous = math.inf
    while True:
        pair = _drift_pair(solve, coarse, p, rtol_resolved)
        relative = pair.d_alpha / max(1.0, abs(pair.alpha or 0.0))
        if pair.alpha is not None and (
            best is None or relative < best.d_alpha / max(1.0, abs(best.alpha or 0.0))
        ):
            best = pair
        if relative <= tol or pair.resolutions[1] >= pmax or _stalled(pair, relative, previous):
            break
        p, coarse, previous = pair.resolutions[1], pair.lam, relative
    chosen = best or pair
    fine_system = systems[chosen.resolutions[1]]
    triangular = max(systems[r].triangular_residual for r in chosen.resolutions)
    A_K, A_err = fine_system.blocks()
    E = fine_system.discrete.E
    blocks = (sl.eigvals(A_K, E), sl.eigvals(A_err, E))
    return _report(nm, chosen, blocks, plant, error, tol, count, method, triangular, design)


def _stalled(pair: _Pair, relative: float, previous: float) -> bool:
    """Refinement no longer helps: an ill-conditioned abscissa whose drift did not shrink.

    Near a coalescence (a Jordan block of the loop: a plant and an error eigenvalue that
    coincide, coupled by K ỹ_a) round-off, not resolution, limits the digits.
    """
    if pair.alpha is None or relative < 0.1 * previous:
        return False
    lead = int(np.argmax(pair.lam[pair.counted].real))
    return bool(pair.lead_loose or pair.kappa[pair.counted][lead] > ILL_CONDITION)


def _report(
    nm: NumericModel,
    pair: _Pair,
    blocks_lam: tuple[np.ndarray, np.ndarray],
    plant: SpectrumReport,
    error: SpectrumReport,
    tol: float,
    count: int,
    method: str,
    triangular: float,
    design: str,
) -> LoopSpectrum:
    blocks = [a for a in (plant.spectral_abscissa, error.spectral_abscissa) if a is not None]
    warnings = [f"controlled plant: {w}" for w in plant.warnings]
    warnings += [f"error system: {w}" for w in error.warnings]
    if pair.alpha is None:
        warnings.append(
            f"no eigenvalue of the loop converges up to resolution {pair.resolutions[1]}: "
            "its spectral abscissa is unbounded below"
        )
        return LoopSpectrum(
            None,
            False,
            None,
            [],
            [],
            [],
            0,
            int(pair.lam.size),
            pair.resolutions,
            method,
            plant,
            error,
            None,
            triangular,
            True,
            False,
            warnings,
            nm.name,
            design,
        )
    lam, kappa = pair.lam[pair.counted], pair.kappa[pair.counted]
    order = np.lexsort((np.abs(lam.imag), -np.round(lam.real, 12)))[:count]
    rightmost = [complex(z) for z in lam[order]]
    conds = [float(c) for c in kappa[order]]
    alpha, d_alpha = pair.alpha, pair.d_alpha
    converged = d_alpha <= tol * max(1.0, abs(alpha))
    digits = float(-np.log10(max(d_alpha, 1e-17) / max(1.0, abs(alpha))))
    ill = bool(conds and (conds[0] > ILL_CONDITION or pair.lead_loose))
    if ill:
        warnings.append(
            f"the loop's rightmost eigenvalue {rightmost[0]:.6g} is ill-conditioned "
            f"(condition number {conds[0]:.3g}): near a coalescence; few digits are reliable"
        )
    unresolved = np.setdiff1d(np.arange(pair.lam.size), pair.counted)
    right = unresolved[pair.lam.real[unresolved] > alpha + 1e-9 * max(1.0, abs(alpha))]
    band = np.max(np.abs(lam))
    low = right[np.abs(pair.lam[right]) <= band]
    if low.size:
        warnings.append(
            f"{low.size} unresolved eigenvalues of the loop lie right of its abscissa within "
            f"the resolved band (max Re {float(np.max(pair.lam.real[low])):.3g}): check them"
        )
    if not converged:
        warnings.append(
            f"the loop's spectral abscissa did not converge to {tol:g}: it drifts by "
            f"{d_alpha:.2g} between resolutions {pair.resolutions[0]} and {pair.resolutions[1]}"
        )
    gap = alpha - max(blocks) if blocks else None
    if gap is not None and abs(gap) > max(10 * d_alpha, 1e-8) * max(1.0, abs(alpha)):
        warnings.append(
            f"the loop's abscissa differs from max(plant, error) by {gap:.2g}, beyond its "
            "resolved digits: the separation structure is not reproduced (report this)"
        )
    return LoopSpectrum(
        spectral_abscissa=alpha,
        converged=bool(converged),
        digits=digits,
        rightmost=rightmost,
        condition_numbers=conds,
        origin=_tag(rightmost, blocks_lam),
        n_resolved=pair.n_tight,
        n_total=int(pair.lam.size),
        resolutions=pair.resolutions,
        method=method,
        plant=plant,
        error=error,
        separation_gap=gap,
        triangular_residual=triangular,
        ill_conditioned=ill,
        warnings=warnings,
        model=nm.name,
        design=design,
    )


def loop_statespace(system: LoopSystem, name: str = "loop") -> Any:
    """Return the assembled loop as ``control.StateSpace`` with named signals.

    States ``e1[j]…`` (plant) then ``hat_e1[j]…`` (observer), as
    :func:`phdesign.numeric.export.state_labels`; inputs the free plant inputs ``v``
    (``u<i>`` for the inputs not actuated); outputs ``y1…`` (plant), ``y_hat1…``
    (observer) and ``u1…`` (the inputs the plant receives, actuated ones included).
    """
    import control

    from phdesign.numeric.export import state_labels

    d = system.discrete
    m = d.n_ports
    A = np.linalg.solve(system.E, system.A)
    B = np.linalg.solve(system.E, system.B)
    C = np.vstack([system.C_y, system.C_yhat, system.C_u])
    D = np.vstack([system.D_y, system.D_yhat, system.D_u])
    return control.ss(
        A,
        B,
        C,
        D,
        inputs=[f"u{j + 1}" for j in system.others],
        outputs=[f"y{i + 1}" for i in range(m)]
        + [f"y_hat{i + 1}" for i in range(m)]
        + [f"u{i + 1}" for i in range(m)],
        states=state_labels(d) + state_labels(d, "hat_"),
        name=name,
    )
