"""Triggers: the can-I, should-I and object-selection conditions action tuples are built from (B&B §6.1).

Registers ``drive`` (with the drives themselves), ``object-present`` and the proximity triggers.
"""
