"""Tests of plugins/layers/."""
