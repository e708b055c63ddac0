"""The forward model's fixture: ``arms``, the two-wrist body with ``out`` and ``up`` (:func:`helpers.out_and_up`)."""

from __future__ import annotations

import pytest

from tests.plugins.matchers.forward_model.helpers import out_and_up


@pytest.fixture
def arms(write, pm):
    return out_and_up(write, pm)
