"""Tests of the top floor: the likeme command, the estimators, the profile proposer and checks."""
