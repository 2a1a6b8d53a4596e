"""Where can equivalent linearisation be trusted?

``randvib study linearisation-accuracy --out OUT [--quick]``

(or ``python studies/linearisation_accuracy.py OUT [--quick]``). Not yet split into a script
of its own: the study's code is still :mod:`randvib.studies.linearisation_accuracy`.
"""

import sys

from randvib.studies import script_main
from randvib.studies.linearisation_accuracy import run_study

__all__ = ["run_study"]

if __name__ == "__main__":
    sys.exit(script_main(run_study))
