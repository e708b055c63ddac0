"""The built-in likeme plugins, one concept per module, in one room per kind of component.

==============  ==========================================================================
room            holds
==============  ==========================================================================
``perception``  perceptions: what an observer gets of the target it watches
``segmenters``  segmenters: where a movement begins and ends
``matchers``    matchers: which of one's own movements a segment is
``motor``       motor systems: one's own movements, performed and learned
``action``      action systems: what a character does and what it makes of what it sees
``triggers``    the conditions action tuples are built from
``views``       pictures of representations and runs
``bench``       the ``likeme bench`` command and its benchmarks
``lib``         the papers' mathematics shared by several rooms (registers nothing)
==============  ==========================================================================

Each module that registers components is an entry of the ``likeme`` entry-point group declared in the project's
``pyproject.toml``, exactly as a third-party plugin's is; the other modules of a room are its own helpers.
"""
