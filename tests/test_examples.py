"""The gallery's examples run, print, and show no object reprs: each on its own.

The documentation build (tests/test_docs.py) renders the gallery without running it
(``-D plot_gallery=0``): running twelve examples one after another inside one Sphinx
process was the longest single piece of the suite. Here the examples run in one fresh
interpreter, one after another, as sphinx-gallery runs them: each file split into its
blocks by sphinx-gallery's own parser, the blocks executed in order in a namespace of
the example's own (in a folder of its own), the value of each block's last expression
shown the way the gallery would show it, and matplotlib's figures and settings reset
between examples (sphinx-gallery's ``reset_modules``). One interpreter, not one per
example: starting one and importing numpy, scipy, numba, matplotlib and randvib cost
about 5 CPU-seconds, paid twelve times; the module runs on one test worker anyway.

Covers the scripts in examples/ (the gallery of the documentation site), which reach the
package through its exports: :mod:`randvib.analytic.prediction`,
:mod:`randvib.montecarlo.simulation`, :mod:`randvib.identification.identify` and others.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))

pytest.importorskip("sphinx_gallery", reason="the docs extra is not installed")

#: Runs examples block by block in one child process, each in a namespace and folder of
#: its own; prints a JSON summary per example last (what it printed, the reprs a gallery
#: page would show, the traceback that stopped it). ``ignore_repr_types`` is
#: docs/conf.py's (the artists that plotting calls return).
RUNNER = r"""
import ast, io, json, os, re, sys, contextlib, traceback
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from sphinx_gallery.py_source_parser import split_code_and_text_blocks
ignore, folder, paths = sys.argv[1], sys.argv[2], sys.argv[3:]
summaries = {}
for path in paths:
    _, blocks = split_code_and_text_blocks(path)[:2]
    namespace = {"__name__": "__main__", "__file__": path}
    printed, reprs, error = io.StringIO(), [], None
    here = os.path.join(folder, os.path.basename(path)[:-3])
    os.makedirs(here)
    os.chdir(here)  # what an example writes lands in a folder of its own
    try:
        for label, source, lineno in blocks:
            if label != "code":
                continue
            tree = ast.parse(source)
            last = tree.body[-1] if tree.body and isinstance(tree.body[-1], ast.Expr) else None
            body = tree.body[:-1] if last is not None else tree.body
            with contextlib.redirect_stdout(printed):
                exec(compile(ast.Module(body, []), path, "exec"), namespace)
                if last is not None:
                    value = eval(compile(ast.Expression(last.value), path, "eval"), namespace)
                    if value is not None and not re.search(ignore, str(type(value))):
                        reprs.append(repr(value))  # sphinx-gallery matches str(type(value)) too
    except Exception:
        error = traceback.format_exc()
    plt.close("all")  # sphinx-gallery's reset of matplotlib between examples
    matplotlib.rcdefaults()
    matplotlib.use("Agg")
    summaries[path] = {"printed": printed.getvalue(), "reprs": reprs, "error": error}
sys.__stdout__.write("\n" + json.dumps(summaries))
"""


def _ignored_repr_types() -> str:
    """docs/conf.py's ``ignore_repr_types`` pattern (read, not imported: conf.py has effects)."""
    text = (ROOT / "docs" / "conf.py").read_text()
    line = next(x for x in text.splitlines() if '"ignore_repr_types"' in x)
    return eval(line.split(":", 1)[1].strip().rstrip(","))  # a raw string literal


@pytest.fixture(scope="module")
def gallery(request, tmp_path_factory):
    """Every example this session selected, run once in one fresh interpreter: its summary."""
    selected = [
        path
        for path in EXAMPLES
        if any(
            getattr(item, "callspec", None) is not None
            and item.callspec.params.get("example") == path
            for item in request.session.items
        )
    ]
    env = dict(os.environ, MPLBACKEND="Agg", NUMBA_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    folder = tmp_path_factory.mktemp("gallery")
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            RUNNER,
            _ignored_repr_types(),
            str(folder),
            *map(str, selected or EXAMPLES),
        ],  # fmt: skip
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=1200,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    return json.loads(done.stdout.rsplit("\n", 1)[-1])


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_prints_and_shows_no_object_reprs(example, gallery):
    summary = gallery[str(example)]
    assert summary["error"] is None, summary["error"][-4000:]
    assert summary["printed"].strip(), f"{example.name} printed nothing"
    assert not [r for r in summary["reprs"] if "object at 0x" in r], summary["reprs"]


def test_every_example_is_in_the_gallery():
    """The gallery's pattern (docs/conf.py) matches every example file name."""
    assert len(EXAMPLES) >= 6
    assert '"filename_pattern": r"/plot_"' in (ROOT / "docs" / "conf.py").read_text()
