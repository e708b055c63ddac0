"""Observer templates chosen per run (``--observer``) and extending one another (``[observer] extends``).

The observer template (``characters/observers/recordings.toml``) is what ``likeme observe`` and ``likeme bench``
compose when told nothing; ``--observer NAME|FILE`` names another, such as the shipped ``papers`` (the papers'
own comparisons and decisions; docs/matchers.md). Everything runs on data the project generates itself.
"""

from __future__ import annotations

import json

import pytest

from plugins.bench.sweep import cells, load_grid
from tests.toolkit.test_observe import data, profile  # noqa: F401  (the generated data, made once for this module)
from toolkit import ConfigError
from toolkit.config.search import resolve_file
from toolkit.config.toml import read_toml
from likeme.cli import main
from toolkit.config.observer_templates import (check_observer_template, observer_template_path, observer_templates,
                                               read_observer_template)
from toolkit.observe import compose_observer


def test_a_template_extending_another_gets_its_tables_and_changes_only_what_it_writes(data, profile, pm, write):
    parent = write("parent.toml", """
        [observer]
        name = "parent"
        description = "the parent"
        [motor]
        plugin = "posegraph"
        [perception]
        plugin = "motion-capture"
        [segmenter]
        plugin = "hub-threshold"
        min_duration = 0.3
        [matcher]
        plugin = "path-search"
        [matcher.beam]
        k = 3
        [matcher.distance]
        max_distance = 0.05
        """)
    child = write("child.toml", """
        [observer]
        extends = "parent.toml"
        name = "child"
        [matcher.beam]
        k = 5
        """)
    table, files = read_observer_template(child, pm)
    assert files == (child.resolve(), parent.resolve())
    assert table["observer"] == {"name": "child", "description": "the parent"}  # extends is not passed on
    assert table["matcher"] == {"plugin": "path-search", "beam": {"k": 5}, "distance": {"max_distance": 0.05}}
    observer = compose_observer(pm, profile, data / "repertoire", template=child)
    assert observer.name == "child"
    assert observer.matcher.params["beam"]["k"] == 5 and observer.matcher.params["distance"]["max_distance"] == 0.05
    assert observer.segmenter.declared["min_duration"] == 0.3
    other = write("other.toml", """
        [observer]
        extends = "parent.toml"
        name = "other"
        [matcher]
        plugin = "dtw"
        """)
    dtw = compose_observer(pm, profile, data / "repertoire", template=other)
    assert dtw.matcher.name == "dtw" and "beam" not in dtw.matcher.declared  # another plugin: a table of its own


def test_a_mistake_is_named_in_the_file_that_makes_it(pm, write):
    write("parent.toml", '[observer]\nname = "p"\n[matcher]\nplugin = "path-search"\n[matcher.beam]\nk = 0\n')
    child = write("child.toml", '[observer]\nextends = "parent.toml"\nname = "c"\n[segmenter]\nplugin = "hub-threshold"\n')
    with pytest.raises(ConfigError, match=r"parent\.toml:6: key matcher\.beam\.k: value 0 out of range"):
        check_observer_template(child, pm)
    mine = write("mine.toml", '[observer]\nextends = "parent.toml"\nname = "c"\n[matcher]\ncandidates = 2\nbeam = 0\n')
    with pytest.raises(ConfigError, match=r"mine\.toml:6: key matcher\.beam"):
        check_observer_template(mine, pm)
    write("a.toml", '[observer]\nname = "a"\nextends = "b.toml"\n')
    loop = write("b.toml", '[observer]\nname = "b"\nextends = "a.toml"\n')
    with pytest.raises(ConfigError, match=r"extends cycle: b\.toml -> a\.toml -> b\.toml"):
        read_observer_template(loop, pm)


def test_a_template_is_found_by_its_name_its_path_or_its_file(pm, write):
    shipped = resolve_file("observers/recordings.toml", None, pm)
    assert observer_template_path("recordings", pm) == shipped
    assert observer_template_path("observers/recordings", pm) == shipped
    assert observer_template_path(shipped, pm) == shipped
    mine = write("mine.toml", '[observer]\nname = "mine"\n')
    assert observer_template_path(mine, pm) == mine.resolve()
    assert {"papers", "recordings"} <= set(observer_templates(pm))
    with pytest.raises(ConfigError, match=r"key --observer: cannot find observer template 'recording'.*"
                                          r"available: papers, recordings"):
        observer_template_path("recording", pm)


def test_papers_is_the_template_with_the_papers_comparisons_and_decisions(data, profile, pm):
    """The shipped template of the papers' own matchers: the observer template's segmenter and perception kept,
    each matcher's comparison, search and decision the papers' (the plugins' own defaults)."""
    from toolkit.params import validate_params

    template = read_toml(resolve_file("observers/recordings.toml", None, pm))
    observer = compose_observer(pm, profile, data / "repertoire", template="papers")
    matcher = observer.matcher
    assert matcher.name == "path-search" and observer.segmenter.name == "hub-threshold"
    defaults = validate_params("path-search", type(matcher).parameters, {})
    assert {k: matcher.params[k] for k in ("comparison", "search", "decision")} == \
        {k: defaults[k] for k in ("comparison", "search", "decision")} == \
        {"comparison": "poses", "search": "k-best", "decision": "distance"}
    assert observer.segmenter.declared["units"] == template["segmenter"]["units"]
    real = compose_observer(pm, profile, data / "repertoire")
    assert {k: real.matcher.params[k] for k in ("comparison", "search", "decision")} == \
        {"comparison": "motion+strokes", "search": "per-movement", "decision": "calibrated"}


def test_observe_and_bench_watch_with_the_template_named(data, write, capsys):
    """``--observer FILE`` is the observer composed: a template that rejects everything answers "unknown" to every
    demo the default template recognises, in ``likeme observe`` and in ``likeme bench recognition``."""
    strict = write("strict.toml", """
        [observer]
        extends = "observers/recordings"
        name = "strict"
        [matcher]
        comparison = "poses"
        decision = "distance"
        [matcher.distance]
        max_distance = 1e-9
        """)
    demos = sorted((data / "demos").rglob("*.bvh"))[:4]
    answers = {}
    for name, options in (("default", []), ("strict", ["--observer", str(strict)])):
        assert main(["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
                     "--json", *options, *map(str, demos)]) == 0
        answers[name] = [s["movement"] for f in json.loads(capsys.readouterr().out) for s in f["segments"]]
    assert answers["strict"] and set(answers["strict"]) == {"unknown"}
    assert any(m != "unknown" for m in answers["default"])
    out = data.parent / "strict.json"
    assert main(["bench", "recognition", "--body", str(data / "profile.toml"), "--repertoire",
                 str(data / "repertoire"), "--demos", str(data / "demos"), "--matcher", "path-search", "--quiet",
                 "--observer", str(strict), "--json", str(out)]) == 0
    row = json.loads(out.read_text())["plugins"][0]
    assert row["plugin"] == "path-search" and row["accuracy"] == 0.0
    assert main(["observe", "--body", str(data / "profile.toml"), "--repertoire", str(data / "repertoire"),
                 "--observer", "nobody", str(demos[0])]) == 1
    assert "key --observer: cannot find observer template 'nobody'" in capsys.readouterr().err


def test_a_sweep_grid_names_its_observer_relative_to_itself(data, write):
    write("strict.toml", '[observer]\nextends = "observers/recordings"\nname = "strict"\n')
    grid = write("grid.toml", f"""
        benchmark = "recognition"
        observer = "strict.toml"
        [data.gen]
        body = "{data / 'profile.toml'}"
        repertoire = "{data / 'repertoire'}"
        demos = "{data / 'demos'}"
        [plugins]
        matchers = ["dtw"]
        """)
    loaded = load_grid(grid)
    assert loaded["observer"] == str(grid.parent / "strict.toml")
    assert all(c["observer"]["template"] == loaded["observer"] for c in cells(loaded))
    named = write("named.toml", 'benchmark = "recognition"\nobserver = "papers"\n'
                  f'[data.gen]\nbody = "{data / "profile.toml"}"\nrepertoire = "{data / "repertoire"}"\n'
                  f'demos = "{data / "demos"}"\n')
    assert load_grid(named)["observer"] == "papers"
