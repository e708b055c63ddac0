"""Tests of plugins/segmenters/."""
