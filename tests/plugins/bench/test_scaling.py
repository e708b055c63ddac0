"""``likeme bench scaling`` (plugins/bench/scaling.py): the slope fit, the generated clips and the command's tables.

No timed assertions: the figures themselves are measurements (docs/benchmarks.md).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from plugins.bench.scaling import QUICK, generated_clips, loglog_slope
from toolkit import create_plugin_manager


@pytest.mark.parametrize("exponent", [0.0, 0.5, 1.0, 2.0])
def test_slope_recovers_the_exponent(exponent):
    sizes = np.array([1.0, 10.0, 60.0, 500.0])
    rng = np.random.default_rng(0)
    costs = 0.37 * sizes**exponent * np.exp(rng.normal(0.0, 0.01, len(sizes)))
    assert loglog_slope(sizes, costs) == pytest.approx(exponent, abs=0.03)


def test_slope_of_linear_and_quadratic_cost_exactly():
    sizes = [5, 50, 500]
    assert loglog_slope(sizes, [2 * s for s in sizes]) == pytest.approx(1.0)
    assert loglog_slope(sizes, [s * s for s in sizes]) == pytest.approx(2.0)
    assert loglog_slope(sizes, [7.0, 7.0, 7.0]) == pytest.approx(0.0, abs=1e-12)


def test_slope_needs_two_usable_points():
    assert np.isnan(loglog_slope([1.0], [1.0]))
    assert np.isnan(loglog_slope([1.0, 2.0], [0.0, 3.0]))  # a zero cost has no logarithm
    assert np.isnan(loglog_slope([3.0, 3.0], [1.0, 2.0]))  # one size: no slope


def test_generated_clips_are_renamed_and_perturbed_but_meet_at_their_ends():
    pm = create_plugin_manager()
    motions, labels = generated_clips(pm, 40, seed=3)
    assert len(motions) == len(labels) == 40
    assert len(set(labels)) == 40  # every clip its own movement
    base = [label for label in labels if not re.search(r"-\d+$", label)]
    copies = [label for label in labels if re.search(r"-\d+$", label)]
    assert base and copies and all(re.sub(r"-\d+$", "", c) in base for c in copies)
    # a copy of a movement at the same length as the original: same ends, different middle
    first = {label: m for label, m in zip(labels, motions)}
    pairs = [(first[re.sub(r"-\d+$", "", c)], first[c]) for c in copies]
    same = [(a, b) for a, b in pairs if a.n_frames == b.n_frames]
    assert same
    for a, b in same:
        assert np.allclose(a.positions[[0, -1]], b.positions[[0, -1]], atol=1e-9)
        middle = a.n_frames // 2
        assert np.abs(a.positions[middle] - b.positions[middle]).max() > 1e-3


@pytest.mark.benchmark
def test_quick_run_prints_three_tables_with_slopes(tmp_path, capsys):
    from likeme.cli import main

    out = tmp_path / "scaling.json"
    assert main(["bench", "scaling", "--quick", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    for title in ("stream length", "repertoire size", "graph size"):
        assert title in text
    slopes = re.findall(r"log-log slope of [^:]+: (-?\d+\.\d\d)", text)
    assert len(slopes) == 4  # observe, build, query against movements, query against nodes
    result = json.loads(out.read_text())
    stream = result["stream"]["rows"]
    assert [r["frames"] for r in stream] == [round(m * 60 * 30) for m in QUICK["minutes"]]
    assert all(r["seconds"] > 0 for r in stream)
    rep = result["repertoire"]["rows"]
    assert [r["movements"] for r in rep] == list(QUICK["movements"])
    frames = [r["clip_frames"] for r in rep]
    nodes = [r["nodes"] for r in rep]
    assert frames == sorted(frames) and len(set(frames)) == 3
    assert nodes == sorted(nodes) and len(set(nodes)) == 3
    for key in ("slope",):
        assert np.isfinite(result["stream"][key]) and np.isfinite(result["graph"][key])
    assert np.isfinite(result["repertoire"]["build_slope"]) and np.isfinite(result["repertoire"]["query_slope"])
    assert float(slopes[0]) == pytest.approx(result["stream"]["slope"], abs=0.006)


def test_bad_sizes_are_refused_in_one_line(capsys):
    from likeme.cli import main

    with pytest.raises(SystemExit) as exit_:
        main(["bench", "scaling", "--quick", "--movements", "0"])
    assert exit_.value.code == 1
    assert "--movements" in capsys.readouterr().err


@pytest.mark.benchmark
def test_set_reaches_the_observer(tmp_path, capsys):
    from likeme.cli import main

    assert main(["bench", "scaling", "--quick", "--minutes", "0.05", "--minutes", "0.1", "--movements", "3",
                 "--movements", "6", "--set", "matcher.candidates=1"]) == 0
    assert "--set matcher.candidates=1" in capsys.readouterr().out
    assert main(["bench", "scaling", "--quick", "--set", "matcher.no_such_key=1"]) == 1
    assert "no_such_key" in capsys.readouterr().err
