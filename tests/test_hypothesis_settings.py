"""Every property test runs untimed: no hypothesis deadline (the project has no timed tests; a CI machine busy with
``pytest -n auto`` can stall one example past 200 ms, which hypothesis reports as a failure or as flaky)."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
MODULES = sorted(".".join(p.relative_to(HERE).with_suffix("").parts) for p in HERE.rglob("test_*.py")
                 if "fixtures" not in p.parts and "hypothesis" in p.read_text(encoding="utf-8"))


def property_tests(module):
    """The module's hypothesis tests (``@given``), methods of test classes included."""
    for name, obj in vars(module).items():
        if hasattr(obj, "hypothesis"):
            yield name, obj
        elif isinstance(obj, type):
            yield from ((f"{name}.{n}", o) for n, o in vars(obj).items() if hasattr(o, "hypothesis"))


@pytest.mark.parametrize("name", MODULES)
def test_no_property_test_has_a_deadline(name):
    module = importlib.import_module(f"tests.{name}")
    timed = [test for test, fn in property_tests(module) if fn._hypothesis_internal_use_settings.deadline is not None]
    assert not timed, f"{name}: {timed} have a hypothesis deadline; set deadline=None (tests are not timed)"


def test_the_property_tests_are_found():
    from tests.plugins.bench import test_metrics

    assert {"test_edit_distance_is_a_metric", "test_macro_f1_and_confusion_equal_the_hand_written_ones"} <= {
        name for name, _ in property_tests(test_metrics)}
