"""The assembly kernel's energy-balance bias against its time step (run by hand).

python tests/calibration/assembly_energy_balance.py [out.txt]

The nonlinear three-DOF assembly of tests/test_assembly_simulation.py
(``SPEC``: Duffing + Coulomb, LuGre + quadratic spring, tanh damper, coil,
piezo, coil bridge into a battery, a bare c_e) under white noise S = 0.2,
Heun, 64 paths x 0.6 s from rest (0.1 s burn-in), seed 9, with the
energy-balance control variates, at dt = 4e-5, 2e-5 and 1e-5 s. Each row:
dt, the input power r^T M r S / 4, all dissipation, and the residual and its
standard error as fractions of the input power. The residual at dt = 2e-5 s
is the scheme's own bias that test_energy_balance_of_the_nonlinear_assembly
tolerates; the last results are kept in ``assembly_energy_balance.txt``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from test_assembly_simulation import SPEC, assembly_of  # noqa: E402

import randvib as rv  # noqa: E402


def main(argv) -> None:
    warnings.simplefilter("ignore")
    lines = ["dt (s)    input (W)   dissipated (W)  residual/input  std error/input"]
    for dt in (4e-5, 2e-5, 1e-5):
        r = rv.simulate(
            assembly_of(SPEC), 0.2, t_end=0.6, dt=dt, n_paths=64, burn_in=0.1, seed=9,
            progress=False, control_variates=True, initial="rest", check_step=False,
        )  # fmt: skip
        res = r.energy_balance_residual()
        lines.append(
            f"{dt:<9.1e} {r.power_input:<11.5g} {r.power_dissipated.mean:<15.6g} "
            f"{res.mean / r.power_input:<+15.4%} {res.std_error / r.power_input:.4%}"
        )
        print(lines[-1])
    if len(argv) > 1:
        Path(argv[1]).write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main(sys.argv)
