r"""Stochastic simulation of plant and observer with white noise, exact at the samples.

Plant and observer (:func:`phdesign.numeric.time.simulation.coupled_system`, state
:math:`X = (\hat e, \hat e_{obs})`) with the noise of :mod:`phdesign.numeric.noise.figures`:
the plant input carries :math:`w` (intensity :math:`\Sigma_w`), the observer receives
:math:`y_m + \nu` (intensity :math:`\Sigma_\nu`) and knows u only.  With
:math:`M = (I + KD)^{-1}` and :math:`G = M K`, the observer's correction is
:math:`\delta = G (B^\top \tilde e + D w) + M C_m^\top L \nu`, so

.. math::

    E_2 \dot X = A_2 X + B_2 u + N_2 n, \qquad
    N_2 = \begin{bmatrix} 0 & B \Sigma_w^{1/2} \\
    B M C_m^\top L \Sigma_\nu^{1/2} & B G D \Sigma_w^{1/2} \end{bmatrix},

n unit white noise; white disturbances :math:`B_w \Sigma_d^{1/2} n_d` of the model's
``[disturbances]`` and unknown inputs enter the plant's row only (the observer does not
know them), so the error's variance is :math:`\operatorname{tr}(C_p P C_p^\top)`, P the
Lyapunov covariance of :mod:`phdesign.numeric.noise.disturbance`. (The difference of the
two rows is the error system's noise input :math:`B M [-C_m^\top L \Sigma_\nu^{1/2},
\Sigma_w^{1/2}]`, since :math:`I - GD = M`.)

The sampled system is exact (Van Loan 1978): over a step Δt,
:math:`X_{k+1} = \Phi X_k + \Gamma u + \eta_k` with :math:`\Phi = e^{F \Delta t}`,
:math:`F = E_2^{-1} A_2`, and :math:`\eta_k` independent Gaussian with covariance

.. math::

    Q_d = \int_0^{\Delta t} e^{F s}\, E_2^{-1} N_2 N_2^\top E_2^{-\top}\, e^{F^\top s}\, ds,

the block-exponential integral computed with the doubling of
:mod:`phdesign.numeric.time.simulation` (stable for the stiff modes of fine discretizations).
So the samples have exactly the distribution of the continuous-time process at the sample
times, whatever Δt: a Monte-Carlo estimate of a variance converges to the Lyapunov value of
the same discretization, with no time-stepping bias.  By linearity the run is the
deterministic response to the initial states and u
(:func:`~phdesign.numeric.time.simulation.simulate`)
plus the response to the noise from zero.

Outputs y and ŷ are reported without the white-noise feedthrough of a model with D ≠ 0
(a sample of white noise has no finite value); the energy balance is audited on the
deterministic part only (a noisy run has no exact balance).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError, ObserverError
from phdesign.core.progress import report
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.coupled import boundary_series
from phdesign.numeric.discretization.functionals import Functional
from phdesign.numeric.discretization.points import point_outputs, point_series
from phdesign.numeric.discretization.registry import DiscretePHS, discretize, feedback_matrix
from phdesign.numeric.disturbance_inputs import DisturbanceChannels
from phdesign.numeric.inputs import input_samples
from phdesign.numeric.noise.figures import check_intensity, noise_intensities
from phdesign.numeric.threads import limited_threads
from phdesign.numeric.time.options import NOISY_SCHEME, SimulationOptions
from phdesign.numeric.time.result import SimulationResult
from phdesign.numeric.time.simulation import coupled_system, simulate
from phdesign.numeric.time.stepping import dissipation_integral

__all__ = ["SampledNoise", "noisy_coupled_system", "sampled_noise", "simulate_noisy"]


def noisy_coupled_system(
    d: DiscretePHS,
    C_m: np.ndarray | None,
    L: np.ndarray | None,
    intensity: np.ndarray | None,
    input_intensity: np.ndarray | None,
    disturbance: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    r"""Return ``(E2, A2, B2, N2)`` of plant and observer driven by unit white noise.

    Without sensors (``C_m`` None) only the plant, driven by the input noise.
    ``disturbance`` is :math:`B_d \Sigma_d^{1/2}`, the white disturbances' columns (last).
    """
    q = 0 if C_m is None else np.atleast_2d(C_m).shape[0]
    K = None if C_m is None or L is None else feedback_matrix(C_m, L, d.n_ports)
    E2, A2, B2 = coupled_system(d, K)
    sigma = np.zeros(q) if intensity is None else np.asarray(intensity, dtype=float)
    w_in = np.zeros(d.n_ports) if input_intensity is None else np.asarray(input_intensity, float)
    plant_w = d.B @ np.diag(np.sqrt(w_in))
    plant_d = np.zeros((d.dim, 0)) if disturbance is None else disturbance
    if K is None or C_m is None or L is None:
        return E2, A2, B2, np.hstack([plant_w, plant_d])
    loop = d.close(K)  # B M = loop.B, G = M K = loop.gain
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    observer_nu = loop.B @ C.T @ Lm @ np.diag(np.sqrt(sigma))
    observer_w = d.B @ loop.gain @ d.D @ np.diag(np.sqrt(w_in))
    top = np.hstack([np.zeros_like(observer_nu), plant_w, plant_d])
    bottom = np.hstack([observer_nu, observer_w, np.zeros_like(plant_d)])
    return E2, A2, B2, np.vstack([top, bottom])


@dataclass(frozen=True)
class SampledNoise:
    r"""The exact sampled noise response :math:`N_{k+1} = \Phi N_k + S z_k`, z standard normal.

    Attributes
    ----------
    Phi : ndarray
        :math:`e^{F \Delta t}`.
    factor : ndarray
        S with :math:`S S^\top = Q_d`.
    dt : float
    """

    Phi: np.ndarray
    factor: np.ndarray
    dt: float

    def paths(self, steps: int, runs: int = 1, rng: Any = None) -> np.ndarray:
        """Return ``steps + 1`` samples of ``runs`` paths from zero, shape (steps+1, dim, runs)."""
        gen = np.random.default_rng(rng)
        n, r = self.factor.shape
        X = np.zeros((steps + 1, n, runs))
        for k in range(steps):
            X[k + 1] = self.Phi @ X[k] + self.factor @ gen.standard_normal((r, runs))
        return X


def sampled_noise(E: np.ndarray, A: np.ndarray, N: np.ndarray, dt: float) -> SampledNoise:
    """Exact sampling over steps ``dt`` of ``E X' = A X + N n`` (module docstring)."""
    F = np.linalg.solve(E, A)
    G = np.linalg.solve(E, N)
    Phi = sl.expm(F * dt)
    Qd = dissipation_integral(F.T, G @ G.T, dt)  # ∫ e^{Fs} G Gᵀ e^{Fᵀs} ds
    lam, V = np.linalg.eigh(0.5 * (Qd + Qd.T))
    keep = lam > 1e-14 * max(float(lam[-1]), 1e-300) if lam.size else lam > 0
    factor = V[:, keep] * np.sqrt(lam[keep])
    return SampledNoise(Phi, factor, float(dt))


@limited_threads
def simulate_noisy(
    nm: NumericModel,
    C_m: np.ndarray | None = None,
    L: np.ndarray | None = None,
    *,
    x0: Callable[[np.ndarray], np.ndarray] | None = None,
    xhat0: Callable[[np.ndarray], np.ndarray] | None = None,
    u: Callable[[float], np.ndarray] | None = None,
    options: SimulationOptions | None = None,
    discrete: DiscretePHS | None = None,
    w: Callable[[float], np.ndarray] | None = None,
    disturbance: DisturbanceChannels | None = None,
) -> SimulationResult:
    """One sample path of plant and observer with sensor, input and disturbance noise.

    Parameters
    ----------
    nm, C_m, L, x0, xhat0, u, discrete, w, disturbance
        As for :func:`phdesign.numeric.time.simulation.simulate`.
    options : SimulationOptions, optional
        As for ``simulate`` (``at`` too: point outputs of the noisy plant and observer), with
        the noise: ``noise_intensity`` (sensor intensities
        σᵢ², one per sensor or one for all; needs sensors), ``input_intensity`` (plant
        input intensities, one per input or one for all), ``disturbance_intensity`` (white
        noise on the channels of ``disturbance`` (B's columns, then the unknown inputs),
        one per channel or one for all; needs
        ``disturbance``) and ``seed`` (the same seed gives
        the same path).  The stepping is exact (``scheme="expm"``): implicit midpoint does
        not apply to a noisy run.

    Returns
    -------
    SimulationResult
        As :func:`~phdesign.numeric.time.simulation.simulate`'s, with the noise description in
        ``info``.
    """
    opts = SimulationOptions.merged(options)
    opts.require("simulate_noisy", "noisy", "continuous")
    if opts.scheme != "expm":
        raise NumericError(NOISY_SCHEME.format(scheme=opts.scheme))
    if opts.noise_intensity is not None and C_m is None:
        raise ObserverError("sensor noise needs an observer: give the sensors C_m and gain L")
    q = 0 if C_m is None else np.atleast_2d(C_m).shape[0]
    sigma, w_in = noise_intensities(nm, q, opts.noise_intensity, opts.input_intensity, default=0.0)
    white = _white_disturbance(opts, disturbance)
    at = point_outputs(nm, opts.at, "at")  # an unknown field is refused before any work
    d = discrete if discrete is not None else discretize(nm, opts.method, opts.resolution)
    base = simulate(
        nm,
        C_m,
        L,
        x0=x0,
        xhat0=xhat0,
        u=u,
        options=opts.deterministic(),
        discrete=d,
        w=w,
        disturbance=disturbance,
    )
    report("simulate: the noise's sample path")
    columns = None
    if white is not None and disturbance is not None:
        columns = disturbance.columns(d) @ np.diag(np.sqrt(white))
    extra = _noise_paths(d, C_m, L, sigma, w_in, base.t, opts.seed, columns)
    U = None if u is None else input_samples(u, base.t, d.n_ports)
    described = []
    if opts.noise_intensity is not None:
        described.append(f"sensor intensity {', '.join(f'{s:g}' for s in sigma)}")
    if w_in is not None:
        described.append(f"input intensity {', '.join(f'{s:g}' for s in w_in)}")
    if white is not None:
        described.append(f"disturbance intensity {', '.join(f'{s:g}' for s in white)}")
    info = {
        **base.info,
        "scheme": "expm (exact; Van Loan sampled noise)",
        "noise": "; ".join(described) or "none",
        "seed": -1 if opts.seed is None else int(opts.seed),
    }
    return replace(base, info=info, **_noisy_series(d, C_m, L, base, extra, U, at))


def _white_disturbance(
    opts: SimulationOptions, disturbance: DisturbanceChannels | None
) -> np.ndarray | None:
    """Return the white disturbances' intensities, one per channel (None: none)."""
    if opts.disturbance_intensity is None:
        return None
    if disturbance is None:
        raise NumericError(
            "disturbance_intensity needs the disturbance matrix B(z) of the model's "
            "[disturbances]: the model has none"
        )
    count = len(disturbance.names)
    return check_intensity(opts.disturbance_intensity, count, "disturbance_intensity")


def _noise_paths(
    d: DiscretePHS,
    C_m: np.ndarray | None,
    L: np.ndarray | None,
    sigma: np.ndarray,
    w_in: np.ndarray | None,
    t: np.ndarray,
    seed: int | None,
    disturbance: np.ndarray | None = None,
) -> np.ndarray:
    """Return one path of the response to the noise from zero, sampled exactly on ``t``."""
    E2, A2, _, N2 = noisy_coupled_system(d, C_m, L, sigma, w_in, disturbance)
    if not (N2.shape[1] and t.size > 1):
        return np.zeros((t.size, E2.shape[0]))
    sampler = sampled_noise(E2, A2, N2, float(t[1] - t[0]))
    return sampler.paths(t.size - 1, 1, seed)[:, :, 0]


def _noisy_series(
    d: DiscretePHS,
    C_m: np.ndarray | None,
    L: np.ndarray | None,
    base: SimulationResult,
    extra: np.ndarray,
    U: np.ndarray | None,
    at: tuple[Functional, ...] = (),
) -> dict[str, Any]:
    """Return the series of the noise-free run ``base`` with the noise's response added.

    The displacement and the point outputs ``at`` are read from the noisy states.
    """
    n = d.dim
    eh = np.asarray(base.states) + extra[:, :n]
    changes: dict[str, Any] = {"states": eh, "H": d.hamiltonian(eh), "y": d.output(eh, U)}
    if C_m is not None and L is not None:
        eo = np.asarray(base.states_hat) + extra[:, n:]
        G = d.close(feedback_matrix(C_m, L, d.n_ports)).gain
        uo = (eh - eo) @ (d.B @ G.T) + (0.0 if U is None else U)
        changes.update(
            states_hat=eo,
            H_hat=d.hamiltonian(eo),
            H_err=d.hamiltonian(eh - eo),
            y_hat=d.output(eo, uo),
        )
    if base.z_w is not None and d.displacement_basis is not None:
        Wd = d.displacement_basis(base.z_w)
        changes["w"] = eh @ Wd.T
        if "states_hat" in changes:
            changes["w_hat"] = changes["states_hat"] @ Wd.T
    hat = changes.get("states_hat")
    return {**changes, **point_series(at, d, eh, hat), **boundary_series(d, eh, hat)}
