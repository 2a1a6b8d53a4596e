"""``randvib study NAME --out DIR``: run one of the packaged studies.

Every study is a function ``run_study(out_dir, *, quick=False, seed=0,
workers=None, scheduler=None, progress=True) -> Path`` (the Markdown report
it wrote) registered in :data:`STUDIES` as ``"module:function"``; the scripts
in the repository's ``studies/`` folder call the same functions.
"""

from __future__ import annotations

import importlib

#: Study name -> "module:function" (imported only when run).
STUDIES = {
    "figure9": "randvib.studies.figure9:run_study",
    "interaction": "randvib.studies.interaction:run_study",
    "linearisation-accuracy": "randvib.studies.linearisation_accuracy:run_study",
    "identification": "randvib.studies.identification:run_study",
    "linearisation-vs-averaging": "randvib.studies.linearisation_vs_averaging:run_study",
}


def load_study(name: str):
    """The ``run_study`` function of a registered study."""
    if name not in STUDIES:
        raise ValueError(f"unknown study {name!r}; available: {', '.join(STUDIES)}")
    module_name, func = STUDIES[name].split(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name == module_name:
            raise ValueError(f"study {name!r} is not available in this version") from None
        raise
    return getattr(module, func)


def register(sub) -> None:
    p = sub.add_parser(
        "study",
        help="run a packaged study (figures, CSV, Markdown report)",
        description="Run a packaged study; writes PNG figures, CSV tables and "
        "a Markdown report into --out.",
    )
    p.add_argument("name", help=f"study: {', '.join(STUDIES)}")
    p.add_argument("--out", required=True, help="output folder (created; never overwritten)")
    p.add_argument("--quick", action="store_true", help="small, fast version (about a minute)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--workers", type=int, default=None, help="local worker processes (default: all cores)"
    )
    p.add_argument(
        "--scheduler", default=None, help="Dask distributed scheduler ADDRESS to run the sweep on"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(handler=run)


def run(args) -> int:
    study = load_study(args.name)
    report = study(
        args.out,
        quick=args.quick,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
    )
    print(f"report: {report}")
    return 0
