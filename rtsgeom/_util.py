"""Small shared helpers (no physics)."""

from __future__ import annotations

import numpy as np


def frozen(values, dtype=None) -> np.ndarray:
    """Return a read-only copy of ``values`` so frozen dataclasses stay immutable all the way down."""
    a = np.array(values, dtype=dtype, copy=True)
    a.flags.writeable = False
    return a
