"""``python -m dvqp``: the command line (see :mod:`dvqp.cli`)."""

import sys

from dvqp.cli import main

if __name__ == "__main__":
    sys.exit(main())
