"""Self-adaptive differential evolution (randvib.identification.sade)."""

import numpy as np
import pytest

from randvib.identification.sade import sade


def sphere(x):
    return np.sum((x - 0.3) ** 2, axis=1)


def rosenbrock(x):
    return np.sum(100 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1 - x[:, :-1]) ** 2, axis=1)


def rastrigin(x):
    return 10 * x.shape[1] + np.sum(x**2 - 10 * np.cos(2 * np.pi * x), axis=1)


@pytest.mark.parametrize(
    "func, d, lo, hi, xstar, gens, tol",
    [
        (sphere, 5, -5.0, 5.0, 0.3, 150, 1e-6),
        (rosenbrock, 4, -2.0, 2.0, 1.0, 600, 1e-3),
        (rastrigin, 4, -5.12, 5.12, 0.0, 400, 1e-4),
    ],
)
def test_standard_functions(func, d, lo, hi, xstar, gens, tol):
    res = sade(func, [(lo, hi)] * d, popsize=40, maxiter=gens, seed=1, tol=0)
    np.testing.assert_allclose(res.x, xstar, atol=tol**0.5 * 3)
    assert res.fun < tol
    assert res.nfev == 40 * (res.nit + 1)


def test_seeded_and_reproducible():
    a = sade(rosenbrock, [(-2, 2)] * 3, popsize=20, maxiter=30, seed=5, tol=0)
    b = sade(rosenbrock, [(-2, 2)] * 3, popsize=20, maxiter=30, seed=5, tol=0)
    np.testing.assert_array_equal(a.x, b.x)
    assert a.history["best"] == b.history["best"]
    assert all(x >= y for x, y in zip(a.history["best"], a.history["best"][1:], strict=False))


def test_log_scaled_parameter_spanning_decades():
    # minimum at 3e-7 inside [1e-9, 1e-1]: found on a log scale in few generations
    target = np.array([3e-7, 2.0])

    def cost(x):
        return (np.log(x[:, 0] / target[0])) ** 2 + (x[:, 1] - target[1]) ** 2

    res = sade(cost, [(1e-9, 1e-1), (0, 5)], log=[True, False], popsize=20, maxiter=100, seed=0)
    assert res.x[0] == pytest.approx(3e-7, rel=1e-3)
    assert np.all(res.population[:, 0] >= 1e-9) and np.all(res.population[:, 0] <= 1e-1)


def test_bounds_respected_and_fixed_parameter():
    seen = []

    def cost(x):
        seen.append(x.copy())
        return sphere(x)

    sade(cost, [(0.5, 1.0), (2.0, 2.0), (-1, 1)], popsize=10, maxiter=20, seed=2)
    allx = np.concatenate(seen)
    assert allx[:, 0].min() >= 0.5 and allx[:, 0].max() <= 1.0
    assert np.all(allx[:, 1] == 2.0)


def test_convergence_stop_and_polish():
    res = sade(sphere, [(-5, 5)] * 2, popsize=20, maxiter=1000, seed=3, tol=1e-3)
    assert res.message.startswith("converged") and res.nit < 1000
    pol = sade(sphere, [(-5, 5)] * 2, popsize=20, maxiter=20, seed=3, polish=True)
    assert pol.fun <= min(pol.history["best"])
    assert pol.fun < 1e-8


def test_non_finite_costs_are_worst():
    def cost(x):
        out = sphere(x)
        out[x[:, 0] > 0] = np.nan
        return out

    res = sade(cost, [(-1, 1), (-1, 1)], popsize=12, maxiter=50, seed=4)
    assert np.isfinite(res.fun) and res.x[0] <= 0


def test_callback_and_patience():
    calls = []
    res = sade(sphere, [(-1, 1)] * 2, popsize=10, maxiter=50, seed=0,
               callback=lambda g, x, f: calls.append(g) or g == 3)  # fmt: skip
    assert res.nit == 3 and res.message == "stopped by callback"
    flat = sade(
        lambda x: np.ones(len(x)),
        [(-1, 1)],
        popsize=8,
        maxiter=100,
        seed=0,
        tol=0,
        atol=-1,
        patience=5,
    )
    assert flat.nit == 6 and "no improvement" in flat.message


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(bounds=[(1.0, 0.0)], names=["k"]), r"bounds for `k`: lower 1.0 > upper 0.0"),
        (dict(bounds=[(0.0, 1.0)], log=[True], names=["beta"]), "log-scaled and must be > 0"),
        (dict(bounds=[(0.0, np.inf)]), "must be finite"),
        (dict(popsize=3), "`popsize` must be an integer >= 6"),
        (dict(init=np.zeros((2, 3))), "`init` must have shape"),
    ],
)
def test_bad_arguments(kwargs, match):
    args = dict(bounds=[(0.0, 1.0)], popsize=8, maxiter=2)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        sade(sphere, **args)
