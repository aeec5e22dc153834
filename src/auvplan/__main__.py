"""``python -m auvplan``: the same command line as the ``auvplan`` script."""

import sys

from auvplan.cli.main import console

if __name__ == "__main__":
    sys.exit(console())
