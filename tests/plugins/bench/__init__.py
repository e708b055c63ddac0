"""Tests of plugins/bench/."""
