"""`python -m kincas` is the `kincas` command."""
import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while Python imports kincas
    print("\nkincas: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
