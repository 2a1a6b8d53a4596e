"""Linearisation vs stochastic averaging vs Monte Carlo: ``python studies/linearisation_vs_averaging.py OUT [--quick]``.

Same as ``randvib study linearisation-vs-averaging --out OUT``.
"""

import sys

from randvib.cli import main

if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        sys.exit("usage: python studies/linearisation_vs_averaging.py OUT_DIR [--quick] [--seed N]")
    sys.exit(main(["study", "linearisation-vs-averaging", "--out", args[0], *args[1:]]))
