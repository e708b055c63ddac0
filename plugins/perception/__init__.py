"""Perceptions: what an observer gets of the target it watches, as root-relative poses (B&B §4.2, §5.1; K&G §4.1).

Registers ``motion-capture``, ``synthetic-vision`` and ``rendered-vision``; ``sensory_buffer`` is the ultra-short
memory the vision perceptions bridge dropouts with.
"""
