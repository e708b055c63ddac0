"""The built-in likeme plugins, one concept per module.

Each module is registered through the ``likeme`` entry-point group declared in
the project's ``pyproject.toml``, exactly as a third-party plugin would be.
Modules named after a concept but without hooks (``key_poses``, ``root_frame``)
are shared building blocks of the plugins that register components.
"""
