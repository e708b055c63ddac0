"""Action systems: what a character does, and what it makes of what it sees.

Registers ``script``, ``imitation`` (B&B §5.3) and ``hierarchical`` (B&B §6); ``action_tuple`` is the hierarchy of
action tuples, ``behaviour_identification`` the simulation of another's behaviour, motivation and goal (§6-7).
"""
