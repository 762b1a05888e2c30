"""The design objects: :class:`~phdesign.design.plant.Plant`, the observer and the loop.

They are what a notebook user holds; each question they answer calls the numeric or
symbolic layer.  A :class:`~phdesign.design.plant.Plant` (the model, its parameter
overrides, its discretization and the numeric model it caches) is what the
:class:`~phdesign.design.observer.Observer` and the :class:`~phdesign.design.loop.Loop`
build on; the command line asks these objects every question it prints the answer of.
"""
