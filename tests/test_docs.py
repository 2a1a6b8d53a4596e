"""The documentation site builds from the docstrings with warnings as errors.

The build (``python -m sphinx -W --keep-going -b html -D plot_gallery=0 docs OUT``)
renders the gallery's pages without running the examples (tests/test_examples.py runs
each of them, on its own, in parallel with the rest of the suite), so a malformed
docstring section or a broken cross-reference fails here. It builds a copy of ``docs/`` so that
the generated pages never land in the checkout.

Covers the docstrings of every module (the API reference of the names re-exported by
``randvib/__init__.py`` and the Modules section) and docs/.
"""

import html as html_module
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import randvib

pytest.importorskip("sphinx", reason="the docs extra (pip install -e '.[docs]') is not installed")
pytest.importorskip("numpydoc")
pytest.importorskip("sphinx_gallery")
pytest.importorskip("myst_parser")
pytest.importorskip("sphinxarg")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The built site: (html folder, the build's output)."""
    tmp = tmp_path_factory.mktemp("docs")
    shutil.copytree(ROOT / "docs", tmp / "docs", ignore=shutil.ignore_patterns("_build"))
    for generated in ("generated", "auto_examples", "sg_execution_times.rst"):
        path = tmp / "docs" / generated
        if path.is_dir():
            shutil.rmtree(path)
        elif path.exists():
            path.unlink()
    env = dict(os.environ, RANDVIB_CHECKOUT=str(ROOT), MPLBACKEND="Agg")
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    command += ["-D", "plot_gallery=0"]  # the examples run in tests/test_examples.py
    # The pages' content, from the same sources, in Sphinx's plain theme: furo
    # rebuilds the site's whole navigation tree for every page (quadratic in the
    # ~150 pages, a third of this build's time, py-spy), and the sidebar is
    # nothing a docstring or a page can break.
    command += ["-D", "html_theme=basic"]
    done = subprocess.run(
        [*command, str(tmp / "docs"), str(tmp / "html")],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    return tmp / "html", done


def test_site_builds_without_warnings(site):
    html, done = site
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-6000:]
    assert "WARNING" not in done.stderr and "ERROR" not in done.stderr, done.stderr[-6000:]
    pages = ("index", "conventions", "testing", "quickstart", "cli", "api", "auto_examples/index")
    for page in pages:
        assert (html / f"{page}.html").is_file(), page


def test_every_example_has_a_gallery_page(site):
    html, _ = site
    assert len(EXAMPLES) >= 6
    for stem in EXAMPLES:
        assert (html / "auto_examples" / f"{stem}.html").is_file(), stem


def test_cli_page_documents_every_command_and_option(site):
    """docs/cli.rst is generated from the parsers: every flag of every command is on it."""
    html, _ = site
    text = html_module.unescape(re.sub(r"<[^>]+>", "", (html / "cli.html").read_text()))
    # the parsers of a fresh process: tests may register extra friction laws here
    listing = (
        "import json; from randvib.cli import build_parser; "
        "c = next(a for a in build_parser()._actions if a.dest == 'command').choices; "
        "print(json.dumps({n: [o for a in p._actions for o in a.option_strings] "
        "for n, p in c.items()}))"
    )
    done = subprocess.run([sys.executable, "-c", listing], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(ROOT)), check=True)  # fmt: skip
    for name, flags in json.loads(done.stdout).items():
        assert f"randvib {name} [-h]" in text, name
        for flag in flags:
            assert flag in text, (name, flag)


def test_api_reference_lists_every_public_name():
    listed = set(
        re.findall(r"~randvib\.[\w.]+\.(\w+)$", (ROOT / "docs" / "api.rst").read_text(), re.M)
    )
    assert set(randvib.__all__) <= listed, sorted(set(randvib.__all__) - listed)


def _text(page: Path) -> str:
    return html_module.unescape(re.sub(r"<[^>]+>", "", page.read_text()))


def test_cli_page_keeps_double_dashes(site):
    """An option in a help text reads as typed (no smart en-dash), so it can be copied."""
    html, _ = site
    text = _text(html / "cli.html")
    assert re.findall(r"\u2013\w", text) == []
    assert "e.g. --fix k3=0" in text  # identify's help for --fix, as typed
    assert "(a new file unless --force)" in text


def test_api_summaries_are_whole_sentences(site):
    """The tables' summaries do not stop at an abbreviation ("Eq.") and none is empty."""
    html, _ = site
    page = (html / "api.html").read_text()
    rows = re.findall(r'<tr class="row-(?:odd|even)"><td>(.*?)</td>\s*<td>(.*?)</td>', page, re.S)
    assert len(rows) >= len(randvib.__all__)
    for name, summary in rows:
        name, summary = (
            html_module.unescape(re.sub(r"<[^>]+>", "", s)).strip() for s in (name, summary)
        )
        assert summary, name
        assert not re.search(r"\b(Eqs?|Sec|Figs?)\.$", summary), (name, summary)


def test_simulate_has_a_page_and_its_module_lists_only_the_public_api(site):
    html, _ = site
    assert "def simulate" not in _text(html / "simulate.html")
    assert "randvib.montecarlo.simulation.simulate(" in _text(html / "simulate.html")
    module = (html / "generated" / "randvib.montecarlo.simulation.html").read_text()
    assert 'id="randvib.montecarlo.simulation.simulate"' in module
    assert 'id="randvib.montecarlo.simulation.execute"' not in module


def test_the_manual_is_in_the_site_and_the_readme_is_a_front_page(site):
    """Every page of the manual is built; the README links to pages that exist, and
    the site itself never sends a reader to the README."""
    html, _ = site
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 200
    for target in re.findall(r"\]\((docs/[^)#]+)\)", readme):
        assert (ROOT / target).is_file(), target
        assert (html / Path(target).relative_to("docs").with_suffix(".html")).is_file(), target
    for page in ("quickstart", "cli", "command_line", "index"):
        assert "README" not in _text(html / f"{page}.html"), page
