"""`python -m kincas` is the `kincas` command."""
import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while Python imports the command line (here: always the command)
    from ._launch import exit_interrupted
    exit_interrupted()

sys.exit(main())
