"""The k-best search's reach table (plugins.matchers.path_search.kbest._fan) next to a hub of thousands of
movements: never built whole for the nodes whose reach passes the hub (test_kbest.py checks the table's rows
against a plain breadth-first search on random graphs)."""

from __future__ import annotations

import networkx as nx

from plugins.matchers.path_search.kbest import WIDE, _fan


def listed(fan, i: int) -> set[int]:
    """Node ``i``'s reach as the table lists it."""
    indptr, ids = fan.full
    if not fan.long[i]:
        return set(ids[indptr[i] : indptr[i + 1]].tolist())
    lp, lids = fan.local
    out = set(lids[lp[i] : lp[i + 1]].tolist())
    wp, wide, dist = fan.wide
    rp, rids = fan.rings
    span = fan.max_skip + 1
    for w, d in zip(wide[wp[i] : wp[i + 1]], dist[wp[i] : wp[i + 1]]):
        for r in range(fan.max_skip - d + 1):
            row = w * span + r
            out |= set(rids[rp[row] : rp[row + 1]].tolist())
    return out


def hub_graph(movements: int, length: int) -> nx.DiGraph:
    """A posegraph's shape: movements of ``length`` nodes from a hub and back to it."""
    g = nx.DiGraph()
    for m in range(movements):
        chain = ["hub", *(f"m{m}_{k}" for k in range(length)), "hub"]
        nx.add_path(g, chain)
    return g


def test_a_hub_of_thousands_of_movements_gives_a_table_the_size_of_the_graph():
    """3,000 movements of 6 nodes through one hub: each node next to the hub reaches thousands, but the table
    holds a few entries a node, and what it lists for each node is its reach."""
    g = hub_graph(3000, 6)
    nodes = list(g.nodes)
    index = {n: i for i, n in enumerate(nodes)}
    fan = _fan(g, nodes, index, 3, forward=True)
    assert WIDE < 3000 and fan.long.sum() >= 3000
    assert len(fan.full[1]) + len(fan.local[1]) + len(fan.rings[1]) <= 16 * len(nodes)
    for name in ("hub", "m0_0", "m0_5", "m1234_3", "m2999_4"):
        want = {index[m] for m in nx.single_source_shortest_path_length(g, name, cutoff=3)}
        assert listed(fan, index[name]) == want
