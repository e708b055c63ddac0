"""The documentation stays true: every hook documented with its signature and exercised by a test."""

from __future__ import annotations

import inspect
import re

import pytest

from tests.conftest import CALLED_HOOKS, ROOT
from toolkit import hookspecs

HOOKS = {name: func for name, func in vars(hookspecs).items() if name.startswith("likeme_") and callable(func)}
PLUGIN_DOC = (ROOT / "docs" / "writing-a-plugin.md").read_text()


def _signature(func):
    return f"{func.__name__}({', '.join(inspect.signature(func).parameters)})"


@pytest.mark.parametrize("name", sorted(HOOKS))
def test_every_hook_is_documented_with_its_signature(name):
    func = HOOKS[name]
    assert func.__doc__ and func.__doc__.strip(), f"{name} has no docstring"
    assert f"`{_signature(func)}`" in PLUGIN_DOC, f"docs/writing-a-plugin.md lacks `{_signature(func)}`"


@pytest.mark.parametrize("name", sorted(HOOKS))
def test_every_hook_is_called_by_a_test(name, request):
    """Some test made the toolkit call the hook with an implementation registered (recorded by a hook-call monitor on
    every plugin manager, tests/conftest.py); this test runs after all the others."""
    if not request.config.whole_suite:
        pytest.skip("run the whole suite: whether a hook is called depends on the other tests")
    assert name in CALLED_HOOKS, f"no test made the toolkit call {name} with an implementation registered"


def test_docs_exist_and_are_linked_from_the_readme():
    readme = (ROOT / "README.md").read_text()
    for doc in ("architecture.md", "character-format.md", "writing-a-plugin.md"):
        assert (ROOT / "docs" / doc).is_file()
        assert f"docs/{doc}" in readme


def test_readme_commands_are_what_ci_runs():
    readme = (ROOT / "README.md").read_text()
    ci = (ROOT / ".ci" / "run").read_text()
    blocks = re.findall(r"```(?:sh|bash|console)?\n(.*?)```", readme, re.S)
    test_command = next(b.strip() for b in blocks if "pytest" in b)
    assert test_command in ci
    assert any("likeme demo" in b for b in blocks)


def test_component_reference_is_current(pm):
    from toolkit.cli import components_markdown

    assert (ROOT / "docs" / "components.md").read_text() == components_markdown(pm), (
        "regenerate with: LIKEME_DISABLE_PLUGIN_AUTOLOAD=1 likeme plugins --markdown > docs/components.md"
    )


def test_the_layout_tables_match_the_rooms_of_plugins():
    """README's layout table and docs/architecture.md's picture of the rooms name every sub-package of plugins/, and
    the picture every module that registers nothing (a room's helpers, lib/)."""
    readme = (ROOT / "README.md").read_text()
    architecture = (ROOT / "docs" / "architecture.md").read_text()
    rooms = sorted(p.parent.name for p in (ROOT / "plugins").glob("*/__init__.py"))
    assert rooms == ["action", "bench", "correspondence", "layers", "lib", "matchers", "motor", "perception",
                     "segmenters", "triggers", "views"]
    picture = architecture[architecture.index("## The rooms"):architecture.index("## From files")]
    for room in rooms:
        assert f"`plugins/{room}/`" in readme, room
        assert re.search(rf"^\s+{room}/\s", picture, re.M), room
        for module in (ROOT / "plugins" / room).glob("*.py"):
            if module.name != "__init__.py" and "@hookimpl" not in module.read_text():
                assert module.stem in picture, f"plugins/{room}/{module.name} is not in the picture of the rooms"


def test_every_file_the_docs_name_exists():
    for doc in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]:
        for path in re.findall(r"`((?:toolkit|plugins|characters|tests)/[\w/.-]+\.(?:py|toml))`", doc.read_text()):
            assert (ROOT / path).is_file(), f"{doc.name} names {path}, which does not exist"


def _examples_table():
    """The rows of docs/examples.md's table of the papers' worked examples, each a list of its cells."""
    text = (ROOT / "docs" / "examples.md").read_text()
    lines = [line for line in text.splitlines() if line.startswith("|")]
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert header[:6] == ["paper", "section / figure", "what happens", "scenario", "command", "tests"], header
    return [[c.strip() for c in line.strip("|").split("|")] for line in lines[2:]]


def test_examples_table_names_real_scenarios_and_tests_and_every_scenario():
    """docs/examples.md: every scenario and `likeme run` command names a file in characters/scenarios/, every test
    named exists (the file and a test function of that name, parametrised or not), every row names a test, and every
    scenario file has a row (a new scenario needs its example row)."""
    import ast

    scenarios = {p.stem for p in (ROOT / "characters" / "scenarios").glob("*.toml")}
    named, functions = set(), {}
    rows = _examples_table()
    assert len(rows) >= 20
    for row in rows:
        where = f"docs/examples.md row {row[1]!r}"
        found = re.findall(r"characters/scenarios/([\w-]+)\.toml", row[3])
        for name in found + re.findall(r"likeme run ([\w-]+)", row[4]):
            assert name in scenarios, f"{where}: no characters/scenarios/{name}.toml"
            named.add(name)
        tests = re.findall(r"`tests/((?:\w+/)*test_\w+\.py)::(\w+)(?:\[[^\]]*\])?`", row[5])
        assert tests, f"{where}: names no test"
        for file, name in tests:
            path = ROOT / "tests" / file
            assert path.is_file(), f"{where}: no tests/{file}"
            if file not in functions:
                functions[file] = {n.name for n in ast.walk(ast.parse(path.read_text()))
                                   if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
            assert name.startswith("test_") and name in functions[file], f"{where}: no {name} in tests/{file}"
    assert not scenarios - named, f"scenarios without a row in docs/examples.md: {sorted(scenarios - named)}"


def test_examples_doc_is_linked():
    assert "docs/examples.md" in (ROOT / "README.md").read_text()
    assert "examples.md" in (ROOT / "docs" / "architecture.md").read_text()
