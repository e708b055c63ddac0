"""Matcher ``forward-model``: predicting the ongoing demonstration from the active node's edges (Kopp & Graeser 2006,
§4.2-4.4, Fig. 3). ``docs/forward-model.md`` says how it works.

- :mod:`~plugins.matchers.forward_model.matcher`: the plugin: parameters, the watching loop's calls, the answer;
- :mod:`~plugins.matchers.forward_model.command_graphs`: what it needs of the motor system (motor command graphs, §4.2);
- :mod:`~plugins.matchers.forward_model.tracks`: the subsystems followed, their candidates and the drop-out (§4.1);
- :mod:`~plugins.matchers.forward_model.prediction`: the forward models' predictions and errors (§4.4);
- :mod:`~plugins.matchers.forward_model.speed`: the clock, re-parameterised by path length or not, and the speed (§4.4);
- :mod:`~plugins.matchers.forward_model.commitment`: commitment, deviation, the last correct node (Fig. 3);
- :mod:`~plugins.matchers.forward_model.learning`: true imitation by the inverse model (§4.3);
- :mod:`~plugins.matchers.forward_model.ranking`: the candidates ranked (``Match.candidates``);
- :mod:`~plugins.matchers.forward_model.anchors`: a command joined late, where its strokes were first seen;
- :mod:`~plugins.matchers.forward_model.tables`: the commands' strokes on a fine grid;
- :mod:`~plugins.matchers.forward_model.observation` and :mod:`~plugins.matchers.forward_model.path_length`: the
  segment in the motor frame, and the path length each part has covered.
"""

from plugins.matchers.forward_model.command_graphs import CommandGraphs
from plugins.matchers.forward_model.matcher import ForwardModel
from plugins.matchers.forward_model.tracks import Track
from toolkit import hookimpl

__all__ = ["CommandGraphs", "ForwardModel", "Track"]


@hookimpl
def likeme_register_matchers():
    return [ForwardModel]
