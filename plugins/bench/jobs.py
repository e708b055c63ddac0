"""Where a benchmark's items run: in this process, in local processes (``--jobs N``) or on a Dask cluster
(``--scheduler ADDRESS``).

:func:`run_items` maps a module-level function over items of plain data (paths, names, settings dicts) and returns
the results in the items' order, whatever ran them, so a benchmark's table does not depend on the number of
workers. Each worker builds what it needs (a plugin manager, a profile, an observer) from the item itself.
The Dask path needs the optional extra ``likeme[dask]`` (``dask[distributed]``); see ``docs/scaling.md``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from toolkit import ConfigError
from toolkit.errors import LikemeError

__all__ = ["LOCAL_PREFIX", "in_process", "run_items", "run_with_pm"]

LOCAL_PREFIX = "local:"
"""``--scheduler local:N`` starts a Dask ``LocalCluster`` of N worker processes for the run."""


def in_process(jobs: int = 1, scheduler: str | None = None) -> bool:
    """Whether :func:`run_items` runs the items in this process (``--jobs 1`` and no ``--scheduler``)."""
    return not scheduler and jobs == 1


def run_with_pm(function: Callable[[Any, Any], Any], items: Sequence[Any], pm: Any, jobs: int = 1,
                scheduler: str | None = None) -> list[Any]:
    """``[function(item, pm) for item in items]`` through :func:`run_items`.

    In this process (``jobs`` 1 or a single item, no ``scheduler``) ``function`` gets the caller's plugin manager
    ``pm`` (plugins registered by hand included); a worker process builds its own, once, from the installed plugins
    (:func:`toolkit.manager.create_plugin_manager`).

    Parameters
    ----------
    function
        A module-level function (picklable) of one item and a plugin manager.
    items
        Plain, picklable data; every per-item seed derives from the item.
    pm
        The caller's plugin manager.
    jobs, scheduler
        As :func:`run_items`.

    Returns
    -------
    list
        The results in the order of ``items``.
    """
    items = list(items)
    if jobs < 1:
        raise ConfigError(f"--jobs {jobs}", key=("--jobs",), expected="a number of processes, 1 or more")
    if in_process(jobs, scheduler) or (not scheduler and len(items) <= 1):  # as run_items: here
        return [function(item, pm) for item in items]
    return run_items(_WithPm(function), items, jobs=jobs, scheduler=scheduler)


_WORKER_PM: list[Any] = []
"""The plugin manager of a worker process, built at its first item."""


class _WithPm:
    """``function(item, pm)`` in a worker, ``pm`` the worker's own plugin manager."""

    def __init__(self, function: Callable[[Any, Any], Any]) -> None:
        self.function = function

    def __call__(self, item: Any) -> Any:
        if not _WORKER_PM:
            from toolkit.manager import create_plugin_manager

            _WORKER_PM.append(create_plugin_manager())
        return self.function(item, _WORKER_PM[0])


def run_items(function: Callable[[Any], Any], items: Sequence[Any], jobs: int = 1,
              scheduler: str | None = None) -> list[Any]:
    """``[function(item) for item in items]``, run here, in ``jobs`` processes or on a Dask cluster.

    Parameters
    ----------
    function
        A module-level function (picklable) of one item.
    items
        Plain, picklable data.
    jobs
        Local worker processes (:class:`concurrent.futures.ProcessPoolExecutor`); 1 runs in this process.
    scheduler
        A Dask scheduler address (``tcp://host:8786``) or ``local:N`` for a ``LocalCluster`` of N workers started
        for this call; wins over ``jobs``.

    Returns
    -------
    list
        The results in the order of ``items``.
    """
    items = list(items)
    if scheduler:
        return _raise(_dask(_Call(function), items, scheduler))
    if jobs < 1:
        raise ConfigError(f"--jobs {jobs}", key=("--jobs",), expected="a number of processes, 1 or more")
    if jobs == 1 or len(items) <= 1:
        return [function(item) for item in items]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # spawn: a fresh interpreter per worker (no forked copy of a threaded parent); the function is found by name
    with ProcessPoolExecutor(max_workers=min(jobs, len(items)),
                             mp_context=multiprocessing.get_context("spawn")) as pool:
        return _raise(list(pool.map(_Call(function), items)))


class _Failed:
    """A :class:`~toolkit.errors.LikemeError` a worker met, as its message (not every error class pickles)."""

    def __init__(self, message: str) -> None:
        self.message = message


class _Call:
    """``function(item)`` in a worker, a user's error (bad input, a plugin's failure) returned as :class:`_Failed`."""

    def __init__(self, function: Callable[[Any], Any]) -> None:
        self.function = function

    def __call__(self, item: Any) -> Any:
        try:
            return self.function(item)
        except LikemeError as err:
            return _Failed(str(err))


def _raise(results: list[Any]) -> list[Any]:
    """The results, or the first worker's error raised here as one ``likeme: error:`` line."""
    for result in results:
        if isinstance(result, _Failed):
            raise LikemeError(result.message)
    return results


def _dask(function: Callable[[Any], Any], items: list[Any], scheduler: str) -> list[Any]:
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ConfigError("dask.distributed is not installed", key=("--scheduler",),
                          expected="pip install 'likeme[dask]' (dask[distributed]) to run on a Dask cluster") from None
    if scheduler.startswith(LOCAL_PREFIX):
        text = scheduler[len(LOCAL_PREFIX):]
        if not text.isdigit() or int(text) < 1:
            raise ConfigError(f"--scheduler {scheduler}", key=("--scheduler",),
                              expected="local:N with N workers, 1 or more, or a scheduler address tcp://HOST:PORT")
        with LocalCluster(n_workers=int(text), threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            return _gather(client, function, items)
    try:
        client = Client(scheduler, timeout="20s")
    except (OSError, TimeoutError, ValueError) as err:
        raise ConfigError(f"cannot reach the Dask scheduler {scheduler!r}: {err}", key=("--scheduler",),
                          expected="the address a running `dask scheduler` prints, e.g. tcp://10.0.0.1:8786, "
                          "or local:N") from None
    with client:
        return _gather(client, function, items)


def _gather(client: Any, function: Callable[[Any], Any], items: list[Any]) -> list[Any]:
    # pure=False: two equal items are still two runs (a timing each); gather keeps the order of the futures
    return client.gather(client.map(function, items, pure=False))
