"""The ``likeme bench`` command and its benchmarks: the toolkit's figures, measured (never by timed tests).

``command`` registers the command and its sub-commands; each other module is one benchmark (``watch``,
``behaviour``, ``facilitation``, ``vision``, ``mocap`` for recognition, segmentation and streams of motion-capture
files, ``memory`` for the observer's memory against stream length, ``startup`` for how long the command takes to
start), ``data`` writes and reads the folders the motion-capture benchmarks run on, and ``metrics`` holds the
scores. ``docs/benchmarks.md`` has every table with the command that printed it.
"""
