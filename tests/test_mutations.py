"""The mutation check (``tests/mutation_check.py``) as part of the suite.

For each curated mutation, a copy of the project is mutated and the tests
named in its entry must fail. The table of mutations, with what each models
and which test catches it, is ``python tests/mutation_check.py --list``; the
whole check is ``python tests/mutation_check.py --record`` (its outcomes kept in
tests/mutation_results.txt and checked here).

Covers the suite itself: each mutant edits one module of randvib
(:mod:`randvib.montecarlo.kernel`, :mod:`randvib.statistics`,
:mod:`randvib.models.friction`, ...; the list is in tests/mutation_check.py).
"""

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


def _caught_by_its_own_test(mutation, failed: str) -> bool:
    """The first failed test is one the mutation names (a file, a test, or a parametrisation)."""
    return any(failed == t or failed.startswith((t + "::", t + "[")) for t in mutation.tests)


def test_every_recorded_outcome_is_a_catch_by_the_mutations_own_tests():
    """tests/mutation_results.txt, kept by ``python tests/mutation_check.py --record``.

    The full run is a command of its own (tests/mutation_check.py's docstring): it is
    the check of the suite, not of the package, and costs more than the rest of the
    suite. Every outcome it kept must name a mutation that still exists, caught by one
    of that mutation's own tests. The file's header says which commit it ran on and
    whether it covered every mutation (a partial run lists what it reached).
    """
    recorded = mc.read_results()
    names = {m.name for m in mc.MUTATIONS}
    assert recorded, f"{mc.RESULTS.name} holds no outcome"
    assert set(recorded) <= names, f"outcomes of removed mutations: {set(recorded) - names}"
    for m in mc.MUTATIONS:
        if m.name in recorded:
            verdict, failed = recorded[m.name]
            assert verdict == "caught", f"{m.name}: {verdict} in the last recorded run"
            assert _caught_by_its_own_test(m, failed), f"{m.name}: caught by {failed}"


#: a mutation of plain Python (no numba recompile): the machinery's end-to-end check
CANARY = "ljung-box-n-plus-2"


def test_one_mutant_is_caught_end_to_end(tmp_path):
    """Copy, mutate, run the named tests in the copy: they fail (exit status 1)."""
    mutation = next(m for m in mc.MUTATIONS if m.name == CANARY)
    outcome = mc.run_mutant(mutation, tmp_path)
    assert outcome.caught, outcome.summary() + "\n" + outcome.output[-3000:]


def test_docs_list_every_mutation():
    # regenerate with: python tests/mutation_check.py --markdown
    text = (mc.ROOT / "docs" / "testing.md").read_text()
    assert mc.markdown_table() in text, "docs/testing.md's mutation table is out of date"
