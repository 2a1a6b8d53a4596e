"""Paper Figure 9 with error bars and verdicts: ``python studies/figure9.py OUT [--quick]``.

Same as ``randvib study figure9 --out OUT``.
"""

import sys

from randvib.cli import main

if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        sys.exit("usage: python studies/figure9.py OUT_DIR [--quick] [--seed N]")
    sys.exit(main(["study", "figure9", "--out", args[0], *args[1:]]))
