"""Compiled loops: numba where it is installed, the caller's numpy path where it is not.

Not in the papers: a speed concern (issue 22). A few inner loops (dtw's warp against every template, the direction
clustering's rounds, the forward model's anchors and stroke points) are written as plain Python, which is their
reference, and compiled here. No ``fastmath``: no reordered sums and no fused multiply-adds, so the compiled loop
gives the bits the reference gives. Every caller keeps a numpy path for when :func:`compiled` returns ``None``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["compiled"]


def compiled(*functions: Callable[..., Any]) -> tuple[Callable[..., Any], ...] | None:
    """Each of ``functions`` compiled by numba (``nogil``, no bounds checks), cached on disk where numba finds a
    writable place for its cache and compiled in each process where it does not (a read-only installation); ``None``
    without numba. Compilation happens at each function's first call, for the types it is called with: callers call
    them once when their component is attached, not in the first demonstration."""
    try:
        import numba
    except ImportError:
        return None
    try:
        return tuple(numba.njit(cache=True, nogil=True, boundscheck=False)(f) for f in functions)
    except RuntimeError:  # no writable place for numba's cache
        return tuple(numba.njit(nogil=True, boundscheck=False)(f) for f in functions)
