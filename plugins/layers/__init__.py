"""Layers: changes of the pose a character shows on top of every movement it performs.

Registers ``look-at`` (B&B §6.1.2): the head turns toward the object of attention, so that others can read the line
of sight from it.
"""
