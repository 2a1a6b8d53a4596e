"""``randvib study NAME --out DIR``: run one of the study scripts.

The studies are scripts in the ``studies/`` folder of a randvib checkout
(:data:`randvib.studies.STUDIES`, found by :func:`randvib.studies.load`);
each defines ``run_study(out_dir, *, quick=False, seed=0, workers=None,
scheduler=None, progress=True) -> Path`` (the Markdown report it wrote).
``--workers`` is the number of local worker *processes* of a study's sweep;
``--threads`` the numba threads of a study that simulates in-process (the
identification study).
"""

from __future__ import annotations

import inspect

from randvib.studies import STUDIES, load


def load_study(name: str):
    """The ``run_study`` function of a registered study script."""
    return load(name).run_study


def register(sub) -> None:
    p = sub.add_parser(
        "study",
        help="run a study script (figures, CSV, Markdown report)",
        description="Run one of the study scripts of the checkout's studies/ folder; "
        "writes PNG figures, CSV tables and a Markdown report into --out.",
    )
    p.add_argument("name", help=f"study: {', '.join(STUDIES)}")
    p.add_argument("--out", required=True, help="output folder (created; never overwritten)")
    p.add_argument("--quick", action="store_true", help="small, fast version (about a minute)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--workers", type=int, default=None, help="local worker processes (default: all cores)"
    )
    p.add_argument(
        "--threads",
        type=int,
        default=None,
        help="numba threads of a study that simulates in-process (identification, "
        "linearisation-vs-averaging; default: all cores)",
    )
    p.add_argument(
        "--scheduler", default=None, help="Dask distributed scheduler ADDRESS to run the sweep on"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(handler=run)


def run(args) -> int:
    study = load_study(args.name)
    extra = {}
    if args.threads is not None:
        if "threads" not in inspect.signature(study).parameters:
            raise ValueError(
                f"study {args.name!r} has no `threads` option; its sweep runs on --workers "
                "processes"
            )
        extra["threads"] = args.threads
    report = study(
        args.out,
        quick=args.quick,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
        **extra,
    )
    print(f"report: {report}")
    return 0
