"""Tests of plugins/matchers/forward_model/, one file per module of the package."""
