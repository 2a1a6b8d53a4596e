"""Results and progress bars in a real Jupyter kernel (notebooks).

The notebooks below are executed by nbclient in a fresh IPython kernel, as a
user's notebook is: what they check is the cell output Jupyter would show
(the widget bar, the HTML table), not our own idea of it.

Covers :mod:`randvib._progress` (the bars in a kernel) and :mod:`randvib._display` (the
HTML tables).
"""

from __future__ import annotations

import ast
from pathlib import Path

import nbclient
import nbformat

ROOT = Path(__file__).resolve().parents[1]

#: First cell of every notebook: import this checkout, as the tests do.
PREAMBLE = f"import sys\nsys.path.insert(0, {str(ROOT)!r})\n"

WIDGET = "application/vnd.jupyter.widget-view+json"


def execute(*cells: str):
    """Run the cells in a fresh python3 kernel; return the executed notebook."""
    notebook = nbformat.v4.new_notebook()
    notebook.cells = [nbformat.v4.new_code_cell(PREAMBLE)]
    notebook.cells += [nbformat.v4.new_code_cell(c) for c in cells]
    client = nbclient.NotebookClient(notebook, timeout=300, kernel_name="python3")
    return client.execute()


def outputs(cell) -> list[dict]:
    return list(cell["outputs"])


def test_simulation_in_a_notebook_shows_a_widget_bar_and_an_html_table():
    notebook = execute(
        # progress=None (the default) must show a bar in a notebook, although
        # the kernel's stderr is not a terminal.
        "import randvib as rv\n"
        "from randvib import _progress\n"
        "bar = _progress.progress_bar(4, desc='points', unit='point')\n"
        "shown = not bar.disable  # close() sets disable\n"
        "for _ in range(4):\n"
        "    bar.update()\n"
        "bar.close()\n"
        "kinds = {c.__module__ for c in type(bar).__mro__}\n"
        "print('tqdm.notebook' in kinds, shown, _progress.progress_wanted())",
        "result = rv.simulate(rv.preset('coulomb-td1'), 1.0, t_end=0.5, dt=1e-4,\n"
        "                     n_paths=8, seed=0)\n"
        "result",
    )
    bar_cell, result_cell = notebook.cells[1], notebook.cells[2]
    assert any(WIDGET in o.get("data", {}) for o in outputs(bar_cell)), outputs(bar_cell)
    printed = "".join(o.get("text", "") for o in outputs(bar_cell) if o["output_type"] == "stream")
    assert printed.split() == ["True", "True", "True"], printed
    shown = [o for o in outputs(result_cell) if o["output_type"] == "execute_result"]
    assert len(shown) == 1 and "text/html" in shown[0]["data"]
    html = shown[0]["data"]["text/html"]
    # the table rows are the result's own statistics, each with its interval
    assert "<table" in html and "power_electrical" in html and "±" in html


def test_without_ipywidgets_a_notebook_gets_a_text_bar_not_silence():
    notebook = execute(
        # A notebook without ipywidgets: tqdm.auto falls back to its text bar,
        # which must still be shown (not disabled as if writing to a log).
        "sys.modules['ipywidgets'] = None\n"
        "from randvib import _progress\n"
        "bar = _progress.progress_bar(3, desc='sweep', unit='point')\n"
        "for _ in range(3):\n"
        "    bar.update()\n"
        "bar.close()\n"
        "print('tqdm.notebook' in {c.__module__ for c in type(bar).__mro__})",
    )
    cell = notebook.cells[1]
    streams = {}
    for o in outputs(cell):
        if o["output_type"] == "stream":
            streams[o["name"]] = streams.get(o["name"], "") + o["text"]
    assert streams.get("stdout", "").strip() == "False"
    assert "sweep: 100%" in streams.get("stderr", ""), streams
    assert "IProgress" not in streams.get("stderr", ""), "the fallback warning leaked"


def test_outside_a_notebook_bars_stay_out_of_logs(monkeypatch):
    from randvib import _progress

    # pytest captures stderr (not a terminal), like a log file or CI.
    monkeypatch.delenv("CI", raising=False)
    assert not _progress.in_notebook()
    assert _progress.progress_wanted() is False
    bar = _progress.progress_bar(2, desc="x", unit="u")
    assert bar.disable
    bar.close()


def test_every_progress_bar_comes_from_the_one_helper():
    """No module builds its own tqdm bar (each used to pick its own rule)."""
    offenders = []
    for path in [*(ROOT / "randvib").rglob("*.py"), *(ROOT / "studies").glob("*.py")]:
        if path.name == "_progress.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            if any(n.split(".")[0] == "tqdm" for n in names):
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert offenders == []
