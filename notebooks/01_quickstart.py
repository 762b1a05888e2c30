# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Quickstart: from a PDE to a tuned boundary observer
#
# A vibrating string whose tension grows along it, $T(z) = T_0 (1 + z)$, on $[0, 1]$:
#
# $$\partial_t \begin{pmatrix} p \\ \varepsilon \end{pmatrix}
#   = \begin{pmatrix} 0 & 1 \\ 1 & 0 \end{pmatrix} \partial_z
#     \left( \begin{pmatrix} 1/\rho & 0 \\ 0 & T(z) \end{pmatrix}
#            \begin{pmatrix} p \\ \varepsilon \end{pmatrix} \right),$$
#
# with momentum $p$, strain $\varepsilon$, efforts $e = (v, \sigma)$ (velocity, stress).
# The inputs are the velocity at $z = 0$ and the stress at $z = 1$; the outputs are their
# power conjugates, so that $\dot H = u^\top y$. We write the model once in TOML and once
# in code, derive its ports, classify an observer, search the sensors, and export the
# error system to python-control. Everything is reached through `import phdesign as phd`;
# every result shows itself as a table (its `print()` is what the command line prints).

# %%
import control
import numpy as np

import phdesign as phd
from phdesign import plots

TOML = """
name = "tapered string"
interval = [0, 1]
order = 1
states = ["momentum", "strain"]

[parameters]
rho = 1
T0 = 1

[matrices]
P1 = [[0, 1], [1, 0]]
H = [["1/rho", 0], [0, "T0*(1 + z)"]]

[ports]
inputs = ["e1(0)", "e2(1)"]
outputs = ["-e2(0)", "e1(1)"]
"""
string = phd.model_from_toml(TOML)
string

# %% [markdown]
# The same model in code. Construction validates everything (symmetry of $P_k$,
# $P_0 + P_0^\top \le 0$, $P_N$ invertible, $\mathcal H$ positive definite, admissible ports).

# %%
same = phd.BCPHS.define(
    name="tapered string",
    interval=(0, 1),
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[["1/rho", 0], [0, "T0*(1 + z)"]],
    inputs=["e1(0)", "e2(1)"],
    outputs=["-e2(0)", "e1(1)"],
    parameters={"rho": 1, "T0": 1},
    state_names=["momentum", "strain"],
)
assert same.H == string.H
assert same.inputs == string.inputs
print(phd.model_to_toml(same)[:120], "...")

# %% [markdown]
# ## Ports
#
# phdesign derives $Q$, $W_B = U R_{ext}^{-1}$ and $W_C = Y R_{ext}^{-1}$ exactly and checks
# $W_B \Sigma W_B^\top = 0$, $W_C \Sigma W_C^\top = 0$, $W_C \Sigma W_B^\top = I$.

# %%
ports = string.ports  # derived once, exactly, when the model was built
assert all(v == 0 for v in ports.identities.values())
ports

# %% [markdown]
# ## Classification of one design
#
# Measure $y_2 = v(1)$ (the tip velocity) with gain $L = 0.5$. For $N = 1$, Proposition 3.2
# gives exponential convergence when $\tfrac12 \tilde y_m^\top (L + L^\top) \tilde y_m
# \ge \kappa \|\tilde e(b)\|^2$; here $\tilde\sigma(1) = -0.5\, \tilde v(1)$, so
# $\|\tilde e(1)\|^2 = (1 + 0.25)\, \tilde v(1)^2$ and $\kappa^* = 0.5 / 1.25 = 0.4$.

# %%
obs = phd.Observer(string, sensors=[2], gain=0.5)
result = obs.classify()
assert result.verdict == "exponential"
assert abs(result.result("3.2", 2).kappa_float - 0.4) < 1e-12
result

# %% [markdown]
# ## Sensor search
#
# Every non-empty sensor subset, classified exactly; the minimal sets per verdict.

# %%
found = phd.search_sensors(string, gain=0.5)
assert found.minimal["exponential"] == ((1,), (2,))
found

# %% [markdown]
# ## Numbers: spectrum of the error system
#
# The propositions certify a decay; the spectrum says how fast. The bridge substitutes the
# parameters (and refuses any symbol left free), then the spectrum is computed at two
# resolutions and only eigenvalues that agree are kept.
#
# This string teaches a lesson: with a varying tension the modes' real parts are not all
# equal, and the least damped ones are the *highest* frequencies. Their real parts creep
# up towards the high-frequency (WKB) limit $\ln|r| / (2\tau)$, with the travel time
# $\tau = \int_0^1 \sqrt{\rho / T}\,dz = 2(\sqrt2 - 1)$ and the reflection coefficient
# $r = (Z - k)/(Z + k)$ of the damper $k = 0.5$ against the impedance
# $Z = \sqrt{\rho T(1)} = \sqrt2$ at the tip. No eigenvalue attains that supremum, and no
# refinement of the band could find it. phdesign derives it from the principal part of
# the PDE instead: the characteristic speeds, the transport along them and the reflections
# of the closed boundary give the chains of eigenvalues above the band and the limits of
# their real parts (the documentation's theory page). The abscissa is that limit, known
# to round-off, and named as "attained by no mode".

# %%
report = obs.spectrum(max_resolution=60)
tau, Z, k = 2 * (np.sqrt(2) - 1), np.sqrt(2), 0.5
wkb = np.log(abs((Z - k) / (Z + k))) / (2 * tau)
print(report)
attained = float(np.max(report.eigenvalues[report.resolved].real))
print(
    f"largest resolved real part {attained:.8f}; the chains' limit "
    f"{report.spectral_abscissa:.10f} ± {report.uncertainty:.1e}; "
    f"WKB limit ln|r|/(2τ) = {wkb:.10f}"
)
assert report.kind == "limit"
assert report.converged
assert abs(report.spectral_abscissa - wkb) <= max(report.uncertainty, 1e-12)
assert attained < wkb

# %% [markdown]
# ## Export to python-control
#
# Plant, observer and error system of the discretization, as `control.StateSpace`
# objects. The observer takes $(u, y_m)$ and returns $\hat y$ and the estimated state
# $\hat x$ at both ends and the midpoint (`quantity`, `z` choose others); the error system
# $E \dot{\tilde e} = (J - R - B K B^\top) \tilde e$, $K = C_m^\top L C_m$, has no input.
# Its poles contain the resolved eigenvalues above.

# %%
degree = report.resolutions[1]
plant_ss = obs.statespace("plant", resolution=degree)
observer_ss = obs.statespace("observer", resolution=degree)
error_ss = obs.statespace("error", resolution=degree)
for sys_ in (plant_ss, observer_ss, error_ss):
    print(f"{sys_.name:9}: {sys_.nstates} states, {sys_.ninputs} inputs, {sys_.noutputs} outputs")
assert isinstance(error_ss, control.StateSpace)
poles = control.poles(error_ss)
nearest = min(abs(poles - report.rightmost[0]))
print(f"distance from the rightmost resolved eigenvalue to the nearest pole: {nearest:.1e}")
assert nearest < 1e-8
fig = plots.plot_spectrum(
    poles,
    abscissa=wkb,
    title="error system poles (python-control)",
    xlim=(-3, 0.5),
    ylim=(-60, 60),
)
fig
