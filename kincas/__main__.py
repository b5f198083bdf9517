"""`python -m kincas` is the `kincas` command."""
import sys

from .cli import main

sys.exit(main())
