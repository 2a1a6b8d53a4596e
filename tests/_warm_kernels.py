"""Compile (or load) every numba signature the test suite uses, with tiny runs.

The suite's compiled kernels (``cache=True``) cost 30-100 CPU-s each on a cold
cache; on two pytest-xdist workers the same one was often compiled twice at
once. ``tests/conftest.py`` runs the two halves below in parallel
subprocesses before the workers start (``pytest_sessionstart``), so that the
workers find a warm cache; the halves are balanced by compile time:

* ``single``: the full loop of :func:`randvib.montecarlo.kernel.run_ensemble`
  (filter or circuit, event, bridge, tones and shocks in one signature), run on
  every combination the suite uses so that a new signature would show up, and
  the record simulation behind a bridge (:mod:`randvib.identification.record_bridge`);
  93 CPU-s cold (November 2026; the assembly half 100);
* ``assembly``: that function's lean loop (white noise, nothing optional), the
  assembly kernel (:mod:`randvib.montecarlo.assembly_kernel`), the record
  integrator of the identification
  (:mod:`randvib.identification.record_integrator`) and the rare-event linear
  surrogate's responses (:mod:`randvib.montecarlo.path_simulator`).

The halves share no kernel: two processes compiling the same one would each
spend its full compile time.

Run by hand: ``python tests/_warm_kernels.py single`` (or ``assembly``, or
both names). A compilation during the tests that is not covered here is
listed in the terminal summary ("compiled during the tests"): add it here.
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

#: A linear device (the paper's, m assumed) and short runs: compiling is the cost, not running.
M, C_M, C_E, K = 0.0226, 0.1, 0.1, 57.4
SHORT = dict(t_end=0.02, dt=1e-3, burn_in=0.01, n_paths=2, progress=False)


def _harvester(**kw):
    import randvib as rv

    return rv.Harvester(m=M, c_m=C_M, c_e=C_E, k=K, **kw)


def _bridge():
    import randvib as rv

    return rv.Harvester.with_coupling(M, 0.05, K, rv.BridgeCoil(0.1992, 0.48, battery=0.1))


def warm_single() -> None:
    """Every combination of :func:`~randvib.montecarlo.kernel.run_ensemble`'s groups in the suite.

    The full loop only: the lean one (white noise, nothing optional) is the other half's;
    and the record simulation behind a bridge.
    """
    import randvib as rv

    band = rv.BandPass(1.0, 8.0, 0.2)
    tone = rv.Tone(25.0, 0.5)
    step = rv.Step()
    rv.simulate(_harvester(), band, **SHORT)  # filter
    rv.simulate(_harvester(), rv.White(1.0) + tone, **SHORT)  # tones
    rv.simulate(_harvester(), band + tone, **SHORT)  # filter and tones
    rv.simulate(_bridge(), 1.0, **SHORT)  # bridge
    rv.simulate(_bridge(), band, **SHORT)  # bridge and filter
    rv.simulate(_bridge(), rv.White(1.0) + tone, **SHORT)  # bridge and tones
    rv.simulate_transient(_harvester(), rv.Enveloped(rv.White(1.0), step), t_end=0.02,
                          dt=1e-3, n_paths=2)  # fmt: skip
    rv.simulate_transient(_harvester(), rv.Enveloped(band, step), t_end=0.02, dt=1e-3,
                          n_paths=2)  # fmt: skip
    # the record simulation behind a diode bridge (identification.record_bridge), here
    # to even the halves: 12 CPU-s of compiling
    bridge = rv.BridgeCoil(alpha=1.0, r_coil=2.0, v_diode=0.2, storage_capacitance=2e-3,
                           r_load=50.0)  # fmt: skip
    device = rv.Harvester.with_coupling(M, C_M, K, bridge)
    drive = np.sin(np.linspace(0.0, 1.0, 32))
    rv.record_response(device, rv.Record(1e-4, base_acceleration=drive), substeps=1)


def warm_assembly() -> None:
    """The lean single-mass loop, the assembly kernel, the record integrator, the surrogate."""
    import randvib as rv
    from randvib.identification.record_integrator import parameter_matrix, run_kernel

    h = _harvester(friction=rv.Coulomb(0.01))
    rv.simulate(_harvester(), 1.0, **SHORT)  # the single mass's lean loop
    # the rare-event estimators' paths: the lean loop with given starting states
    rv.first_passage(_harvester(), 1.0, duration=0.02, stroke=1e-5, method="crude",
                     target_cov=0.9, dt=1e-3, progress=False)  # fmt: skip
    rv.simulate(rv.Assembly.from_harvester(h), 1.0, **SHORT)
    matrix = parameter_matrix({"m": M, "c": C_M, "k": K, "k3": 0.0}, None)
    drive = np.sin(np.linspace(0.0, 1.0, 32))
    run_kernel(matrix, None, drive, True, 1e-3, reference=np.zeros(32))
    # importance sampling's linear surrogate: z_n of the linearised device, per row
    from randvib.montecarlo.path_simulator import HarvesterPaths

    paths = HarvesterPaths(_harvester(), 1.0, stroke=1e-3, duration=0.02, dt=1e-3)
    surrogate = paths.linear_surrogate
    surrogate.responses(np.zeros((2, surrogate.n_start + surrogate.n_steps)))


HALVES = {"single": warm_single, "assembly": warm_assembly}


def main(names) -> int:
    """Run the named halves (all without names); print how long each took."""
    for name in names or list(HALVES):
        started = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            HALVES[name]()
        print(f"warm {name}: {time.perf_counter() - started:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
