"""The mutation check (``tests/mutation_check.py``) as part of the suite.

For each curated mutation, a copy of the project is mutated and the tests
named in its entry must fail. The table of mutations, with what each models
and which test catches it, is ``python tests/mutation_check.py --list``.

Covers the suite itself: each mutant edits one module of randvib
(:mod:`randvib.montecarlo.kernel`, :mod:`randvib.statistics`,
:mod:`randvib.models.friction`, ...; the list is in tests/mutation_check.py).
"""

from concurrent.futures import ThreadPoolExecutor

import mutation_check as mc
import pytest


@pytest.mark.parametrize("mutation", mc.MUTATIONS, ids=lambda m: m.name)
def test_each_mutation_applies_to_exactly_one_place(mutation, tmp_path):
    # cheap guard: a refactor that moves the mutated line must update the list
    target = tmp_path / mutation.path
    target.parent.mkdir(parents=True)
    target.write_text((mc.ROOT / mutation.path).read_text())
    mc.apply(mutation, tmp_path)
    assert target.read_text() != (mc.ROOT / mutation.path).read_text()


def test_numba_caches_are_dropped_for_every_module_that_imports_the_mutant():
    reached = mc.reaching_modules(mc.ROOT, "randvib/models/friction.py")
    # the Monte Carlo kernel calls the compiled friction force: it must recompile
    assert {"randvib.models.friction", "randvib.montecarlo.kernel"} <= reached
    assert "randvib.montecarlo.rng" not in reached  # the generator does not import friction


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """Every mutant's run, two at a time.

    A mutant's run is mostly numba compiling the mutated module on one core,
    so two concurrent runs keep a two-core machine busy and halve the wall time.
    """
    root = tmp_path_factory.mktemp("mutants")
    prepared = []
    for mutation in mc.MUTATIONS:  # serially: copying and parsing is not thread-safe
        work = root / mutation.name
        work.mkdir()
        prepared.append((mutation, mc.prepare_mutant(mutation, work)))

    def run(item):
        mutation, project = item
        return mutation.name, mc.run_prepared(mutation, project)

    with ThreadPoolExecutor(max_workers=2) as pool:
        return dict(pool.map(run, prepared))


@pytest.mark.slow
@pytest.mark.parametrize("mutation", mc.MUTATIONS, ids=lambda m: m.name)
def test_suite_catches_the_mutation(mutation, outcomes):
    outcome = outcomes[mutation.name]
    assert outcome.caught, outcome.summary() + "\n" + outcome.output[-3000:]


def test_docs_list_every_mutation():
    # regenerate with: python tests/mutation_check.py --markdown
    text = (mc.ROOT / "docs" / "testing.md").read_text()
    assert mc.markdown_table() in text, "docs/testing.md's mutation table is out of date"
