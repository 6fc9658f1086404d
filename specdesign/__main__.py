"""``python -m specdesign``: the command line of :mod:`specdesign.cli`."""
import sys

from specdesign.cli import main

if __name__ == "__main__":
    sys.exit(main())
