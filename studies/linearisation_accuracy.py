"""Where equivalent linearisation can be trusted: ``python studies/linearisation_accuracy.py OUT [--quick]``.

Same as ``randvib study linearisation-accuracy --out OUT``.
"""

import sys

from randvib.cli import main

if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        sys.exit("usage: python studies/linearisation_accuracy.py OUT_DIR [--quick] [--seed N]")
    sys.exit(main(["study", "linearisation-accuracy", "--out", args[0], *args[1:]]))
