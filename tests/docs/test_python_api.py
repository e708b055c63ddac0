"""docs/python-api.md runs: every ```python block, in order, in one namespace, on data generated here (the machinery
of ``likeme bench make-data``), never on the Bandai-Namco clips; the figures the page prints are what it shows."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from plugins.bench.data import make_data
from tests.conftest import ROOT
from toolkit import create_plugin_manager

DOC = ROOT / "docs" / "python-api.md"


def blocks(text: str) -> list[str]:
    """The ```python blocks of a Markdown page, in order."""
    return re.findall(r"^```python\n(.*?)^```", text, re.S | re.M)


def shown(block: str) -> list[str]:
    """The output a block shows: its lines that are a comment from their start (what the prints above print)."""
    return [line[2:] for line in block.split("\n") if line.startswith("# ")]


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    path = tmp_path_factory.mktemp("python-api")
    make_data(create_plugin_manager(), path / "bench-data")  # `likeme bench make-data bench-data`
    return path


def test_the_page_has_blocks_and_names_the_command():
    text = DOC.read_text(encoding="utf-8")
    assert len(blocks(text)) >= 8
    assert "likeme bench make-data bench-data" in text


def test_every_block_runs_and_shows_what_it_prints(workdir, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(workdir)
    namespace: dict = {"__name__": "python_api_doc"}
    for number, block in enumerate(blocks(DOC.read_text(encoding="utf-8")), 1):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(block, f"{DOC.name} block {number}", "exec"), namespace)
        expected = shown(block)
        if expected:
            assert out.getvalue().rstrip("\n").split("\n") == expected, f"block {number} prints something else"
    assert (workdir / "segments.png").stat().st_size > 10_000
    live, truth = namespace["live"], namespace["truth"]
    assert [label for _, _, label in live] == [label for _, _, label in truth[0]]
    in_memory, from_folder = namespace["in_memory"].motor, namespace["from_folder"].motor
    assert list(in_memory.graph.nodes) == list(from_folder.graph.nodes)
