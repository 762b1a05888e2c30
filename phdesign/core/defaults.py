r"""The one table of defaults: every default of a signature or a command is read here.

A public function whose argument is ``None`` by default uses the value of the table in
force for it (``None`` means "the registered default"), and the command line builds its
options' defaults and choices from the same table, so a change of policy is one edit
and the reason for each number stands next to it.  The table is read-only, as pyMOR's
``core/defaults.py`` without its global setter: :func:`current` returns the table in
force, :func:`using` puts a changed copy in force inside a ``with`` block (for the
current thread or task only, restored on exit), and nothing else changes it.  The module
imports nothing heavy: the command line builds its parser from it without loading the
numeric layer (``phdesign classify`` starts fast), and the design objects check their
``method`` against it.

The table holds

``method`` and ``methods``
    The default discretization and, per registered method, its defaults by model order
    (:class:`MethodDefaults`, one :class:`OrderDefaults` row per order; the last row serves
    every higher order).  The builders are registered under the same names in
    :mod:`phdesign.numeric.discretization.registry`, which checks that the two agree.
``spectrum``, ``simulation``, ``export``
    The rest of the defaults of the spectrum, the simulations and the exported observer.
``progress``
    When the progress line of a long run first shows, and how often it is redrawn.

The discretization rows:

============  ======  ========  =======  ==========  ========  =======  =======  ======
method        order   degree    first    largest     band      basis    abscissa drift
============  ======  ========  =======  ==========  ========  =======  =======  ======
galerkin      N = 1       40       20       100        330     legendre  1e-10   1e-6
galerkin      N = 2       40       20       110        240     legendre  1e-10   1e-6
galerkin      N >= 3      16        8       110        110     scaled    1e-10   1e-6
fd            N = 1, 2    70       70       240        240     --        1e-3    1e-2
============  ======  ========  =======  ==========  ========  =======  =======  ======

Why these numbers:

* ``resolution`` (``degree`` above; :func:`phdesign.numeric.discretization.registry.discretize`
  and so the simulations and exports): 40 resolves the low modes of N <= 2 models to
  ~1e-12; for N >= 3 the weakly imposed feedback on high derivative traces makes
  :math:`E^{-1}A` grow like :math:`p^{4N-3}`, and the exact time stepping keeps its energy
  balance only at a low degree: on airy with every sensor (L = I, t = 1, x1 = sin(πz))
  the error system's balance drifts by 8e-10, 2e-9, 2e-8, 1e-7, 9e-6, 5e-5 of its energy
  at degrees 12, 16, 20, 24, 32, 40, alike in both Galerkin bases, against the warning
  threshold 1e-8 (:mod:`phdesign.numeric.time.simulation`); degree 16 also resolves
  airy's slow modes to 1e-5.  Finite differences take 70 nodes per group, the paper's 140
  states for the beam.
* ``spectrum_start`` and ``spectrum_max``: the spectrum refines p -> ⌈1.5 p⌉ from the first
  resolution up to the largest; N >= 3 starts low because its rightmost modes are
  resolved early.
* ``band_max``: the largest resolution the refinement reaches while its band does not
  reach the onset of the principal part (:mod:`phdesign.numeric.spectrum.branches`): a
  steel Timoshenko beam's thickness-shear branch starts at 2.03e5 rad/s, 78 times its
  rate, and needs the pair (153, 230); a resolution of 330 costs about 5 s for n = 4.
* ``tune_fallback``: the coarse degree of noise-aware tuning's pair when the spectrum at
  L = I did not converge (an unconverged start says nothing about a good pair).
* ``basis``: the Galerkin basis; N >= 3 takes the trace-scaled one, in which the noise
  figures' QZ keeps 15 digits on airy where the plain Legendre basis loses them, and in
  which airy's spectrum with sensor 1 converges (the measurements are in
  :mod:`phdesign.numeric.discretization.legendre`); None for a method without bases.
* ``abscissa_tol`` and ``resolved_rtol``: the agreement of the spectral abscissa that
  counts as converged and the drift under which an eigenvalue counts as resolved, both
  relative to the problem's rate (:mod:`phdesign.numeric.scales`); ``noise_tol`` the
  agreement of a noise figure between two resolutions: spectral accuracy for Galerkin,
  second order for finite differences.

Examples
--------
>>> row = current().discretization("galerkin", 3)
>>> row.resolution, row.basis, (row.spectrum_start, row.spectrum_max)
(16, 'scaled', (8, 110))
>>> current().method_names, current().simulation.samples
(('galerkin', 'fd'), 501)
>>> from dataclasses import replace
>>> quick = replace(DEFAULTS, simulation=replace(DEFAULTS.simulation, samples=11))
>>> with using(quick):
...     current().simulation.samples
11
>>> current().simulation.samples
501
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from phdesign.core.errors import ArgumentError, NumericError

__all__ = [
    "DEFAULTS",
    "Defaults",
    "ExportDefaults",
    "MethodDefaults",
    "OrderDefaults",
    "ProgressDefaults",
    "SimulationDefaults",
    "SpectrumDefaults",
    "current",
    "method_or_default",
    "using",
]


@dataclass(frozen=True)
class OrderDefaults:
    """Defaults of one discretization method for one model order (one row of its table).

    Attributes
    ----------
    resolution : int
        Default resolution of a discretization (and so of simulations and exports):
        Galerkin degree or finite-difference nodes per group.
    spectrum_start, spectrum_max : int
        First and largest resolution of the spectrum's refinement.
    band_max : int
        Largest refinement resolution while the band does not reach the onset of the
        principal part (:mod:`phdesign.numeric.spectrum.branches`); at least
        ``spectrum_max``.
    tune_fallback : int
        Coarse resolution of noise-aware tuning when the spectrum at L = I did not converge.
    basis : str or None
        The basis of a method that has several; None otherwise.
    abscissa_tol : float
        Agreement of the spectral abscissa that counts as converged.
    resolved_rtol : float
        Relative drift under which an eigenvalue counts as resolved between two resolutions.
    noise_tol : float
        Relative agreement of a noise figure that counts as converged.
    """

    resolution: int
    spectrum_start: int
    spectrum_max: int
    band_max: int
    tune_fallback: int
    basis: str | None = None
    abscissa_tol: float = 1e-10
    resolved_rtol: float = 1e-6
    noise_tol: float = 1e-6


@dataclass(frozen=True)
class MethodDefaults:
    """A discretization method's entry: its rows by model order and what it supports.

    Attributes
    ----------
    name : str
        The name a ``method`` argument gives (``"galerkin"``).
    summary : str
        One line for the command line's help.
    rows : mapping of int to OrderDefaults
        One row per model order; orders beyond the last row use the last row.
    bases : tuple of str
        The values a ``basis`` argument may take (empty: the method has no bases).
    """

    name: str
    summary: str
    rows: Mapping[int, OrderDefaults]
    bases: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "rows", MappingProxyType(dict(self.rows)))

    def at(self, order: int) -> OrderDefaults:
        """Return the row for a model of order ``order`` (the last row beyond the table)."""
        return self.rows[min(max(int(order), min(self.rows)), max(self.rows))]

    def describe(self, name: str) -> str:
        """Return the field ``name`` of the rows as text: ``"40 (16 for N >= 3)"``."""
        orders = sorted(self.rows)
        groups: list[tuple[int, object]] = []
        for order in orders:
            value = getattr(self.rows[order], name)
            if not groups or groups[-1][1] != value:
                groups.append((order, value))
        text = _shown(groups[0][1])
        for k, (order, value) in enumerate(groups[1:], start=1):
            last = k == len(groups) - 1
            text += f" ({_shown(value)} for N {'>=' if last else '='} {order})"
        return text

    def with_row(self, order: int, **changes: object) -> MethodDefaults:
        """Return this entry with the row of ``order`` changed (unknown names raise)."""
        row = replace(self.at(order), **changes)  # type: ignore[arg-type]
        return replace(self, rows={**self.rows, order: row})


def _shown(value: object) -> str:
    """Return a default as a command's help shows it: ``1e-10``, ``40``, ``scaled``."""
    if isinstance(value, float) and 0 < abs(value) <= 1e-2:
        return f"{value:.0e}".replace("e-0", "e-")
    return f"{value:g}" if isinstance(value, float) else str(value)


_GALERKIN = MethodDefaults(
    "galerkin",
    "Legendre-Galerkin (spectral, any order)",
    {
        1: OrderDefaults(40, 20, 100, 330, 30, "legendre"),
        2: OrderDefaults(40, 20, 110, 240, 30, "legendre"),
        3: OrderDefaults(16, 8, 110, 110, 30, "scaled"),
    },
    bases=("scaled", "legendre"),
)
_FD_ROW = OrderDefaults(
    70, 70, 240, 240, 70, abscissa_tol=1e-3, resolved_rtol=1e-2, noise_tol=1e-3
)
_FD = MethodDefaults(
    "fd",
    "staggered finite differences (the paper's setting, N = 1 and 2)",
    {1: _FD_ROW, 2: _FD_ROW},
)


def _filled(row: object, **given: object) -> tuple[object, ...]:
    """Return the values ``given``, in their order, with ``row``'s where a value is None."""
    return tuple(getattr(row, name) if value is None else value for name, value in given.items())


@dataclass(frozen=True)
class SpectrumDefaults:
    """Defaults of the spectrum: ``count`` rightmost eigenvalues are reported."""

    count: int = 6


@dataclass(frozen=True)
class SimulationDefaults:
    """Defaults of every simulation (plant, observer, sampled, noisy, loop).

    Attributes
    ----------
    t_end : float
        Final time (s): five seconds hold several periods of the paper's beam's slowest
        modes and its error's decay.
    samples : int
        Output samples on [0, t_end] (a step of 0.01 s for the default t_end).
    scheme : str
        ``"expm"``: the exact exponential of the linear flow (``"midpoint"``: implicit
        midpoint, :mod:`phdesign.numeric.time.stepping`).
    tol : float
        Midpoint: largest estimated error of the states, relative to their largest energy
        norm.
    """

    t_end: float = 5.0
    samples: int = 501
    scheme: str = "expm"
    tol: float = 1e-6

    def fill(
        self,
        t_end: float | None = None,
        samples: int | None = None,
        scheme: str | None = None,
        tol: float | None = None,
    ) -> tuple[float, int, str, float]:
        """Return ``(t_end, samples, scheme, tol)``, these defaults where a value is None.

        The values given pass unchanged: the simulators check them.
        """
        filled = _filled(self, t_end=t_end, samples=samples, scheme=scheme, tol=tol)
        return filled  # type: ignore[return-value]


@dataclass(frozen=True)
class ExportDefaults:
    """Defaults of the exported observer, shared by the library, the design object and the CLI.

    Attributes
    ----------
    sampler : str
        ``"average"``: the mean of the sensors over each period, whose sampled error system
        is dissipative for every period (:mod:`phdesign.numeric.sampled.period_maps`);
        point samples alias a boundary velocity's unresolved content.
    tol : float
        Relative accuracy of the rightmost error eigenvalues the order must reproduce.
    output_tol : float
        Error floor of the performance outputs, relative to their peak.
    t_end : float
        Length (s) of the performance and verification runs: five seconds hold several
        periods of the paper's beam's slowest modes and its error's decay to the floor.
    plant_degree : int
        Galerkin degree of the verification plant: the paper's beam observer of degree 16
        (34 states) then meets a plant of 98 states.
    design : str
        ``"auto"``: the passive and the Kalman design, verified on the initial states, the
        lower worst-case floor wins (:mod:`phdesign.numeric.sampled.gain_design`).
    max_ratio : float
        The largest worst ratio of the sampled to the continuous error floor over the
        verification set that passes (``strict`` fails above it; a Kalman design above it
        is not taken): the aliasing threshold, ten.
    """

    sampler: str = "average"
    tol: float = 1e-6
    output_tol: float = 1e-3
    t_end: float = 5.0
    plant_degree: int = 48
    design: str = "auto"
    max_ratio: float = 10.0

    def fill(
        self,
        sampler: str | None = None,
        tol: float | None = None,
        output_tol: float | None = None,
        t_end: float | None = None,
    ) -> tuple[str, float, float, float]:
        """Return ``(sampler, tol, output_tol, t_end)``, these defaults where a value is None.

        The values given pass unchanged: the exporter checks them.
        """
        filled = _filled(self, sampler=sampler, tol=tol, output_tol=output_tol, t_end=t_end)
        return filled  # type: ignore[return-value]


@dataclass(frozen=True)
class ProgressDefaults:
    """Defaults of the progress line of long runs (:class:`phdesign.core.progress.Display`).

    Attributes
    ----------
    delay : float
        Seconds a run lasts before its progress shows: a command that answers within about
        two seconds prints nothing but its answer.
    interval : float
        Least seconds between two drawings of the line (a terminal redrawn more often
        only flickers).
    """

    delay: float = 2.0
    interval: float = 0.1


@dataclass(frozen=True)
class Defaults:
    """The table of defaults (module docstring); build a changed one with :func:`replace`."""

    method: str = "galerkin"
    methods: Mapping[str, MethodDefaults] = field(
        default_factory=lambda: {_GALERKIN.name: _GALERKIN, _FD.name: _FD}
    )
    spectrum: SpectrumDefaults = SpectrumDefaults()
    simulation: SimulationDefaults = SimulationDefaults()
    export: ExportDefaults = ExportDefaults()
    progress: ProgressDefaults = ProgressDefaults()

    def __post_init__(self) -> None:
        object.__setattr__(self, "methods", MappingProxyType(dict(self.methods)))
        if self.method not in self.methods:
            raise NumericError(
                f"method: the default method must be one of {self.method_names}; found "
                f"{self.method!r}"
            )

    @property
    def method_names(self) -> tuple[str, ...]:
        """The names of the methods, in registration order (the CLI's ``--method`` choices)."""
        return tuple(self.methods)

    def entry(self, method: str) -> MethodDefaults:
        """Return ``method``'s entry, or raise :class:`NumericError` naming the known ones."""
        try:
            return self.methods[method]
        except (KeyError, TypeError):
            raise NumericError(
                f"method must be one of {', '.join(map(repr, self.methods))}; found {method!r}"
            ) from None

    def discretization(self, method: str, order: int) -> OrderDefaults:
        """Return the row of ``method`` for a model of order ``order``."""
        return self.entry(method).at(order)

    def describe(self, name: str) -> str:
        """Return the default ``name`` of every method's rows as text, for a command's help.

        >>> DEFAULTS.describe("resolution")
        'galerkin 40 (16 for N >= 3), fd 70'
        """
        return ", ".join(f"{m.name} {m.describe(name)}" for m in self.methods.values())

    def with_method(self, entry: MethodDefaults) -> Defaults:
        """Return this table with ``entry`` added, or replacing the entry of its name."""
        return replace(self, methods={**self.methods, entry.name: entry})


#: The registered table (:class:`Defaults`).
DEFAULTS = Defaults()
_IN_FORCE: ContextVar[Defaults] = ContextVar("phdesign_defaults", default=DEFAULTS)


def current() -> Defaults:
    """Return the table in force: :data:`DEFAULTS`, or the one of an enclosing :func:`using`."""
    return _IN_FORCE.get()


def method_or_default(method: str | None) -> str:
    """Return ``method``, or the default method of the table in force when it is None."""
    return current().method if method is None else method


@contextmanager
def using(table: Defaults) -> Iterator[Defaults]:
    """Put ``table`` in force inside a ``with`` block (this thread or task only).

    Raises
    ------
    ArgumentError
        ``table`` is not a :class:`Defaults`.
    """
    if not isinstance(table, Defaults):
        raise ArgumentError(f"table must be a Defaults; found {type(table).__name__}")
    token = _IN_FORCE.set(table)
    try:
        yield table
    finally:
        _IN_FORCE.reset(token)
