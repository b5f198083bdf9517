"""The `kincas` command: one module per command, scene reading, tables, files and pictures."""
try:  # the console script imports this after the package: Ctrl-C may still come while it loads
    from .app import main
except KeyboardInterrupt:
    from .._launch import interrupted_while_loading
    interrupted_while_loading()
    raise

__all__ = ["main"]
