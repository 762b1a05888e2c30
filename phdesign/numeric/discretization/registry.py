r"""Structure-preserving discretizations of a BC-PHS: the registered methods and dispatch.

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
A method is one module with a :class:`~phdesign.numeric.discretization.base.Method`
subclass (registered by its name) and one entry of the table of defaults
(:mod:`phdesign.core.defaults`: resolutions, basis, caps and tolerances by order); this
module imports the built-in ones and checks that the two agree.

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
from phdesign.core.cache import MODEL_WORK
from phdesign.core.defaults import MethodDefaults, current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization import galerkin, staggered
from phdesign.numeric.discretization.base import Method, check_registered
from phdesign.numeric.discretization.coupled import close_and_couple
from phdesign.numeric.discretization.phs import ClosedLoop, DiscretePHS, feedback_matrix

__all__ = ["ClosedLoop", "DiscretePHS", "check_basis", "discretize", "feedback_matrix"]

#: The built-in methods (their modules register them as they load).
_BUILT_IN = (galerkin.Galerkin, staggered.StaggeredFD)
check_registered()


def check_basis(entry: MethodDefaults, basis: object) -> None:
    """Refuse a ``basis`` that the method of ``entry`` does not accept (None always passes)."""
    if basis is None or basis in entry.bases:
        return
    if not entry.bases:
        raise NumericError(
            f"basis: method {entry.name!r} has no bases; found basis={basis!r} (methods with "
            f"bases: {', '.join(repr(m.name) for m in current().methods.values() if m.bases)})"
        )
    raise NumericError(
        f"basis must be one of {', '.join(map(repr, entry.bases))} for method {entry.name!r}; "
        f"found {basis!r}"
    )


def discretize(
    nm: NumericModel,
    method: str | None = None,
    resolution: int | None = None,
    *,
    basis: str | None = None,
) -> DiscretePHS:
    """Discretize ``nm`` with ``method`` at ``resolution``.

    Parameters
    ----------
    nm : NumericModel
    method : str, optional
        A registered method (``"galerkin"``, ``"fd"``); default: the table's
        (:mod:`phdesign.core.defaults`).
    resolution : int, optional
        Degree (Galerkin) or nodes per group (FD); default: the method's row of the table
        (Galerkin 40, or 16 for N >= 3; FD 70: the paper's 140 states for the beam).
    basis : str, optional
        The basis of a method that has several (Galerkin: ``"scaled"`` or
        ``"legendre"``); default: the row's.

    Returns
    -------
    DiscretePHS
        Built once per model, method, resolution and basis and shared
        (:data:`~phdesign.core.cache.MODEL_WORK`): its matrices are read-only.
    """
    table = current()
    method = table.method if method is None else method
    entry = table.entry(method)
    limits.check_discretization(nm, method, resolution)
    check_basis(entry, basis)
    row = entry.at(nm.order)
    res = row.resolution if resolution is None else int(resolution)
    chosen = row.basis if basis is None else basis
    return MODEL_WORK.get(
        nm, ("discretize", method, res, chosen), lambda: _build(nm, method, res, chosen)
    )


def _build(nm: NumericModel, method: str, resolution: int, basis: str | None) -> DiscretePHS:
    discrete = Method.from_name(method).build(nm, resolution, basis)
    if discrete.method != method:
        raise NumericError(
            f"the method {method!r} built a discretization that says method="
            f"{discrete.method!r}; expected its own name"
        )
    # the model's own [feedback] closes the open discretization and its boundary systems
    # join it (numeric.discretization.coupled)
    closed = close_and_couple(discrete)
    for matrix in (closed.E, closed.J, closed.R, closed.B, closed.D):
        matrix.setflags(write=False)  # shared by every caller (phdesign.core.cache)
    return closed
