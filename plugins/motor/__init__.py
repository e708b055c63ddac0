"""Motor systems: a character's own movements, how it performs them and how it learns new ones.

Registers ``keyframe``, ``posegraph`` (B&B §4.1) and ``motor-command-graph`` (K&G §4.2); ``key_poses`` holds the
timed key poses the first two are declared with.
"""
