"""Scenario tests that replay the papers' examples (characters/scenarios/), whole runs end to end."""
