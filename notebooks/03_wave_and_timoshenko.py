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
# # Wave and Timoshenko beam: what the propositions promise, what the spectrum shows
#
# Two first-order ($N = 1$) models. For $N = 1$, Propositions 3.1 (asymptotic) and 3.2
# (exponential) select the same traces, so a design that satisfies one satisfies the other:
# the verdicts are *exponential* or *inconclusive*, never asymptotic only. We check the
# exponential verdicts against exact and computed decay rates, and look at what an
# inconclusive design really does.

# %%
import numpy as np

import phdesign as phd
from phdesign import plots

wave = phd.load("wave")
verdict = phd.Observer(wave, sensors=[2], gain="symbolic").classify()
print("sensor y2, symbolic gain:", verdict.verdict, "|", verdict.result("3.2", 2).reason)
assert verdict.verdict == "exponential"
string = phd.Observer(wave, sensors=[2])  # y2 = u_t(1); a gain per question below


def exact_abscissa(k):
    """½ ln|(1 − k)/(1 + k)|: the damped string's spectral abscissa (k ≠ 1)."""
    return 0.5 * np.log(np.abs((1 - k) / (1 + k)))


gains = np.array([0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 0.95, 1.05, 1.2, 1.5, 2.0, 3.0, 5.0])
computed = []
for k in gains:
    rep = string.with_gain(float(k)).spectrum()
    computed.append(rep.spectral_abscissa if rep.converged else np.nan)
computed = np.array(computed)
errors = np.abs(computed - exact_abscissa(gains))
for k, a, e in zip(gains, computed, errors, strict=True):
    print(f"k = {k:4.2f}: computed {a:+.12f}, exact {exact_abscissa(k):+.12f}, |diff| {e:.1e}")
assert np.all(errors < 1e-8)
fig = plots.plot_abscissa_sweep(
    gains, computed, exact=exact_abscissa, exact_label="exact ½ ln|(1−k)/(1+k)|"
)
fig

# %% [markdown]
# The best gain is the matched damper $k = 1$: there the exact spectrum is empty. phdesign
# does not invent a number for it:

# %%
matched = string.with_gain(1.0).spectrum()
print("k = 1: unbounded below:", matched.unbounded_below, "| abscissa:", matched.spectral_abscissa)
print(matched.warnings[0])
assert matched.unbounded_below

# %% [markdown]
# And the spectrum for $k = 0.5$, against the exact eigenvalues: the resolved ones sit on
# the line $\mathrm{Re}\,\lambda = \tfrac12\ln(1/3)$; the unresolved top of the discrete
# spectrum drifts towards the imaginary axis (the loss of boundary damping of every
# semi-discretization), which is why only resolved eigenvalues count.

# %%
rep = string.with_gain(0.5).spectrum()
p, p_fine = rep.resolutions
m = np.arange(-12, 12)
exact = exact_abscissa(0.5) + 1j * (m + 0.5) * np.pi
fig = rep.plot(exact=exact, xlim=(-1.5, 0.2), ylim=(-40, 40))
fig

# %%
print(f"{rep.n_resolved} of {rep.n_total} eigenvalues resolved at degrees {p} and {p_fine}")

# %% [markdown]
# ## Timoshenko beam: exponential against inconclusive designs
#
# $x$ = (shear strain, momentum, angular strain, angular momentum), so
# $e$ = (shear force, velocity, bending moment, angular velocity). The inputs are the
# velocities at $z = 0$ and the force and moment at $z = 1$ (clamped-free when $u = 0$); the
# outputs are $y_1 = -e_1(0)$, $y_2 = -e_3(0)$ (force and moment at the clamp) and
# $y_3 = e_2(1)$, $y_4 = e_4(1)$ (velocities at the free end). The search classifies every
# subset.

# %%
timo = phd.load("timoshenko")
found = phd.search_sensors(timo, gain=1)
print("minimal sensor sets:", found.minimal)
assert found.minimal["exponential"] == ((1, 2), (3, 4))

# %% [markdown]
# Take the exponential design $\{y_3, y_4\}$ and the inconclusive $\{y_2, y_3\}$ (one
# sensor at each end), both with $L = I$, and compare their spectral abscissas and error
# energies. Inconclusive is not unstable: the propositions are sufficient conditions.

# %%
timo_plant = phd.Plant(timo)  # one numeric model for both designs
x0 = "x1: sin(pi*z), x3: z*(1 - z)"
designs = {"{y3, y4}": (3, 4), "{y2, y3}": (2, 3)}
runs, reps = {}, {}
for label, sensors in designs.items():
    obs = phd.Observer(timo_plant, sensors=list(sensors), gain=1)
    reps[label] = obs.spectrum()
    runs[label] = obs.simulate(x0=x0, t_end=10.0, samples=401)
    verdict = found.subset(sensors).verdict
    # below its resolved floor H̃ is made of unresolved modes: time_below() then says None
    times = [runs[label].time_below(r) for r in (1e-2, 1e-4)]
    shown = [f"{t_:.2f} s" if t_ is not None else "not resolved" for t_ in times]
    print(
        f"{label}: {verdict:12} spectral abscissa {reps[label].spectral_abscissa:.4f} "
        f"(converged {reps[label].converged}); H̃/H̃(0) < 1e-2 at {shown[0]}, "
        f"< 1e-4 at {shown[1]} (H̃ resolved down to {runs[label].resolved_floor})"
    )
assert found.subset((3, 4)).verdict == "exponential"
assert found.subset((2, 3)).verdict == "inconclusive"
assert reps["{y2, y3}"].spectral_abscissa < 0
for label, r in reps.items():
    print(f"{label}: rightmost {', '.join(f'{z:.4f}' for z in r.rightmost[:3])}")
fig = plots.plot_error_energy(runs)
fig

# %% [markdown]
# Both designs converge here; only $\{y_3, y_4\}$ (or $\{y_1, y_2\}$) comes with a
# certificate, which holds for every positive gain and every parameter value the
# classifier was given, while the inconclusive design's decay is a numerical observation
# for these parameters only.
