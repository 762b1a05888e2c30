"""Numeric backend: discretization, spectrum, simulation, tuning and export.

Data enter through :mod:`phdesign.numeric.bridge` (the one crossing from the symbolic
layer); :mod:`~phdesign.numeric.discretization.registry` turns a
:class:`~phdesign.numeric.bridge.NumericModel`
into a finite-dimensional port-Hamiltonian system; :mod:`~phdesign.numeric.spectrum.converged`,
:mod:`~phdesign.numeric.time.simulation`, :mod:`~phdesign.numeric.tuning.search` and
:mod:`~phdesign.numeric.statespace` work on that.  Submodules are imported on demand.
"""
