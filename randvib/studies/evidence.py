"""How many independent pieces of evidence a study's points are.

Without the Duffing spring (k3 = 0) the equation of motion is linear in
(z, Fc, sqrt(S)): a point at noise PSD S and Coulomb force Fc, simulated
on the same noise paths as a point at S' and Fc sqrt(S'/S), gives exactly
the same motion scaled by sqrt(S/S'), and the power scaled by S/S'. Such
rows repeat one experiment; counting them as separate confirmations would
overstate the evidence. :func:`rescaling_groups` finds them in a table (it
checks the rescaling on the numbers, it does not assume it), and
:func:`independent_count` counts the groups.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

#: Device columns that must agree for two rows to be rescalings of each other.
_DEVICE_COLUMNS = ("k3", "c_m", "c_e", "m", "k", "zeta")


def rescaling_groups(
    table: pd.DataFrame, value: str = "power_electrical", rtol: float = 1e-9
) -> np.ndarray:
    """A group label per row; rows that are exact rescalings of each other share one.

    Two rows are grouped when both have k3 = 0, the same device columns,
    the same Fc / sqrt(S), and the same ``value`` / S to ``rtol`` (the
    power scales with S exactly when the same paths are rescaled).

    Parameters
    ----------
    table : DataFrame
        Rows with ``psd`` ((m/s^2)^2/Hz), ``fc`` (N), ``k3`` (N/m^3) and ``value`` (W);
        without a ``value`` column every row is its own group.
    value : str
        The column whose rescaling is checked.
    rtol : float
        Relative tolerance of "the same" (rounding only).

    Returns
    -------
    ndarray of int
        ``labels[i] == labels[j]`` where rows i and j are one piece of evidence.
    """
    labels = np.arange(len(table))
    if len(table) == 0 or value not in table:
        return labels
    rows = table.reset_index(drop=True)
    device = [c for c in _DEVICE_COLUMNS if c in rows]
    scaled_fc = rows.fc.to_numpy(float) / np.sqrt(rows.psd.to_numpy(float))
    scaled_value = rows[value].to_numpy(float) / rows.psd.to_numpy(float)
    for i in range(len(rows)):
        if rows.k3.iloc[i] != 0 or labels[i] != i:
            continue
        for j in range(i + 1, len(rows)):
            same_device = all(rows[c].iloc[i] == rows[c].iloc[j] for c in device)
            if (
                same_device
                and labels[j] == j
                and np.isclose(scaled_fc[i], scaled_fc[j], rtol=rtol, atol=0.0)
                and np.isclose(scaled_value[i], scaled_value[j], rtol=rtol, atol=0.0)
            ):
                labels[j] = labels[i]
    return labels


def independent_count(table: pd.DataFrame, value: str = "power_electrical") -> int:
    """The number of independent pieces of evidence among the rows of ``table``."""
    return len(set(rescaling_groups(table, value).tolist()))


def independence_note(n_rows: int, n_independent: int, what: str = "points") -> str:
    """'' when every row is independent, else '; the k3 = 0 rows ... are N independent pieces
    of evidence' (to close a parenthesis with)."""
    if n_independent == n_rows:
        return ""
    return (
        f"; the k3 = 0 rows at different S are exact rescalings of the same noise paths, so "
        f"these {n_rows} {what} are {n_independent} independent pieces of evidence"
    )
