"""Analytic power predictions against Monte Carlo.

``randvib study linearisation-vs-averaging --out OUT [--quick]``

(or ``python studies/linearisation_vs_averaging.py OUT [--quick]``). Not yet split into a script
of its own: the study's code is still :mod:`randvib.studies.linearisation_vs_averaging`.
"""

import sys

from randvib.studies import script_main
from randvib.studies.linearisation_vs_averaging import run_study

__all__ = ["run_study"]

if __name__ == "__main__":
    sys.exit(script_main(run_study))
