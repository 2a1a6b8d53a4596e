"""An identification campaign: synthetic shaker records, resumable fits, their tables.

The pieces of a study that identifies friction models on records (paper
Sec. 3-4): :func:`synthetic_record` makes a shaker test from a known device,
with the sensor noise of the paper's rig, and :func:`shaker_test` test N of
a campaign on its own stream of the campaign's seed; :func:`identify_cached`
runs :func:`randvib.identify` once per (record, model) and keeps the fit on
disk, so that an interrupted campaign resumes, and :func:`identify_all` does
so for every model on every training record; :func:`cost_table`,
:func:`parameter_table` and :func:`recovery_table` tabulate the fits (paper
Figure 7, Table 2, exact recovery), :func:`figure7` draws the costs and
:func:`voltage_figures` the load voltage the fits predict with the paper's
coil (:func:`paper_coil`; Figure 8); :func:`write_records` and
:func:`write_fits` keep the records and the fits in the study's folder;
:func:`set_threads` sets the threads of the record simulations.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from randvib._io import atomic_write_text, dumps, write_tracked
from randvib.figure_style import save_figure
from randvib.identification.identify import identify
from randvib.identification.models import MODEL_PARAMETERS, device_from_parameters
from randvib.identification.plots import MODEL_STYLE, figure_costs, figure_fit
from randvib.identification.record_response import record_response
from randvib.identification.result import IdentificationResult
from randvib.models.coupling import Resistive
from randvib.models.excitation import band_limited_excitation
from randvib.models.presets import ALPHA, R_COIL
from randvib.models.record import Record

#: Every parameter name of the paper's four models, in Table 2's order.
PARAMETER_ORDER = ("c", "k", "k3", "fc", "beta", "sigma0", "sigma1", "fs", "vs")
#: The columns of :func:`voltage_figures`: the share of samples with |V| < 0.5 mV (the
#: spike at zero volts of sticking), in the simulated and in the measured voltage.
SIMULATED, MEASURED = "share |V| < 0.5 mV, simulated", "share |V| < 0.5 mV, measured"


def paper_coil(r_load: float) -> Resistive:
    """The paper's coil (alpha = 0.1992 Wb/m, R_C = 0.48 ohm, measured) with load ``r_load`` (ohm)."""
    return Resistive(ALPHA, r_load, R_COIL)


def synthetic_record(
    truth: dict, rms: float, *, duration: float, fs: float, rng, name: str,
    warmup: float = 2.0, noise: tuple | None = (1e-6, 2e-6, 1e-4), electrical=None,
) -> tuple[Record, np.ndarray]:  # fmt: skip
    """One synthetic shaker test of the Coulomb device ``truth``: (Record, true velocity).

    The base acceleration is band-limited Gaussian (4-20 Hz,
    :func:`randvib.band_limited_excitation`) of RMS ``rms`` (m/s^2); the
    truth is simulated with 8 sub-steps and starts ``warmup`` s before the
    record, so that the record begins mid-motion. The record holds what the
    paper's rig measured: the base displacement and the magnet's relative
    displacement, with white sensor noise of RMS ``noise`` = (base (m),
    relative (m), voltage (V)) (the LVDT's 1 um, the laser's 2 um, 0.1 mV),
    or none with ``noise=None``. ``electrical`` (a
    :class:`randvib.Resistive`) adds its damping c_e to the truth's
    c and records the load voltage. ``rng`` draws the excitation, then the
    noise.

    Parameters
    ----------
    truth : dict
        ``m`` (kg), ``c`` (Ns/m), ``k`` (N/m), ``k3`` (N/m^3), ``fc`` (N).
    """
    n_warm = int(round(warmup * fs))
    ex = band_limited_excitation(duration + warmup, fs, rms, seed=rng)
    device, _ = device_from_parameters("coulomb", truth, electrical)
    sim = record_response(device, ex, input_kind="base_acceleration", substeps=8)
    y = ex["base_displacement"][n_warm:]
    z = sim.z[0, n_warm:]
    v = sim.v[0, n_warm:]
    voltage = None
    if noise is not None:
        y = y + noise[0] * rng.standard_normal(y.size)
        z = z + noise[1] * rng.standard_normal(z.size)
    if electrical is not None:
        voltage = electrical.alpha * v * electrical.load_fraction
        if noise is not None:
            voltage = voltage + noise[2] * rng.standard_normal(v.size)
    record = Record(
        1 / fs, base_displacement=y, relative_displacement=z, voltage=voltage, name=name
    )
    return record, v


def shaker_test(truth: dict, rms: float, number: int, *, seed: int, **kwargs):
    """Test ``number`` of a campaign seeded ``seed``: :func:`synthetic_record` on its own stream.

    The stream is ``numpy.random.default_rng([seed, number])``: each test has
    its excitation and noise whatever other tests the campaign makes, and in
    whatever order. ``kwargs`` are :func:`synthetic_record`'s.
    """
    return synthetic_record(truth, rms, rng=np.random.default_rng([seed, number]), **kwargs)


def set_threads(threads: int | None) -> None:
    """numba threads of the batched record simulations: ``threads`` (at most what numba
    has), or left as set when None."""
    if threads is not None:
        import numba

        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def write_records(records: dict, folder: Path) -> None:
    """Each record as ``folder/testN.csv`` (usable with ``randvib identify``), unless there.

    ``records`` maps test numbers to :class:`~randvib.Record`.
    """
    Path(folder).mkdir(exist_ok=True)
    for n, record in records.items():
        if not (Path(folder) / f"test{n}.csv").exists():
            record.to_csv(Path(folder) / f"test{n}.csv")


def load_fit(path: Path) -> IdentificationResult:
    """An :class:`~randvib.IdentificationResult` saved as its ``to_dict()`` JSON
    (:meth:`~randvib.IdentificationResult.from_dict`: standard errors, intervals,
    residual diagnostics and the input's kind included)."""
    return IdentificationResult.from_dict(json.loads(Path(path).read_text()))


def identify_cached(path: Path, record: Record, model: str, **kwargs) -> IdentificationResult:
    """:func:`randvib.identify` of ``model`` on ``record``, kept at ``path`` (JSON).

    A fit already at ``path`` is loaded instead of run again, so that an
    interrupted campaign resumes where it stopped; one that cannot be read
    (truncated, edited into something else) is named in a warning and fitted
    again.
    """
    if Path(path).exists():
        try:
            return load_fit(path)
        except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
            warnings.warn(
                f"stored fit {str(path)!r} is unusable ({type(exc).__name__}: {exc}); fitting again",
                stacklevel=2,
            )
    result = identify(record, model, **kwargs)
    atomic_write_text(path, dumps(result.to_dict(), indent=2))
    return result


def identify_all(records: dict, models, folder: Path, **kwargs) -> dict:
    """Every model identified on every record, each fit kept in ``folder`` (resumable).

    ``records`` maps test numbers to :class:`~randvib.Record`; the fit of
    ``model`` on test N is :func:`identify_cached` at ``folder/testN-model.json``
    with ``kwargs`` (:func:`randvib.identify`'s). Returns
    ``{(test, model): IdentificationResult}``, test by test.
    """
    Path(folder).mkdir(exist_ok=True)
    return {(n, model): identify_cached(Path(folder) / f"test{n}-{model}.json", record, model,
                                        **kwargs)
            for n, record in records.items() for model in models}  # fmt: skip


def write_fits(path: Path, fits: dict) -> Path:
    """The fits of :func:`identify_all` as one JSON file, ``testN-model``: ``to_dict()``."""
    data = {f"test{t}-{m}": fit.to_dict() for (t, m), fit in fits.items()}
    return write_tracked(path, dumps(data, indent=2))


def cost_table(fits: dict, records: dict, rms: dict) -> pd.DataFrame:
    """J (Eq. 11) of every fit on every record (paper Figure 7).

    ``fits`` maps (training test, model) to an :class:`~randvib.IdentificationResult`,
    ``records`` test number to :class:`~randvib.Record`, ``rms`` test number to
    its RMS base acceleration (m/s^2).
    """
    rows = []
    for (train, model), fit in fits.items():
        for n, rec in records.items():
            rows.append(
                dict(
                    training_test=train,
                    model=model,
                    test=n,
                    rms_acceleration=rms[n],
                    J=fit.predict(rec).cost,
                )
            )
    return pd.DataFrame(rows)


def cost_matrix(costs: pd.DataFrame) -> pd.DataFrame:
    """:func:`cost_table` as one row per (training test, model), one column per test."""
    pivot = costs.pivot_table(
        index=["training_test", "model"], columns="test", values="J"
    ).reset_index()
    pivot.columns = [str(c) if isinstance(c, int | np.integer) else c for c in pivot.columns]
    return pivot


def parameter_table(fits: dict, models, training, truth: dict) -> pd.DataFrame:
    """Identified parameters beside the truth (paper Table 2), with each fit's J.

    One row per (model, parameter) and a last row ``J (training)`` per model;
    one column ``test N`` per training test.
    """
    table = []
    for model in models:
        for name in MODEL_PARAMETERS[model]:
            row = {"model": model, "parameter": name, "truth": truth.get(name, np.nan)}
            for train in training:
                row[f"test {train}"] = fits[(train, model)].parameters[name]
            table.append(row)
        row = {"model": model, "parameter": "J (training)", "truth": np.nan}
        for train in training:
            row[f"test {train}"] = fits[(train, model)].cost
        table.append(row)
    table = pd.DataFrame(table)
    order = list(PARAMETER_ORDER) + ["J (training)"]
    table["parameter"] = pd.Categorical(table["parameter"], order, ordered=False)
    return table


def recovery_table(fit: IdentificationResult, truth: dict, names=("c", "k", "k3", "fc")):
    """Identified against true parameters, with the error in percent."""
    return pd.DataFrame(
        [
            dict(
                parameter=n,
                truth=truth[n],
                identified=fit.parameters[n],
                error_percent=100 * (fit.parameters[n] / truth[n] - 1),
            )
            for n in names
        ]
    )


def share_near_zero(voltage, threshold: float = 5e-4) -> float:
    """Share of samples with |V| < ``threshold`` (V): the spike at zero volts of sticking."""
    return float(np.mean(np.abs(voltage) < threshold))


def figure7(costs: pd.DataFrame, models, training, path: Path) -> Path:
    """J of every fit on every test, one panel per training test (paper Figure 7).

    ``costs`` is :func:`cost_table`'s; ``training`` the training tests' numbers.
    """
    per_fit = {f"test {t}": {m: costs.J[(costs.training_test == t) & (costs.model == m)].tolist()
                             for m in models} for t in training}  # fmt: skip
    titles = {f"test {t}": f"trained on test {t}" for t in training}
    tests = sorted(costs.test.unique().tolist())
    return save_figure(figure_costs(per_fit, tests, titles=titles), path)


def voltage_figures(fits: dict, wired, electrical, out: Path, *, trained_on: str) -> pd.DataFrame:
    """The load voltage each fit predicts on records taken with the coil (paper Figure 8).

    Parameters
    ----------
    fits : dict
        Model -> :class:`~randvib.IdentificationResult` (identified without
        the coil; ``electrical`` is added to its c).
    wired : sequence of (tag, label, rms, Record)
        Records with the load voltage: a file tag, words and the RMS base
        acceleration (m/s^2) for the title and the table.
    electrical : Resistive
    out : Path
        Folder of the figures ``figure8_{tag}_{model}.png`` (time history and
        densities, :func:`randvib.identification.plots.figure_fit`).
    trained_on : str
        Where the fits come from, for the titles ("test 3").

    Returns
    -------
    DataFrame
        One row per record and model: ``excitation``, ``model``, ``J`` (Eq. 11)
        and the shares :data:`SIMULATED` and :data:`MEASURED`.
    """
    rows = []
    for tag, label, rms, record in wired:
        for model, fit in fits.items():
            prediction = fit.predict(record, electrical=electrical)
            name = MODEL_STYLE.get(model, {}).get("label", model)  # "Coulomb", as in the legends
            title = (f"{label} ({rms:g} m/s$^2$ RMS), coil with R$_L$ = {electrical.r_load:g}"
                     f" Ω: {name} model identified on {trained_on}")  # fmt: skip
            figure = figure_fit(prediction, window=(0, 2), scale=1e3, unit="mm", title=title)
            save_figure(figure, Path(out) / f"figure8_{tag}_{model}.png")
            rows.append({"excitation": f"{label}, {rms:g} m/s^2", "model": model,
                         "J": prediction.cost, SIMULATED: share_near_zero(prediction.voltage),
                         MEASURED: share_near_zero(record.voltage)})  # fmt: skip
    return pd.DataFrame(rows)
