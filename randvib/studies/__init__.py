"""Building blocks for studies, and the finder of the study scripts.

A study is a short script in the top-level ``studies/`` folder, installed with
the package as :mod:`randvib.study_scripts` (a packaging mapping, no copies),
written against the public API the way a user would write their own sweep:
compute (a sweep, contrasts), tables, figures, a report with verdicts. What
such scripts share lives here:

- :mod:`~randvib.studies.grids`: friction and Duffing levels, Coulomb and
  friction-level grids, the points of a half-step re-run, burn-in, coloured inputs at
  equal response, fixed-size ensemble settings;
- :mod:`~randvib.studies.contrasts`: paired interaction contrasts (of a sweep, or
  within the groups of :func:`randvib.run_ensembles`) with Holm's correction, and
  analytic predictions of the same contrasts and of the power on fine grids;
- :mod:`~randvib.studies.budget`: a stroke study's Monte Carlo table, the power at a
  stroke-exceedance budget, and paired gains over a linear device;
- :mod:`~randvib.studies.accuracy`: where an analytic method can be trusted (trusted
  ranges of the friction level, the collapse of series that scale exactly);
- :mod:`~randvib.studies.campaign`: an identification campaign (synthetic shaker
  records on the campaign's seed, resumable fits, their tables and figures);
- :mod:`~randvib.studies.methods`: every analytic method against Monte Carlo (a sweep's
  points, or the cases of :func:`randvib.run_ensembles`), and the accuracy criteria for
  a fast method;
- :mod:`~randvib.studies.half_step`: the sweep with its half-step re-run, its verdict
  and its report section (the time-step bias of a study's sweep; the linear test
  system's step bias is :mod:`randvib.montecarlo.step_check`);
- :mod:`~randvib.studies.verdicts`: the verdict sentences, built from the numbers;
- :mod:`~randvib.studies.evidence`: rows that repeat one experiment (exact rescalings);
- :mod:`~randvib.studies.figures`: figures of power and contrasts against Fc or the
  bandwidth, power against stroke exceedance, methods' errors against the level;
- :mod:`~randvib.studies.bridge`: a coil's bridge against its resistive figure (paired
  cases, stored-power tables, the optimum's table, where the resistive figure overstates);
- :mod:`~randvib.studies.gaussian_error`: the Gaussian answer against Monte Carlo under
  tones or non-Gaussian input, relative errors with intervals and a 5 % verdict;
- :mod:`~randvib.studies.assembly_cases`: harvesters on a host mode and the single-mass
  answer (exact, in series), arrays and two-mass harvesters, paired Monte Carlo of
  assemblies, and the assemblies study's verdicts;
- :mod:`~randvib.studies.report`: CSV, ``verdicts.json``, Markdown tables, ``report.md``.

A script imports only ``randvib`` (its exports), these building blocks and the
package's top-level public modules (``randvib.statistics``,
``randvib.figure_style``); its loops over paths, points and cases, its seeds
and its resume are the runner's (:func:`randvib.run_sweep`,
:func:`randvib.run_ensembles`) or a building block's.

Every figure is drawn in :mod:`randvib.figure_style` (shared with the
identification plots).

Every script defines ``run_study(out_dir, *, quick=False, seed=0,
workers=None, scheduler=None, progress=True) -> Path`` (the report it wrote);
``workers`` always means local worker *processes* (of its sweep or
:func:`randvib.run_ensembles`), and a study that simulates in-process on numba
threads takes ``threads`` as well.
:func:`load` finds a script by its name (``randvib study NAME`` runs it).
"""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import sys
from pathlib import Path

from randvib._interrupts import interrupted_exit, interrupts_seen, sigterm_stops
from randvib._validation import MAX_SEED, integer_option

#: The package of the study scripts: the top-level ``studies/`` folder, which
#: pyproject.toml installs as this subpackage.
SCRIPTS_PACKAGE = "randvib.study_scripts"

#: The registered studies (``randvib study NAME``), each ``studies/NAME.py`` with
#: dashes as underscores.
STUDIES = (
    "figure9",
    "interaction",
    "linearisation-accuracy",
    "identification",
    "linearisation-vs-averaging",
    "silverbox",
    "excitation",
    "devices",
    "events",
    "dc-power",
    "design",
    "non-gaussian",
    "electrical-identification",
    "assemblies",
)


def _scripts_package():
    """:mod:`randvib.study_scripts`, from the ``studies/`` folder that belongs to this randvib.

    An install (wheel, ``pip install .`` or editable) maps the folder into the
    package. A source tree imported without installing it (``PYTHONPATH``, a
    scratch copy of the project) has the folder beside the package instead;
    that one is taken first, so the scripts always come with the package
    they were written for, never from another checkout's install.
    """
    if SCRIPTS_PACKAGE in sys.modules:
        return sys.modules[SCRIPTS_PACKAGE]
    beside = Path(__file__).resolve().parents[2] / "studies"
    if not (beside / "__init__.py").is_file():
        return importlib.import_module(SCRIPTS_PACKAGE)
    spec = importlib.util.spec_from_file_location(
        SCRIPTS_PACKAGE, beside / "__init__.py", submodule_search_locations=[str(beside)]
    )
    package = importlib.util.module_from_spec(spec)
    sys.modules[SCRIPTS_PACKAGE] = package
    try:
        spec.loader.exec_module(package)
    except BaseException:
        del sys.modules[SCRIPTS_PACKAGE]
        raise
    sys.modules["randvib"].study_scripts = package  # as an import would set it
    return package


def load(name: str):
    """The module of the study script ``name``: ``randvib.study_scripts.NAME``.

    Imported once, then the same object (a test's monkeypatch and the CLI
    see the same module).

    Raises
    ------
    ValueError
        ``name`` is not a registered study.
    """
    if name not in STUDIES:
        raise ValueError(f"unknown study {name!r}; available: {', '.join(STUDIES)}")
    package = _scripts_package()
    return importlib.import_module(f"{package.__name__}.{name.replace('-', '_')}")


def add_run_options(parser: argparse.ArgumentParser) -> None:
    """The options of a study run, shared by ``randvib study`` and the scripts' ``__main__``."""
    parser.add_argument("--quick", action="store_true", help="small, fast version (about a minute)")
    parser.add_argument(
        "--seed", type=integer_option(0, MAX_SEED), default=0, help="random seed (default 0)"
    )
    parser.add_argument(
        "--workers",
        type=integer_option(1),
        default=None,
        help="local worker processes (default: all cores)",
    )
    parser.add_argument(
        "--threads",
        type=integer_option(1),
        default=None,
        help="numba threads of a study that simulates in-process (identification; "
        "default: all cores)",
    )
    parser.add_argument(
        "--scheduler",
        default=None,
        help="Dask distributed scheduler ADDRESS to run the sweep on (it is sent pickled "
        "Python objects: a cluster you trust only)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.add_argument(
        "--force",
        action="store_true",
        help="overwrite reports, tables and figures edited since the study wrote them",
    )


def run_with_options(run_study, name: str, out, args) -> Path:
    """Call a study's ``run_study`` with the options of :func:`add_run_options`.

    ``--threads`` goes only to a study that takes it; elsewhere it is refused,
    because those studies run their sweep on ``--workers`` processes. The
    output folder is checked before anything runs; files the user edited since
    the study wrote them are kept unless ``--force``; the folder locks taken by
    the run are released when it ends.
    """
    from randvib._io import check_output_folder, overwrite_edited, release_all

    check_output_folder(out, "--out")
    extra = {}
    if args.threads is not None:
        if "threads" not in inspect.signature(run_study).parameters:
            raise ValueError(
                f"study {name!r} has no `threads` option; its sweep runs on --workers processes"
            )
        extra["threads"] = args.threads
    try:
        with overwrite_edited(getattr(args, "force", False)):
            return run_study(
                out,
                quick=args.quick,
                seed=args.seed,
                workers=args.workers,
                scheduler=args.scheduler,
                progress=not args.no_progress,
                **extra,
            )
    finally:
        release_all()


def script_main(run_study, argv=None) -> int:
    """``python studies/NAME.py OUT_DIR [options]``: run one study.

    The same as ``randvib study NAME --out OUT_DIR [options]`` (the same
    options and the same call); for the ``__main__`` block of a study script.
    """
    parser = argparse.ArgumentParser(description=(run_study.__doc__ or "").splitlines()[0])
    parser.add_argument(
        "out", help="output folder (created; a rerun resumes; edited files kept unless --force)"
    )
    add_run_options(parser)
    args = parser.parse_args(argv)
    name = Path(sys.modules[run_study.__module__].__file__).stem.replace("_", "-")
    from randvib.studies.report import print_verdicts

    try:
        with sigterm_stops():  # SIGTERM stops the study as Ctrl-C does
            print_verdicts(run_with_options(run_study, name, args.out, args))
            # an interrupt a finaliser swallowed: the study went on, but was asked to stop
            swallowed = interrupts_seen()
            if swallowed is not None:
                raise swallowed
    except KeyboardInterrupt as exc:  # finished points and files are kept
        code, line = interrupted_exit(exc)
        print(line, file=sys.stderr)
        return code
    return 0
