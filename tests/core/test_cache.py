"""The one cache of work built once per owner (phdesign.core.cache), and who uses it."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.cache import MODEL_WORK, OwnerCache, array_bytes
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.spectrum.refinement import _STRUCTURES


class Owner:
    """A stand-in for a model: weak-referenceable, compared by identity."""


def test_entries_are_built_once_and_the_least_recently_used_go_first():
    cache = OwnerCache("test", entries=2, nbytes=1 << 20)
    owner, calls = Owner(), []

    def build(key):
        calls.append(key)
        return key

    for key in ("a", "b", "a", "c", "a", "b"):
        assert cache.get(owner, key, lambda key=key: build(key)) == key
    # "a" is used again before "c" arrives, so "b" goes; then "b" is built again
    assert calls == ["a", "b", "c", "b"]
    assert len(cache) == 2
    info = cache.info()
    assert (info.hits, info.misses) == (2, 4)


def test_the_bytes_bound_drops_old_entries_and_never_keeps_a_value_too_large():
    cache = OwnerCache("test", entries=10, nbytes=2000)
    owner = Owner()
    cache.get(owner, 1, lambda: np.zeros(100))  # 800 bytes
    cache.get(owner, 2, lambda: np.zeros(100))
    cache.get(owner, 3, lambda: np.zeros(100))  # 2400 > 2000: entry 1 goes
    assert len(cache) == 2
    assert cache.info().nbytes == 1600
    big = cache.get(owner, 4, lambda: np.zeros(1000))  # alone above the bound: not kept
    assert big.size == 1000
    assert len(cache) == 2


def test_an_owner_that_dies_takes_its_entries_and_its_id_finds_nothing():
    cache = OwnerCache("test", entries=10, nbytes=1 << 20)
    owner = Owner()
    cache.get(owner, "k", lambda: "first owner's")
    del owner
    gc.collect()
    assert len(cache) == 0
    # any new object, whatever id it gets, builds its own work
    assert cache.get(Owner(), "k", lambda: "second owner's") == "second owner's"


def test_array_bytes_counts_each_array_once_through_containers_and_dataclasses():
    a = np.zeros(4)
    d = discretize(to_numeric(phd.load("wave")), "galerkin", 6)
    assert array_bytes((a, [a, {"x": a}])) == 32
    assert array_bytes(d) >= sum(getattr(d, m).nbytes for m in "EJRBD")


def test_a_discretization_is_built_once_per_model_and_resolution_and_is_read_only():
    nm = to_numeric(phd.load("wave"))
    first = discretize(nm, "galerkin", 9)
    assert discretize(nm, "galerkin", 9) is first
    assert discretize(nm, "galerkin", 10) is not first
    assert discretize(to_numeric(phd.load("wave")), "galerkin", 9) is not first  # another model
    with pytest.raises(ValueError, match="read-only"):
        first.J[0, 0] = 1.0


def test_two_spectra_of_one_design_build_its_discretizations_once():
    obs = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    first = obs.spectrum()
    built = MODEL_WORK.info().misses, _STRUCTURES.info().misses
    again = obs.spectrum()
    assert (MODEL_WORK.info().misses, _STRUCTURES.info().misses) == built
    assert again.spectral_abscissa == first.spectral_abscissa
    # another gain reuses the discretizations; only its structure above the band is new
    obs.with_gain([0.2, 2]).spectrum()
    assert MODEL_WORK.info().misses == built[0]
    assert _STRUCTURES.info().misses == built[1] + 1
