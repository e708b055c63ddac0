"""Segmenter ``velocity-direction`` (Kopp & Graeser 2006, §4.1 and §4.3), one concept a module:

- :mod:`.segmenter`: the plugin: the sensory memory finds where a movement begins and ends, the working memory holds
  it, and the stroke analysis (:mod:`plugins.lib.strokes`) cuts it into strokes when it ends;
- :mod:`.speed`: how fast the chosen parts move over the sensory memory, and how fast a tracker's jitter alone would
  make them seem to move;
- :mod:`.rests`: where a movement ends when the demonstrator's rest is their own (``end = "rest"``): near where it
  began or another rest they were seen in, a hold half-way, a new stance and the shift into it.
- :mod:`.departure`: where a movement begins by position (``end = "rest"``): where some part leaves the pose the
  demonstrator rests in, however slowly.
"""

from plugins.segmenters.velocity_direction.segmenter import VelocityDirection, likeme_register_segmenters

__all__ = ["VelocityDirection", "likeme_register_segmenters"]
