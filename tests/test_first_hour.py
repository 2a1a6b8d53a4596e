"""What a new user meets in the first hour: results that convert, messages that lead.

Covers the step check's refusal (:mod:`randvib.montecarlo.step_check`), file
modes of written outputs (:mod:`randvib._io`, see also tests/test_output_files.py),
and the refusals of the CLI's option parsing and checks
(:mod:`randvib.cli.power`, :mod:`randvib.cli.identify`).
"""

import warnings

import pytest

import randvib as rv


def test_unstable_step_is_called_unstable_not_off_by_inf():
    """Euler-Maruyama at a step beyond its stability limit: the refusal says unstable,
    gives a finite step, and no scipy warning comes before it."""
    h = rv.Harvester(m=0.0226, c_m=0.001, c_e=0.0, k=5740.0, k3=7e4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError) as info:
            rv.simulate(h, 0.005, scheme="euler-maruyama", dt=5e-4, t_end=1.0, n_paths=2)
    message = str(info.value)
    assert "unstable" in message and "inf" not in message, message
    assert "use dt <=" in message
