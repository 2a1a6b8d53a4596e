"""Synthetic identification campaign (paper Sec. 3-4): ``python studies/identification.py OUT [--quick]``.

Same as ``randvib study identification --out OUT``.
"""

import sys

from randvib.cli import main

if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        sys.exit("usage: python studies/identification.py OUT_DIR [--quick] [--seed N]")
    sys.exit(main(["study", "identification", "--out", args[0], *args[1:]]))
