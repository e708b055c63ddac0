"""The documentation stays true: its hooks, its Python blocks and the command output it shows."""
