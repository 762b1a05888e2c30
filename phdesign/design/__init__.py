"""The design objects: :class:`~phdesign.design.observer.plant.Plant`, the observer and the loop.

They are what a notebook user holds; each question they answer calls the numeric or
symbolic layer.
"""
