"""Matcher ``path-search``: the observed movement as the nearest path through one's own posegraph.

Buchsbaum & Blumberg 2005, §5.2 (Fig. 5-8). A comparison (:mod:`plugins.matchers.comparison`), a search and a
decision (:mod:`plugins.matchers.decision`), each chosen once when the matcher is attached:

- :mod:`~plugins.matchers.path_search.matcher`: the plugin; samples the segment at the node rate, asks the search
  and the decision, learns what is unknown (§5.2.3, §7.3);
- :mod:`~plugins.matchers.path_search.kbest`: the paper's k best paths from the poses nearest the middle frame;
- :mod:`~plugins.matchers.path_search.per_movement`: every movement's own best path, exactly.

``docs/matchers.md`` says how they work together and which the observer template chooses for real people.
"""

from plugins.matchers.path_search.matcher import PathSearch, PoseGraph, Takes
from toolkit import hookimpl

__all__ = ["PathSearch", "PoseGraph", "Takes"]


@hookimpl
def likeme_register_matchers():
    return [PathSearch]
