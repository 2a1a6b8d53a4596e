"""Synthetic identification campaign: paper Sec. 3-4, Figures 7-8, Table 2.

``randvib study identification --out OUT [--quick]``

(or ``python studies/identification.py OUT [--quick]``). Not yet split into a script
of its own: the study's code is still :mod:`randvib.studies.identification`.
"""

import sys

from randvib.studies import script_main
from randvib.studies.identification import run_study

__all__ = ["run_study"]

if __name__ == "__main__":
    sys.exit(script_main(run_study))
