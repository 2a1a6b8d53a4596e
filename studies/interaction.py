"""Duffing-Coulomb interaction beyond the paper's k3: ``python studies/interaction.py OUT [--quick]``.

Same as ``randvib study interaction --out OUT``.
"""

import sys

from randvib.cli import main

if __name__ == "__main__":
    args = sys.argv[1:]
    if not args:
        sys.exit("usage: python studies/interaction.py OUT_DIR [--quick] [--seed N]")
    sys.exit(main(["study", "interaction", "--out", args[0], *args[1:]]))
