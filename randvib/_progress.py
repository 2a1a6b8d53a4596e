"""One progress bar for every long loop: terminals, notebooks, and quiet in logs.

Every simulation, sweep, SaDE search and study loop asks :func:`progress_bar`
for its bar, so that they all behave alike:

- In a terminal, a text bar on stderr.
- In Jupyter (an IPython kernel), the notebook widget bar of ``tqdm.auto``
  when ipywidgets is installed (``pip install "randvib[notebook]"``), else a
  text bar in the cell output. Either way it is shown: a kernel's stderr is
  not a terminal, and tqdm's own rule (``disable=None``: terminals only) would
  hide every bar in a notebook.
- Anywhere else (a log file, CI, a pipe) no bar at all, so logs are not
  filled with carriage returns.
"""

from __future__ import annotations

import os
import sys


def in_notebook() -> bool:
    """Whether this process is an IPython kernel (Jupyter, VS Code, Colab)."""
    # Importing ipykernel (jupyter_client does) is not running in it: ask
    # IPython whether its shell is a kernel's.
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    return getattr(shell, "kernel", None) is not None


def progress_wanted() -> bool:
    """Whether a run whose caller did not say (``progress=None``) shows a bar.

    Yes in a notebook and on a terminal; no in CI (``CI`` set) or when stderr
    goes to a file or a pipe.
    """
    if in_notebook():
        return True
    return sys.stderr.isatty() and os.environ.get("CI") is None


def progress_bar(total: int, *, desc: str, unit: str, initial: int = 0, transient: bool = False):
    """A tqdm bar that shows in terminals and notebooks and stays silent in logs.

    Parameters
    ----------
    total : int
        Number of units of work.
    desc : str
        Label written before the bar (the command, study or search).
    unit : str
        Name of one unit of work ("path", "point", "gen", ...).
    initial : int, optional
        Units already done (a resumed sweep).
    transient : bool, optional
        Remove the bar when it closes (an inner loop whose result is printed
        afterwards); such a bar also appears only after 3 s, so short runs
        print nothing.

    Returns
    -------
    tqdm.tqdm
        Use as a context manager or call ``update`` and ``close``.
    """
    import warnings

    with warnings.catch_warnings():
        # tqdm.auto warns once, with a traceback-like source line, when a
        # notebook lacks ipywidgets; it then falls back to a text bar, which
        # is what we want, so the warning carries no news for the user.
        warnings.filterwarnings("ignore", message=".*IProgress not found.*")
        warnings.filterwarnings("ignore", message=".*notebook mode.*")
        from tqdm.auto import tqdm

    notebook = in_notebook()
    return tqdm(
        total=total,
        initial=initial,
        desc=desc,
        unit=unit,
        leave=not transient,
        delay=3.0 if transient else 0.0,
        disable=False if notebook else None,
    )
