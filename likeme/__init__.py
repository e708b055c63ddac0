"""likeme's top floor: what a user runs, on top of the core (:mod:`toolkit`) and the plugins (:mod:`plugins`).

- :mod:`likeme.cli`: the ``likeme`` command, one module per command (run, plugins, show, observe, validate,
  profile; plugins add more, ``likeme bench`` among them);
- :mod:`likeme.estimators`: scikit-learn style estimators over the plugins, for a notebook (``docs/python-api.md``);
- :mod:`likeme.profiles`: body profiles proposed for a recording and checked against it (``likeme profile``,
  ``likeme validate --body``).

The floors import downward only: :mod:`toolkit` imports neither :mod:`plugins` nor this package, the plugins import
the core, and this package may import both (``tests/test_floors.py``). The Python API of the core (compose
characters, run scenarios, watch recordings) is :mod:`toolkit` itself.
"""

from toolkit import __version__

__all__ = ["__version__"]
