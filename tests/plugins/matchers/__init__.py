"""Tests of plugins/matchers/."""
