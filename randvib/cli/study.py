"""``randvib study NAME --out DIR``: run one of the study scripts.

The studies are the scripts of the top-level ``studies/`` folder, installed
with the package as :mod:`randvib.study_scripts`
(:data:`randvib.studies.STUDIES`, found by :func:`randvib.studies.load`);
each defines ``run_study(out_dir, *, quick=False, seed=0, workers=None,
scheduler=None, progress=True) -> Path`` (the Markdown report it wrote).
``--workers`` is the number of local worker *processes* of a study's sweep;
``--threads`` the numba threads of a study that simulates in-process (the
identification study).
"""

from __future__ import annotations

from randvib.cli import COMMAND_HELP
from randvib.studies import STUDIES, add_run_options, load, run_with_options


def load_study(name: str):
    """The ``run_study`` function of a registered study script."""
    return load(name).run_study


def register(sub) -> None:
    p = sub.add_parser(
        "study",
        help=COMMAND_HELP["study"],
        description="Run one of the study scripts (the studies/ folder, installed with the "
        "package as randvib.study_scripts); "
        "writes PNG figures, CSV tables and a Markdown report into --out.",
    )
    p.add_argument("name", choices=STUDIES, metavar="NAME", help=f"study: {', '.join(STUDIES)}")
    p.add_argument(
        "--out",
        required=True,
        help="output folder (created; a rerun resumes; edited files kept unless --force)",
    )
    add_run_options(p)
    p.set_defaults(handler=run)


def run(args) -> int:
    from randvib.studies.report import print_verdicts

    print_verdicts(run_with_options(load_study(args.name), args.name, args.out, args))
    return 0
