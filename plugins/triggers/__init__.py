"""Triggers: the can-I, should-I and object-selection conditions action tuples are built from (B&B §6.1).

Registers ``drive`` (with the drives themselves), ``object-present`` and the proximity triggers.

Besides :meth:`~toolkit.Trigger.evaluate`, a trigger used as a do-until (success) context may define
``imagine(context) -> dict | None``: the objects of a world in which it holds for ``context.actor`` and
``context.object`` (copies: the real world is never changed), or ``None`` when it cannot say. An observer predicts
what another will do next by imagining the success of the behaviour it identified (Buchsbaum & Blumberg 2005, §7.4;
:mod:`plugins.action.prediction`). ``holding`` and ``not-holding`` imagine; the others cannot (a drive is not part of
the world, and where an object would have to be to be within reach is not one place).
"""
