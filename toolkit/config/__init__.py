"""Declarations read from files and from the command line, before anything is composed.

- :mod:`toolkit.config.toml`: TOML files read bounded, and the line a key was written on;
- :mod:`toolkit.config.search`: the character path, ``extends`` chains and how tables merge;
- :mod:`toolkit.config.settings`: ``--set TABLE.KEY=VALUE`` parsed and checked against the plugins it reaches;
- :mod:`toolkit.config.observer_templates`: the observer templates ``likeme observe`` and the benchmarks compose
  observers from.

A component's own parameters, and their checks, are :mod:`toolkit.params`; composing a character from the tables
read here is :mod:`toolkit.character`.
"""
