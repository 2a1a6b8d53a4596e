"""The gallery's examples run, print, and show no object reprs: each on its own.

The documentation build (tests/test_docs.py) renders the gallery without running it
(``-D plot_gallery=0``): running twelve examples one after another inside one Sphinx
process was the longest single piece of the suite. Here each example runs in a fresh
interpreter, as sphinx-gallery runs it: the file split into its blocks by
sphinx-gallery's own parser, the blocks executed in one namespace in order, and the
value of each block's last expression shown the way the gallery would show it. The
examples then spread over the test workers and share their compiled kernels.

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

#: Runs one example block by block in a child process; prints a JSON summary last.
#: ``ignore_repr_types`` is docs/conf.py's (the artists that plotting calls return).
RUNNER = r"""
import ast, io, json, re, sys, contextlib
import matplotlib
matplotlib.use("Agg")
from sphinx_gallery.py_source_parser import split_code_and_text_blocks
path, ignore = sys.argv[1], sys.argv[2]
_, blocks = split_code_and_text_blocks(path)[:2]
namespace = {"__name__": "__main__", "__file__": path}
printed, reprs = io.StringIO(), []
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
sys.__stdout__.write("\n" + json.dumps({"printed": printed.getvalue(), "reprs": reprs}))
"""


def _ignored_repr_types() -> str:
    """docs/conf.py's ``ignore_repr_types`` pattern (read, not imported: conf.py has effects)."""
    text = (ROOT / "docs" / "conf.py").read_text()
    line = next(x for x in text.splitlines() if '"ignore_repr_types"' in x)
    return eval(line.split(":", 1)[1].strip().rstrip(","))  # a raw string literal


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_prints_and_shows_no_object_reprs(example, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg", NUMBA_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    done = subprocess.run(
        [sys.executable, "-c", RUNNER, str(example), _ignored_repr_types()],
        cwd=tmp_path,  # what an example writes lands in the test's folder
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    summary = json.loads(done.stdout.rsplit("\n", 1)[-1])
    assert summary["printed"].strip(), f"{example.name} printed nothing"
    assert not [r for r in summary["reprs"] if "object at 0x" in r], summary["reprs"]


def test_every_example_is_in_the_gallery():
    """The gallery's pattern (docs/conf.py) matches every example file name."""
    assert len(EXAMPLES) >= 6
    assert '"filename_pattern": r"/plot_"' in (ROOT / "docs" / "conf.py").read_text()
