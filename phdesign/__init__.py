"""phdesign: boundary observers for 1D boundary-controlled port-Hamiltonian systems.

A flat namespace for notebooks and scripts::

    import phdesign as phd
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    obs.classify()
    obs.noise()                          # what the gain costs in sensor noise
    obs.export(dt=1e-3)                  # the sampled observer for a controller
    phd.Loop(obs, actuate=3).spectrum()  # observer-based control u3 = -K y3_hat

Every name is imported on first use (PEP 562), so ``import phdesign`` stays light: the
command line and ``phdesign.plots`` start without sympy, numpy or matplotlib until a name
that needs them is touched.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: Public name -> module that defines it.
_EXPORTS: dict[str, str] = {
    # models
    "BCPHS": "phdesign.symbolic.model",
    "Displacement": "phdesign.symbolic.definition",
    "CoupledInitialState": "phdesign.numeric.boundary_start",
    "BoundarySystem": "phdesign.symbolic.boundary_systems",
    "load": "phdesign.models",
    "load_builtin": "phdesign.models",
    "builtin_names": "phdesign.models",
    "read_model": "phdesign.io",
    "write_model": "phdesign.io",
    "model_from_toml": "phdesign.io",
    "model_to_toml": "phdesign.io",
    # ports and the observer's exact layer
    "Ports": "phdesign.symbolic.ports",
    "derive_ports": "phdesign.symbolic.ports",
    "port_inverse": "phdesign.symbolic.observer",
    "sensor_matrix": "phdesign.symbolic.observer",
    "measurement_matrix": "phdesign.symbolic.observer",
    "gain_matrix": "phdesign.symbolic.observer",
    "classify": "phdesign.symbolic.classify",
    "Classification": "phdesign.symbolic.classify",
    "CoupledClassification": "phdesign.symbolic.coupled_classify",
    "search_sensors": "phdesign.symbolic.search",
    "SensorSearch": "phdesign.symbolic.search_result",
    # the design objects
    "Observer": "phdesign.design.observer",
    "Plant": "phdesign.design.plant",
    "Loop": "phdesign.design.loop",
    # numbers
    "to_numeric": "phdesign.numeric.bridge",
    "discretize": "phdesign.numeric.discretization.registry",
    "spectrum": "phdesign.numeric.spectrum.converged",
    "SpectrumReport": "phdesign.numeric.spectrum.report",
    "simulate": "phdesign.numeric.time.simulation",
    "SimulationOptions": "phdesign.numeric.time.options",
    "SimulationResult": "phdesign.numeric.time.result",
    "tune": "phdesign.numeric.tuning.search",
    "TuneResult": "phdesign.numeric.tuning.search",
    "NoiseReport": "phdesign.numeric.noise.report",
    "GainReport": "phdesign.numeric.noise.disturbance_report",
    "Tradeoff": "phdesign.numeric.noise.tradeoff",
    "SampledObserver": "phdesign.numeric.sampled.export",
    "Certificate": "phdesign.numeric.certified.certificate",
    # errors
    "PhdesignError": "phdesign.core.errors",
}

__all__ = [
    "BCPHS",
    "BoundarySystem",
    "Certificate",
    "Classification",
    "CoupledClassification",
    "CoupledInitialState",
    "Displacement",
    "GainReport",
    "Loop",
    "NoiseReport",
    "Observer",
    "PhdesignError",
    "Plant",
    "Ports",
    "SampledObserver",
    "SensorSearch",
    "SimulationOptions",
    "SimulationResult",
    "SpectrumReport",
    "Tradeoff",
    "TuneResult",
    "__version__",
    "builtin_names",
    "classify",
    "derive_ports",
    "discretize",
    "gain_matrix",
    "load",
    "load_builtin",
    "measurement_matrix",
    "model_from_toml",
    "model_to_toml",
    "port_inverse",
    "read_model",
    "search_sensors",
    "sensor_matrix",
    "simulate",
    "spectrum",
    "to_numeric",
    "tune",
    "write_model",
]

if TYPE_CHECKING:  # pragma: no cover - static imports for type checkers and IDEs
    from phdesign.core.errors import PhdesignError
    from phdesign.design.loop import Loop
    from phdesign.design.observer import Observer
    from phdesign.design.plant import Plant
    from phdesign.io import model_from_toml, model_to_toml, read_model, write_model
    from phdesign.models import builtin_names, load, load_builtin
    from phdesign.numeric.boundary_start import CoupledInitialState
    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.certified.certificate import Certificate
    from phdesign.numeric.discretization.registry import discretize
    from phdesign.numeric.noise.disturbance_report import GainReport
    from phdesign.numeric.noise.report import NoiseReport
    from phdesign.numeric.noise.tradeoff import Tradeoff
    from phdesign.numeric.sampled.export import SampledObserver
    from phdesign.numeric.spectrum.converged import spectrum
    from phdesign.numeric.spectrum.report import SpectrumReport
    from phdesign.numeric.time.options import SimulationOptions
    from phdesign.numeric.time.result import SimulationResult
    from phdesign.numeric.time.simulation import simulate
    from phdesign.numeric.tuning.search import TuneResult, tune
    from phdesign.symbolic.boundary_systems import BoundarySystem
    from phdesign.symbolic.classify import Classification, classify
    from phdesign.symbolic.coupled_classify import CoupledClassification
    from phdesign.symbolic.definition import Displacement
    from phdesign.symbolic.model import BCPHS
    from phdesign.symbolic.observer import (
        gain_matrix,
        measurement_matrix,
        port_inverse,
        sensor_matrix,
    )
    from phdesign.symbolic.ports import Ports, derive_ports
    from phdesign.symbolic.search import search_sensors
    from phdesign.symbolic.search_result import SensorSearch


#: Subpackages and modules reachable as attributes (``phd.plots``), imported on first use.
_SUBMODULES = (
    "cli",
    "design",
    "errors",
    "io",
    "loop",
    "models",
    "numeric",
    "plant",
    "plots",
    "sweep",
    "symbolic",
)


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"phdesign.{name}")
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'phdesign' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    """Return the package's own names: its exports, its subpackages and its dunders.

    Not the names this file uses to build them (``annotations``, ``importlib``, ``Any``,
    ``TYPE_CHECKING``), which a user's tab completion would offer as phdesign's.
    """
    dunders = {name for name in globals() if name.startswith("__") and name.endswith("__")}
    return sorted({*__all__, *_EXPORTS, *_SUBMODULES, *dunders})
