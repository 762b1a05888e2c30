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
# # Boundary dynamics: a payload on a flexible arm, and a string with a tip mass
#
# Real structures end in something: an arm carries a payload, a string a mass. phdesign
# joins such a *boundary system* $\dot x_c = (J_c - R_c)Q_c x_c + G_c u_c + B_c w$,
# $y_c = G_c^\top Q_c x_c$ to the PDE's boundary ports by the power-preserving gyrator
# $u_p = -y_c$, $u_c = y_p$; the coupled system is again port-Hamiltonian with energy
# $H + H_c$. The paper's propositions concern static boundary conditions, so the verdict on
# a coupled observer rests on other theorems (the dynamic-feedback theorem of Ramirez,
# Le Gorrec, Macchelli and Zwart for exponential convergence, an exact imaginary-axis test
# for asymptotic convergence), and it says which. This notebook asks two questions: how a
# payload changes which sensors suffice on a flexible arm, and why no boundary gain makes
# the observer of a string with a tip mass converge exponentially.

# %%
import matplotlib.pyplot as plt
import numpy as np

import phdesign as phd
from phdesign.plots import plot_boundary_states

string = phd.load("string-tip-mass")
print(string)

# %% [markdown]
# ## The string with a tip mass: asymptotic, never exponential
#
# $\rho u_{tt} = T u_{zz}$, $u(0) = 0$, and at $z = 1$ a mass $m$ with a damper $c$:
# $m u_{tt}(1) = -T u_z(1) - c u_t(1)$. Its eigenvalues solve
# $(m\lambda + c)\sinh\lambda + \cosh\lambda = 0$ (unit $\rho$, $T$), so
# $\lambda_k \approx i\pi k - (c - i m \pi k)/(c^2 + m^2\pi^2 k^2)$: the real parts tend to 0
# like $-c/(m\pi k)^2$. The high modes see the mass as a wall. An observer may measure
# the force at the clamp ($y_1$) or the mass's velocity ($y_2$, injected as a force on the
# mass); every sensor set is asymptotic, none exponential, whatever the gain.

# %%
search = phd.search_sensors(string, gain=1)
print(search)
assert search.minimal["exponential"] == ()
assert search.minimal["asymptotic"] == ((1,), (2,))

reports = {}
for gain in (0.5, 4.0):
    obs = phd.Observer(string, sensors=[2], gain=gain)
    assert obs.classify().verdict == "asymptotic"
    reports[gain] = obs.spectrum()
    print(
        f"gain {gain}: abscissa {reports[gain].spectral_abscissa}, "
        f"no decay: {reports[gain].no_decay}"
    )
    assert reports[gain].no_decay

# %%
fig, ax = plt.subplots(figsize=(6, 3.5))
for gain, report in reports.items():
    lam = report.eigenvalues[report.resolved & (report.eigenvalues.imag > 0)]
    ax.semilogy(lam.imag, -lam.real, "o", ms=3, label=f"l = {gain}")
k = np.arange(1, 9)
ax.semilogy(np.pi * k, 1 / (np.pi * k) ** 2, "k--", lw=1, label="c/(m π k)² (plant)")
ax.set_xlabel("Im λ")
ax.set_ylabel("−Re λ")
ax.set_title("string with a tip mass: the error's real parts approach 0")
ax.legend()
plt.show()

# %% [markdown]
# ## The mass's own state: where it starts, how it is estimated
#
# A boundary system's states start where the initial state names them (`mass momentum: 1`:
# the mass moves, the string is at rest), the observer's estimates where its own initial
# state says; `phdesign ports` lists the coupled system's external ports (here the force
# at the clamp $y_1$ and the mass's velocity $y_2$). Measured at the clamp, the observer
# recovers the mass's momentum, and the run's figure shows it beside its estimate.

# %%
print("\n".join(str(string.ports).splitlines()[-3:]))
obs = phd.Observer(string, sensors=[1], gain=1)
run = obs.simulate(x0="mass momentum: 1", xhat0="mass momentum: -0.5", t_end=10, samples=201)
assert run.x_c[0, 0] == 1.0
assert run.x_c_hat[0, 0] == -0.5
assert abs(run.x_c[-1, 0] - run.x_c_hat[-1, 0]) < 1e-3 * abs(run.x_c[0, 0] - run.x_c_hat[0, 0])
plot_boundary_states(run)

# %% [markdown]
# ## A flexible arm with a payload
#
# The Timoshenko beam of `flexible-arm` is clamped to a rigid hub (inertia $I_{hub}$,
# driven by a torque) at $z = 0$ and free at $z = 1$. A payload of mass $M$ at the tip makes
# the tip a velocity port: the payload imposes $w_t(1)$ and feels the shear force. Both are
# boundary systems; their own inputs (the torque, a force on the payload) are ports of the
# coupled model, so the hub's rate and the payload's velocity are sensors.


# %%
def arm_with_payload(M):
    return phd.BCPHS.define(
        name="arm with payload",
        interval=(0, 1),
        order=1,
        P={
            0: [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]],
            1: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]],
        },
        H=[["K", 0, 0, 0], [0, "1/rho", 0, 0], [0, 0, "EI", 0], [0, 0, 0, "1/I_rho"]],
        parameters={"K": 1, "rho": 1, "EI": 1, "I_rho": 1, "I_hub": 1, "M": M},
        inputs=["e2(0)", "e4(0)", "e2(1)", "e3(1)"],
        outputs="conjugate",
        boundary_systems=[
            {
                "name": "hub",
                "ports": [2],
                "J": [[0]],
                "R": [[0]],
                "Q": [["1/I_hub"]],
                "G": [[-1]],
                "B": [[1]],
                "inputs": ["torque"],
                "outputs": ["hub rate"],
            },
            {
                "name": "payload",
                "ports": [3],
                "J": [[0]],
                "R": [[0]],
                "Q": [["1/M"]],
                "G": [[-1]],
                "B": [[1]],
                "inputs": ["force"],
                "outputs": ["payload velocity"],
            },
        ],
    )


arm = phd.load("flexible-arm")
loaded = arm_with_payload(0.5)
print("outputs without payload:", [str(y) for y in arm.external_outputs], "+ hub rate")
print(
    "outputs with payload:   ",
    [str(y) for y in loaded.external_outputs],
    "+ hub rate, payload velocity",
)
bare_sets = phd.search_sensors(arm, gain=1).minimal
loaded_sets = phd.search_sensors(loaded, gain=1).minimal
print("without payload, minimal asymptotic sets:", bare_sets["asymptotic"])
print("with payload,    minimal asymptotic sets:", loaded_sets["asymptotic"])
assert bare_sets["asymptotic"] == ((1, 4), (2, 3))
assert loaded_sets["asymptotic"] == ((1, 3), (2, 4))

# %% [markdown]
# Without a payload the tip's two velocities ($y_2 = w_t(1)$, $y_3 = \phi_t(1)$) suffice,
# or the root's shear force with the hub's rate. With the payload the tip velocity is no
# longer an output of the beam: it is the payload's state, measured as $y_4$; the pairs
# that suffice are the payload's velocity with the tip's rotation rate ($y_2$), or the
# root's shear force with the hub's rate ($y_1$, $y_3$). Neither is exponential: the hub
# and the payload are not strictly input passive. How fast does the observer converge? The
# error energy of the tip pair, for payloads of growing mass:

# %%
fig, ax = plt.subplots(figsize=(6, 3.5))
final = {}
for M in (0.1, 2.0):
    obs = phd.Observer(arm_with_payload(M), sensors=[2, 4], gain=1)
    run = obs.simulate(x0="x2: z, x4: 1", t_end=10, samples=201)
    ax.semilogy(run.t, run.H_err / run.H_err[0], label=f"payload M = {M}")
    final[M] = run.H_err[-1] / run.H_err[0]
ax.set_xlabel("t")
ax.set_ylabel("H_err / H_err(0)")
ax.set_title("arm with payload: error energy, sensors y2 and y4")
ax.legend()
plt.show()
print({M: f"{v:.2e}" for M, v in final.items()})
assert final[0.1] < final[2.0]  # a heavier payload is harder to estimate
