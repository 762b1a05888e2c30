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
# # Observer-based boundary control: feed back what is not measured
#
# A boundary damper works by feeding a collocated output back to its input,
# $u_i = -k\,y_i$: the power $u_i y_i = -k y_i^2$ leaves the structure.  On the paper's
# beam (here without viscous damping, $d = 0$: left alone it oscillates forever) a tip
# torque $u_3 = e_2(1)$ would need the tip rotation rate $y_3 = \partial_z e_1(1)$, but
# the only sensor is the tip velocity $y_4 = -e_1(1)$, which is not collocated with the
# torque: $u_3 = -k\,y_4$ is not a damper.  The observer estimates $y_3$ from $y_4$, and
# the controller feeds the estimate back,
#
# $$u_3 = -K\,\hat y_3, \qquad \hat u = u + C_m^\top L\,(y_4 - \hat y_4).$$
#
# With $\tilde x = x - \hat x$ this is $u_3 = -K y_3 + K\tilde y_3$: the *controlled
# plant* ($u_3 = -K y_3$, a BC-PHS with a dissipative boundary) driven by the estimation
# error, and an *error system* that does not see $u$ at all (the observer computes $u$
# itself).  The loop is block-triangular in $(x, \tilde x)$: its spectrum is the union of
# the two, and it converges when both do.

# %%
import numpy as np

import phdesign as phd
from phdesign import plots

beam = phd.load("euler-bernoulli")
loop = phd.Loop(beam, actuate=3, feedback=1, sensors=[4], gain=1, parameters={"d": 0})
print(loop)

# %% [markdown]
# ## Certificates
#
# The controlled plant is classified as a plant with no sensors: the left-hand side of
# every proposition is then its own boundary dissipation $K e_1'(1)^2$.  It leaves the tip
# velocity $e_1(1)$ free, so no proposition applies; the error system with $y_4$ is
# exponential (Proposition 3.4).  The certificates say nothing about this loop:
# *inconclusive*, never "unstable".

# %%
certificates = loop.classify()
print(certificates)
assert certificates.plant.verdict == "inconclusive"
assert certificates.error.verdict == "exponential"
assert certificates.verdict == "inconclusive"

# %% [markdown]
# ## What the spectrum shows
#
# The converged spectrum of the *assembled* loop (plant and observer states together: 124
# discrete states at Legendre degree 30, compared with degree 20) against those of its two
# blocks, each refined on its own: the loop is exactly as fast as the slower block, the
# controlled plant.

# %%
spectrum = loop.spectrum(count=6)
print(spectrum)
assert spectrum.converged
assert abs(spectrum.spectral_abscissa - spectrum.plant_abscissa) < 1e-9
assert spectrum.error_abscissa < spectrum.plant_abscissa < -0.7
fig = spectrum.plot()
fig

# %% [markdown]
# ## Estimated against ideal measured feedback
#
# The ideal, which no sensor allows here, feeds the true $y_3$ back: the same loop with
# $y_3$ measured as well and `feedback_source="measured"` (the plant then never sees the
# observer).  From the paper's initial state $x_0 = (0,\ z - 0.9)$ and an observer that
# starts from zero, the estimated loop first acts on a wrong $\hat y_3$.  The difference
# $\delta = x_{est} - x_{ideal}$ obeys the controlled plant driven by $K\tilde y_3$ from
# $\delta(0) = 0$: it is a transient, made while the estimation error dies out (at the
# error system's rate $-1.97$, faster than the plant's $-0.72$), that then decays with the
# plant.

# %%
ideal = phd.Loop(
    beam,
    actuate=3,
    feedback=1,
    sensors=[3, 4],
    gain=1,
    parameters={"d": 0},
    feedback_source="measured",
    resolution=24,
)
estimated = phd.Loop(
    beam, actuate=3, feedback=1, sensors=[4], gain=1, parameters={"d": 0}, resolution=24
)
x0 = "x1: 0, x2: z - 0.9"
runs = {
    "ideal: measured y3": ideal.simulate(x0=x0, t_end=8.0, samples=401),
    "observer-based: estimated ŷ3": estimated.simulate(x0=x0, t_end=8.0, samples=401),
}
fig, (ax_energy, ax_tip, ax_torque) = plots.new_figure(1, 3, figsize=(14, 3.8))
for label, run in runs.items():
    ax_energy.semilogy(run.t, run.H, label=f"H, {label}")
    ax_tip.plot(run.t, run.w[:, -1], label=label)
    ax_torque.plot(run.t, run.u[:, 2], label=label)
    print(f"{label}: H(8)/H(0) = {run.H[-1] / run.H[0]:.2e}, warnings: {list(run.warnings)}")
run = runs["observer-based: estimated ŷ3"]
ax_energy.semilogy(run.t, run.H_err, "k:", label="H̃ (estimation error)")
ax_energy.set(xlabel="time t [s]", ylabel="energy [J]", title="energies (log scale)")
ax_tip.set(xlabel="time t [s]", ylabel="w(1, t) [m]", title="tip deflection")
ax_torque.set(xlabel="time t [s]", ylabel="u3 = e2(1)", title="tip torque")
for ax in (ax_energy, ax_tip, ax_torque):
    ax.grid(True, alpha=0.3)
    ax.legend()
reference = runs["ideal: measured y3"]
difference = np.abs(run.u[:, 2] - reference.u[:, 2]) / np.max(np.abs(reference.u[:, 2]))
for t_from in (0.0, 2.0, 4.0, 6.0):
    window = run.t >= t_from
    print(
        f"torque difference after t = {t_from:g} s: {np.max(difference[window]):.2e} of its peak"
    )
assert np.max(difference[run.t >= 6.0]) < 0.1 * np.max(difference)
assert all(not r.warnings for r in runs.values())
assert run.H_err[-1] < 1e-6 * run.H_err[0]
assert run.H[-1] < 1e-2 * run.H[0]
fig

# %% [markdown]
# Both loops take the energy out at the controlled plant's rate; the observer-based one
# pays only a transient.  Feeding $\hat y_3$ back is what makes the torque actuator usable
# with a velocity sensor.
#
# ## Tuning by separation
#
# The loop's abscissa is $\max(\alpha_{plant}(K), \alpha_{error}(L))$, so $K$ is tuned on
# the controlled plant and $L$ on the error system, each on its own, and the result is
# checked on the assembled loop.

# %%
tuned = loop.tune(starts=1)
print(tuned)
assert tuned.report.converged
assert tuned.spectral_abscissa < spectrum.spectral_abscissa
assert tuned.limited_by == "plant"

# %% [markdown]
# ## A loop the propositions do certify
#
# Actuate the tip shear force $u_4 = e_2'(1)$ with the estimate of the tip velocity $y_4$,
# measuring only the bending moment at the clamp, $y_2 = -e_2(0)$ (a strain gauge): the
# controlled plant is exponential ($\kappa^* = k/(1 + k^2)$ by Proposition 3.4), the error
# system too, and so is the loop.

# %%
certified = phd.Loop(beam, actuate=4, feedback=1, sensors=[2], gain=1).classify()
print(certified.plant.verdict, certified.error.verdict, "->", certified.verdict)
print(certified.reason)
assert certified.verdict == "exponential"
