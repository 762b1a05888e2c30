r"""Structure-preserving discretizations of a BC-PHS: the common result type and dispatch.

Every method returns a :class:`DiscretePHS` in *effort coordinates* ê (the discrete
efforts, e ≈ e(ê)), in descriptor port-Hamiltonian form

.. math::

    E \dot{\hat e} = (J - R) \hat e + B u, \qquad y = B^\top \hat e + D u,
    \qquad H_d = \tfrac12 \hat e^\top E \hat e,

with :math:`E = E^\top \succ 0`, :math:`J = -J^\top`, :math:`R = R^\top \succeq 0` and
:math:`D = -D^\top`.  Hence, exactly (to round-off, whatever the resolution),

.. math::

    \dot H_d = -\hat e^\top R \hat e + u^\top y .

The energy-state form of the contract, :math:`\dot x_d = (J - R) Q x_d + B u`, is
:math:`x_d = E \hat e`, :math:`Q = E^{-1}`.

Methods
-------
``"galerkin"`` (default, :mod:`phdesign.numeric.discretization.galerkin`)
    Legendre-Galerkin with weakly imposed, power-conjugate boundary inputs: spectrally
    accurate for smooth data, any order N, any size n, H varying in z, any admissible
    ports.  Chosen as the default because spectral abscissas converge exponentially in the
    degree (the damped wave reaches 1e-13 at degree ~40), which is what makes the
    drift-filtered spectrum and the tuning reliable.
``"fd"`` (:mod:`phdesign.numeric.discretization.staggered`)
    Staggered-grid finite differences (Trenchant et al., JCP 2018), the paper's setting:
    second order, for N = 1 and N = 2 models whose state splits into two groups with
    mixed boundary causality (wave, Timoshenko, Euler-Bernoulli).
"""

from __future__ import annotations

from phdesign.core import limits
from phdesign.core.checks import DISCRETIZATION_METHODS
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.defaults import defaults_for
from phdesign.numeric.discretization.feedback import close_plant_feedback
from phdesign.numeric.discretization.phs import ClosedLoop, DiscretePHS, feedback_matrix

__all__ = ["METHODS", "ClosedLoop", "DiscretePHS", "discretize", "feedback_matrix"]

METHODS = DISCRETIZATION_METHODS


def discretize(
    nm: NumericModel,
    method: str = "galerkin",
    resolution: int | None = None,
    *,
    basis: str | None = None,
) -> DiscretePHS:
    """Discretize ``nm`` with ``method`` at ``resolution``.

    Parameters
    ----------
    nm : NumericModel
    method : {"galerkin", "fd"}
    resolution : int, optional
        Degree (Galerkin) or nodes per state group (FD); default from the registry
        :mod:`phdesign.numeric.discretization.defaults` (Galerkin 40, or 16 for N >= 3; FD 70: the
        paper's 140 states for the beam).
    basis : {"scaled", "legendre"}, optional
        Galerkin basis (default: the registry's); not accepted by ``"fd"``.

    Returns
    -------
    DiscretePHS
    """
    limits.check_discretization(nm, method, resolution)
    if method not in METHODS:
        raise NumericError(f"unknown discretization method {method!r}; expected one of {METHODS}")
    res = defaults_for(method, nm.order).resolution if resolution is None else int(resolution)
    # the model's own [feedback] closes the open discretization (numeric.feedback)
    if method == "galerkin":
        from phdesign.numeric.discretization.galerkin import galerkin

        return close_plant_feedback(galerkin(nm, res, basis))
    if basis is not None:
        raise NumericError(f"basis applies to method='galerkin' only; found basis={basis!r}")
    from phdesign.numeric.discretization.staggered import staggered_fd

    return close_plant_feedback(staggered_fd(nm, res))
