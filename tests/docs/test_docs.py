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
    from likeme.cli.plugins import components_markdown

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
        for path in re.findall(r"`((?:toolkit|plugins|likeme|characters|tests)/[\w/.-]+\.(?:py|toml))`", doc.read_text()):
            assert (ROOT / path).is_file(), f"{doc.name} names {path}, which does not exist"


def _anchors(page):
    """The anchors of a Markdown page's headings as GitHub makes them: lower case, punctuation dropped, spaces to
    hyphens, ``-1``, ``-2`` after a repeated one (headings inside fenced code are none); and its ``<a id="...">``."""
    text = page.read_text()
    anchors, seen, fenced = set(re.findall(r'<a id="([^"]+)"></a>', text)), {}, False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        heading = None if fenced else re.match(r"#{1,6}\s+(.*)", line)
        if heading:
            anchor = re.sub(r"[^\w\- ]", "", heading.group(1).strip().lower()).replace(" ", "-")
            anchors.add(f"{anchor}-{seen[anchor]}" if anchor in seen else anchor)
            seen[anchor] = seen.get(anchor, 0) + 1
    return anchors


def test_the_benchmark_page_holds_todays_figures_a_newcomer_can_rerun():
    """docs/benchmarks.md: at most 400 lines, every table after a command that prints it, no scratch paths."""
    text = (ROOT / "docs" / "benchmarks.md").read_text()
    lines = text.splitlines()
    assert len(lines) <= 400, f"docs/benchmarks.md has {len(lines)} lines; history belongs in git"
    assert "/tmp/" not in text and "/work/" not in text, "a path a reader cannot recreate"
    tables = [i for i, line in enumerate(lines) if line.startswith("|") and (i == 0 or not lines[i - 1].startswith("|"))]
    for i in tables:  # a table's command: in its header, or in the text or code block above it
        before = "\n".join(lines[max(0, i - 40):i + 1])
        assert "likeme bench" in before or "likeme " in lines[i], f"table at line {i + 1} has no command above it"


def test_anchors_are_made_as_github_makes_them(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# Max watches Morris (B&B §5)\n## The posegraph's pose index\n```sh\n# a comment\n```\n"
                    '## Memory\n<a id="memory-issue-12"></a>\n### Memory\n')
    assert _anchors(page) == {"max-watches-morris-bb-5", "the-posegraphs-pose-index", "memory", "memory-1",
                              "memory-issue-12"}


def test_every_link_to_a_heading_finds_it():
    """A link ``[...](PAGE.md#anchor)`` or ``[...](#anchor)`` in README.md, docs/ or the code names a heading the
    page has (a renamed or removed section breaks no link)."""
    pages = {p.name: p for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]}
    anchors = {}
    sources = [*pages.values(), *[p for room in ("toolkit", "plugins", "likeme", "tests", "characters")
                                  for p in (ROOT / room).rglob("*") if p.suffix in (".py", ".toml", ".md")]]
    broken = []
    for source in sources:
        for target, anchor in re.findall(r"\]\(([\w./-]*\.md)?#([^)\s]+)\)", source.read_text(errors="replace")):
            name = target.rsplit("/", 1)[-1] if target else source.name
            if name not in pages:
                continue
            if name not in anchors:
                anchors[name] = _anchors(pages[name])
            if anchor not in anchors[name]:
                broken.append(f"{source.relative_to(ROOT)}: {target}#{anchor}")
    assert not broken, f"links to headings that are not there: {broken}"


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


def test_ci_runs_readmes_test_command_then_the_benchmarks_it_leaves_out():
    readme = (ROOT / "README.md").read_text()
    command = re.search(r"^python3 -m venv .*pytest[^\n]*$", readme, re.M).group(0)
    assert command.endswith('pytest -n auto -m "not benchmark"')
    steps = (ROOT / ".ci" / "run").read_text().splitlines()
    at = steps.index(command)
    assert steps[at + 1] == "pytest -n auto -m benchmark"
    marker = re.search(r"^\s*\"benchmark: ", (ROOT / "pyproject.toml").read_text(), re.M)
    assert marker, "the benchmark mark is registered in pyproject.toml"
