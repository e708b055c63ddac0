"""Tests of plugins/action/."""
