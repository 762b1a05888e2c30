"""Numeric backend: discretization, spectrum, simulation, tuning and export.

Data enter through :mod:`phdesign.numeric.bridge` (the one crossing from the symbolic
layer); :mod:`~phdesign.numeric.discretize` turns a :class:`~phdesign.numeric.bridge.NumericModel`
into a finite-dimensional port-Hamiltonian system; :mod:`~phdesign.numeric.spectrum`,
:mod:`~phdesign.numeric.simulate`, :mod:`~phdesign.numeric.tune` and
:mod:`~phdesign.numeric.export` work on that.  Submodules are imported on demand.
"""
