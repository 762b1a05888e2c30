"""What the sweep tests share: the small beam sweep and a bitwise comparison of results."""

from __future__ import annotations

import numpy as np

#: The beam at two damping values times a 3 x 2 gain grid from the pair (12, 18), refined
#: up to (18, 27) (where the spectrum's rule needs four resolved modes above the rightmost
#: one): 12 points in 6 chunks of 2, so that two workers both take chunks.
BEAM_MAP = {
    "sensors": [3, 4],
    "grid": {"l1": "0.05:0.5:3:log", "l2": "0.5,2"},
    "param_grid": {"d": "0.1,0.3"},
    "options": {"resolution": 12, "max_resolution": 27},
    "chunk_size": 2,
    "progress": False,
}


def same_figures(a, b) -> None:
    """Bitwise equality of every figure (NaN equal to NaN) and of the coordinates."""
    assert list(a.data_vars) == list(b.data_vars)
    for name in a.data_vars:
        x, y = a[name].values, b[name].values
        assert x.dtype == y.dtype, name
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), name
    for name in a.coords:
        assert np.array_equal(a[name].values, b[name].values), name
