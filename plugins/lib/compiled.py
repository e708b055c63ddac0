"""Compiled loops: numba where it is installed, the caller's numpy path where it is not.

Not in the papers: a speed concern (issue 22). A few inner loops (dtw's warp against every template, the direction
clustering's rounds, the forward model's anchors and stroke points) are written as plain Python, which is their
reference, and compiled here. No ``fastmath``: no reordered sums and no fused multiply-adds, so the compiled loop
gives the bits the reference gives. Every caller keeps a numpy path for when :func:`compiled` returns ``None``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

__all__ = ["compiled", "compiled_now", "kernel", "one_thread"]


def compiled(*functions: Callable[..., Any], reordered: bool = False) -> tuple[Callable[..., Any], ...] | None:
    """Each of ``functions`` compiled by numba (``nogil``, no bounds checks), cached on disk where numba finds a
    writable place for its cache and compiled in each process where it does not (a read-only installation); ``None``
    without numba. Compilation happens at each function's first call, for the types it is called with: callers call
    them once when their component is attached, not in the first demonstration.

    ``reordered``: sums may be reordered (numba's ``fastmath``: side by side in vector registers), for a loop whose
    numbers need only be the same from call to call, not the reference's to the last bit (a distance summed over
    many coordinates)."""
    try:
        import numba
    except ImportError:
        return None
    options = {"nogil": True, "boundscheck": False, **({"fastmath": True} if reordered else {})}
    try:
        return tuple(numba.njit(cache=True, **options)(f) for f in functions)
    except RuntimeError:  # no writable place for numba's cache
        return tuple(numba.njit(**options)(f) for f in functions)


def compiled_now(function: Callable[..., Any], *example: Any) -> Callable[..., Any] | None:
    """``function`` compiled by numba (:func:`compiled`) and called once with ``example`` arguments, so that it is
    compiled (or loaded from numba's cache) for their types now rather than at its first real call; ``None`` without
    numba."""
    kernels = compiled(function)
    if kernels is None:
        return None
    (kernel,) = kernels
    kernel(*example)
    return kernel



@cache
def kernel(function: Callable[..., Any], reordered: bool = False) -> Callable[..., Any]:
    """``function`` compiled by numba (:func:`compiled`) the first time it is asked for, the same compiled function
    every time after; ``function`` itself without numba (a loop whose plain Python is its own fallback)."""
    found = compiled(function, reordered=reordered)
    return found[0] if found is not None else function

_CONTROLLER = None


def one_thread():
    """A context in which numpy's BLAS runs on one thread (threadpoolctl), for the small matrix products of a
    matcher's comparison: many short products on several threads spend more time waking the threads than
    multiplying, and on a busy or pinned core (``taskset``) far more (30 ms against 1 ms for a 16 x 138 by 138 x
    1665 product, measured on the development machine under load)."""
    global _CONTROLLER
    from threadpoolctl import ThreadpoolController

    if _CONTROLLER is None:
        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="blas")
