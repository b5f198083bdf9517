"""The `kincas` command: one module per command, scene reading, tables, files and pictures."""
from .app import main

__all__ = ["main"]
