"""The likeme command: plugins, validate, demo, run; one-line errors with exit status 1."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import CHARACTERS, ROOT


def likeme(*args, env=None, cwd=ROOT):
    full_env = {**os.environ, "LIKEME_DISABLE_PLUGIN_AUTOLOAD": "1", **(env or {})}
    return subprocess.run(
        [sys.executable, "-m", "toolkit.cli", *map(str, args)], capture_output=True, text=True, env=full_env, cwd=cwd, timeout=300
    )


def assert_one_line_error(result, *fragments):
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("likeme: error: ")
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "likeme"
    assert script.exists(), "pip install -e . creates the likeme command"
    result = subprocess.run([script, "--version"], capture_output=True, text=True)
    assert result.returncode == 0 and result.stdout.startswith("likeme ")


def test_plugins_lists_every_kind_with_distribution():
    result = likeme("plugins")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    for heading in ("perceptions", "segmenters", "matchers", "motor systems", "action systems", "triggers", "plugins:"):
        assert heading in out
    assert "keyframe" in out and "[likeme 0.1.0: keyframe]" in out
    assert "motion-capture" in out and "imitation" in out and "script" in out


def test_plugins_json_and_params():
    data = json.loads(likeme("plugins", "--json", "--params").stdout)
    motors = {c["name"]: c for c in data["components"]["motor"]}
    assert motors["keyframe"]["distribution"] == "likeme"
    assert {p["name"] for p in motors["keyframe"]["parameters"]} == {"rest", "hubs", "poses", "movements"}
    plugins = {p["name"]: p for p in data["plugins"]}
    assert plugins["script"]["hooks"] == ["likeme_register_action_systems"]


def test_plugins_params_show_a_parameters_own_table_nested():
    """Options that only mean something together are a table of their own: ``--params`` lists its keys under it,
    indented, and ``--json`` nests them in its row."""
    data = json.loads(likeme("plugins", "--json", "--params").stdout)
    mapping = {c["name"]: c for c in data["components"]["correspondence"]}["body-mapping"]
    dwell = {p["name"]: p for p in mapping["parameters"]}["dwell"]
    assert dwell["type"] == "table of speed, window, memory"
    assert [p["name"] for p in dwell["parameters"]] == ["speed", "window", "memory"]
    lines = likeme("plugins", "--params").stdout.splitlines()
    at = lines.index(next(line for line in lines if line.startswith("      dwell: table of speed, window, memory.")))
    assert [line.split(":")[0] for line in lines[at + 1: at + 4]] == ["          speed", "          window",
                                                                     "          memory"]


def test_validate_builtin_characters_and_scenarios():
    files = sorted(CHARACTERS.glob("*.toml")) + sorted((CHARACTERS / "scenarios").glob("*.toml"))
    result = likeme("validate", *files)
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("ok ") == len(files)
    assert "character 'Max'" in result.stdout and "scenario 'Max watches Morris'" in result.stdout
    max_line = next(line for line in result.stdout.splitlines() if "character 'Max'" in line)
    assert max_line.endswith("action hierarchical, layer look-at")  # every component table, the layer included


def test_the_run_report_names_every_component_of_a_character():
    from toolkit.report import _components_line

    described = {"name": "X", "parts": 3, "motor": {"plugin": "posegraph"}, "layer": {"plugin": "look-at"},
                 "correspondence": {"plugin": "body-mapping"}}
    assert _components_line(described) == ("motor posegraph; perception -; correspondence body-mapping; segmenter -; "
                                            "matcher -; action -; layer look-at")


BAD = {
    "unknown_plugin.toml": ('[segmenter]\nplugin = "hub-treshold"\n', ["unknown_plugin.toml:", "key segmenter.plugin", "unknown segmenter 'hub-treshold'", "available:"]),
    "wrong_type.toml": ('[action]\nplugin = "script"\nrandom = "ten"\n', ["wrong_type.toml:", "key action.random", "wrong type str", "expected an integer"]),
    "syntax.toml": ("[action\nplugin = 1\n", ["syntax.toml:4:", "TOML syntax error"]),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_validate_bad_character_fails_with_one_clear_line(write, name):
    text, fragments = BAD[name]
    path = write(name, f'[character]\nname = "Bad"\nextends = "{CHARACTERS / "max.toml"}"\n{text}')
    assert_one_line_error(likeme("validate", path), *fragments)


def test_validate_reports_each_bad_file_and_still_checks_the_good_ones(write):
    bad = write("bad.toml", '[character]\nname = 3\n')
    result = likeme("validate", CHARACTERS / "max.toml", bad)
    assert result.returncode == 1
    assert "ok    " in result.stdout and "key character.name" in result.stderr


def test_demo_reports_what_each_character_did_and_saw():
    result = likeme("demo")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "morris (Morris" in out and "max (Max" in out
    assert "did:" in out and "perceived morris:" in out
    assert "segmented:" in out and "recognised:" in out
    assert "Ice cream" in out and "learns that ice_cream is food" in out
    data = json.loads(likeme("demo", "--json", "--seed", "3", "--scenario", "demo").stdout)
    morris = next(a for a in data["actors"] if a["id"] == "morris")
    assert len(morris["did"]) >= 10
    max_ = next(a for a in data["actors"] if a["id"] == "max")
    assert max_["watching"]["perceived"]["frames"] == data["frames"]


def test_seed_changes_the_random_sequence():
    a = json.loads(likeme("demo", "--json", "--seed", "1", "--scenario", "demo").stdout)
    b = json.loads(likeme("demo", "--json", "--seed", "2", "--scenario", "demo").stdout)
    seq = lambda d: [x["movement"] for x in next(a for a in d["actors"] if a["id"] == "morris")["did"]]  # noqa: E731
    assert seq(a) != seq(b)
    assert seq(a) == seq(json.loads(likeme("demo", "--json", "--seed", "1", "--scenario", "demo").stdout))


def test_run_scenario_file_and_errors(write):
    result = likeme("run", CHARACTERS / "scenarios" / "demo.toml", "--duration", "2")
    assert result.returncode == 0 and "2.00 s" in result.stdout
    assert_one_line_error(likeme("run", "no-such-scenario"), "cannot find 'no-such-scenario'", "available:")
    bad = write("scene.toml", f'[scenario]\nname = "x"\n[[actors]]\ncharacter = "{CHARACTERS / "max.toml"}"\nwatch = "ghost"\n')
    assert_one_line_error(likeme("run", bad), "scene.toml", "key actors[0].watch", "unknown actor 'ghost'")


def test_argument_errors_exit_1_with_one_line():
    assert_one_line_error(likeme("run"), "the following arguments are required: scenario")
    assert_one_line_error(likeme("frobnicate"), "invalid choice: 'frobnicate'")
    assert_one_line_error(likeme("demo", "--seed", "x"), "invalid int value")


def test_show_actions_prints_the_hierarchy():
    result = likeme("show", "--actions", CHARACTERS / "max.toml")
    assert result.returncode == 0, result.stderr
    assert "satisfy_hunger" in result.stdout and "movement-action correspondence map:" in result.stdout
    plain = likeme("show", "--actions", CHARACTERS / "morris.toml")
    assert "ice_cream is food" in plain.stdout


def test_bench_behaviour_runs(tmp_path):
    out = tmp_path / "b.json"
    result = likeme("bench", "behaviour", "--episodes", "3", "--quiet", "--json", out)
    assert result.returncode == 0, result.stderr
    data = json.loads(out.read_text())
    assert set(data["conditions"]) == {"line-of-sight", "no-line-of-sight", "close-together", "random-placement"}
    assert data["conditions"]["line-of-sight"]["path"] >= 2 / 3


# -- arguments and output paths checked where they enter (issue 21) -----------------------------------------


def test_seed_bounds():
    import argparse

    from toolkit.cli import seed_type

    assert seed_type("0") == 0 and seed_type(str(2**63 - 1)) == 2**63 - 1
    for text in ("-1", str(2**63), "x", "1.5"):
        with pytest.raises(argparse.ArgumentTypeError):
            seed_type(text)


@pytest.mark.parametrize("text", ["nan", "inf", "-inf", "-0.5", "3600.5"])
def test_duration_refuses_non_finite_and_out_of_range(text):
    import argparse

    from toolkit.cli import number_type

    parse = number_type(0.0, 3600.0, "seconds")
    assert parse("0") == 0.0 and parse("3600") == 3600.0
    with pytest.raises(argparse.ArgumentTypeError, match=r"expected seconds in \[0, 3600\]"):
        parse(text)


def test_output_file_checks(tmp_path):
    from toolkit import ConfigError
    from toolkit.cli import check_output_file

    assert check_output_file(tmp_path / "new.json", "--json") == tmp_path / "new.json"
    assert not (tmp_path / "new.json").exists() and list(tmp_path.iterdir()) == []  # the probe leaves nothing
    with pytest.raises(ConfigError, match="key --json: is a folder"):
        check_output_file(tmp_path, "--json")
    with pytest.raises(ConfigError, match="key --csv: no such folder"):
        check_output_file(tmp_path / "missing" / "x.csv", "--csv")
    with pytest.raises(ConfigError, match="key --out: not a regular file"):
        check_output_file("/dev/null", "--out")


def test_render_folder_is_created_before_the_run(tmp_path):
    from toolkit.cli import check_output_dir

    folder = tmp_path / "a" / "b"
    assert check_output_dir(folder, "--render") == folder and folder.is_dir() and list(folder.iterdir()) == []


def test_view_settings_without_a_view_are_refused():
    assert_one_line_error(likeme("run", "demo", "--set", "every=2"), "key --set: --set without --render")
    assert_one_line_error(likeme("show", "max", "--set", "keys=4"), "key --set: --set without --view")
    assert_one_line_error(likeme("show", "max", "--out", "x.png"), "key --out: --out without --view")


def test_bad_output_fails_before_any_work(tmp_path):
    """A bench that would run for minutes stops at once on an output it could not write."""
    result = likeme("bench", "watch", "--movements", "200", "--json", tmp_path / "missing" / "w.json")
    assert_one_line_error(result, "key --json: no such folder")
