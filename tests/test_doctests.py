"""The ``Examples`` sections of the public docstrings run as doctests.

Every module of the package whose source holds a ``>>>`` example is listed in
``MODULES`` (a test checks the list is complete), and each runs under
:mod:`doctest` with the usual numpy-friendly flags. The examples print
rounded numbers, so they state what the code computes at fixed seeds.

Covers the examples of the modules in ``MODULES`` (:mod:`randvib.models.presets`,
:mod:`randvib.montecarlo.simulation`, :mod:`randvib.formatting`,
:mod:`randvib.quantities`, ...).
"""

import doctest
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "randvib"

MODULES = (
    "randvib.analytic.bridge",
    "randvib.analytic.linearisation",
    "randvib.analytic.prediction",
    "randvib.analytic.statistical_linearisation",
    "randvib.formatting",
    "randvib.analytic.transient",
    "randvib.identification.prediction",
    "randvib.identification.record_response",
    "randvib.identification.synthetic",
    "randvib.models.assembly",
    "randvib.models.combined",
    "randvib.models.coupling",
    "randvib.models.event",
    "randvib.models.excitation",
    "randvib.models.harvester",
    "randvib.models.potential",
    "randvib.models.presets",
    "randvib.models.record",
    "randvib.models.rectifier",
    "randvib.models.shock",
    "randvib.models.tone",
    "randvib.models.translation",
    "randvib.montecarlo.simulation",
    "randvib.montecarlo.sweep",
    "randvib.quantities",
    "randvib.montecarlo.transient",
    "randvib.harvester_design.design",
    "randvib.montecarlo.reliability",
)

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def test_every_module_with_examples_is_run():
    with_examples = {
        ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        for path in PACKAGE.rglob("*.py")
        if ">>>" in path.read_text()
    }
    assert with_examples == set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)  # the module's own objects only
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    tests = [t for t in finder.find(module, name) if t.examples]
    assert tests, f"{name} has no examples"
    for test in tests:
        runner.run(test)
    results = runner.summarize(verbose=False)
    assert results.failed == 0, f"{results.failed} of {results.attempted} examples failed in {name}"
