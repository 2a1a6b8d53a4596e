"""Records: channels sampled on one uniform time grid, and their CSV reader.

A record is what a test rig writes: samples of a few signals (channels) taken
at the times ``t_i = t_0 + i dt``. One class, :class:`Record`, holds every
kind randvib uses:

* a shaker test for identification: an input channel (base displacement, base
  acceleration or force) and the relative displacement, perhaps the load
  voltage (:func:`randvib.identify`, :func:`randvib.predict_record`);
* a measured base acceleration that drives the device
  (:class:`randvib.Measured`, the excitation, is built from one);
* one realisation of band-limited base motion, its acceleration, velocity and
  displacement (:func:`randvib.band_limited_excitation`).

Channels are named by what they hold, in SI units (:data:`CHANNELS`); the
names are the CSV columns that :func:`read_record` reads and
:meth:`Record.to_csv` writes, beside a ``time`` column (s).

**The time grid.** Every consumer places sample i at ``t_0 + i dt``: the
record simulation reconstructs the input between samples on that grid, Welch's
PSD and the Monte Carlo windows assume it. Sample times are therefore accepted
when each lies within :data:`GRID_TOLERANCE` (1 %) of a step of that grid,
with ``dt = (t_last - t_0) / (n - 1)``. A sample 1 % of a step off shifts a
component at frequency f by 2 pi f (0.01 dt), at most 0.03 rad at the Nyquist
frequency, while a time column written with a few digits fewer than the
samples, or with the rounding of a logger's clock, still passes; a dropped or
repeated sample (a whole step) does not. The same rule checks a sample rate
given beside a time column: every sample must lie within 1 % of a step of the
grid that rate gives.
"""

from __future__ import annotations

from pathlib import Path
from types import MappingProxyType

import numpy as np

from randvib._io import existing_file
from randvib._validation import check_positive
from randvib.quantities import QUANTITIES

#: Channel name -> its :class:`~randvib.quantities.Quantity` (SI unit, what it
#: holds); the CSV column names of a record.
CHANNELS = {
    name: QUANTITIES[name]
    for name in (
        "base_acceleration",
        "base_velocity",
        "base_displacement",
        "force",
        "relative_displacement",
        "relative_velocity",
        "voltage",
        "current",
    )
}
#: The channels that can drive the device (paper Eq. 1: -m y'' or a force u).
INPUT_KINDS = ("base_displacement", "base_acceleration", "force")
#: The response channel that identification fits.
OUTPUT_CHANNEL = "relative_displacement"
#: The response channels a record's CSV may hold: what an output column may be
#: declared to hold (``output_kind``, ``outputs``, ``--output-kind``); the output
#: kinds of identification.
OUTPUT_KINDS = ("relative_displacement", "relative_velocity", "voltage", "current")
#: The CSV column of the sample times (s).
TIME_COLUMN = "time"
#: How far (in steps) a sample may lie from the uniform grid; see the module docstring.
GRID_TOLERANCE = 0.01
#: Fewest samples of a record: the five-point stencils (the initial velocity,
#: the second derivative of a base displacement) need five.
MIN_SAMPLES = 5


class Record:
    """Channels sampled on one uniform time grid (the CSV columns of a test).

    Parameters
    ----------
    dt : float, optional
        Sample interval (s), > 0; the times are then ``i dt``.
    time : array_like, optional
        Sample times (s), evenly spaced (see the module docstring); with
        ``dt`` as well, they must lie on the grid of step ``dt``, which is
        then the record's step.
    name : str
        Label used in tables, plots and messages.
    **channels : array_like
        One-dimensional, finite samples of equal length, at least
        :data:`MIN_SAMPLES`, named as in :data:`CHANNELS` (``base_acceleration``
        m/s^2, ``base_velocity`` m/s, ``base_displacement`` m, ``force`` N,
        ``relative_displacement`` m, ``voltage`` V). A channel given as None
        is left out.

    Examples
    --------
    >>> import numpy as np
    >>> import randvib as rv
    >>> t = np.arange(500) * 2e-3
    >>> record = rv.Record(time=t, base_acceleration=np.sin(2 * np.pi * 8 * t), name="sine")
    >>> record
    Record('sine': 500 samples at 500 Hz, 1 s; base_acceleration)
    >>> record.input_kind, record.dt
    ('base_acceleration', 0.002)
    """

    __slots__ = ("_dt", "_time", "_channels", "_name")

    def __init__(self, dt=None, *, time=None, name: str = "record", **channels):
        unknown = [key for key in channels if key not in CHANNELS]
        if unknown:
            raise ValueError(
                f"unknown channel(s) {', '.join(map(repr, unknown))} of record {name!r}; a "
                f"record's channels are {', '.join(CHANNELS)}"
            )
        data = {key: _finite_column(key, channels[key]) for key in CHANNELS if key in channels}
        data = {key: value for key, value in data.items() if value is not None}
        if not data:
            raise ValueError(f"record {name!r} has no channel; give one of {', '.join(CHANNELS)}")
        sizes = {key: value.size for key, value in data.items()}
        n = next(iter(sizes.values()))
        if len(set(sizes.values())) > 1:
            lengths = ", ".join(f"`{key}` {size}" for key, size in sizes.items())
            raise ValueError(f"the channels of record {name!r} differ in length: {lengths}")
        _check_length(n, name)
        if time is None:
            if dt is None:
                raise ValueError(
                    f"record {name!r} needs its sample interval `dt` (s) or its sample times "
                    "`time` (s)"
                )
            dt = float(check_positive("dt", dt, "s"))
            time = np.arange(n) * dt
        else:
            time = _finite_column(TIME_COLUMN, time)
            if time.size != n:
                raise ValueError(
                    f"`time` of record {name!r} has {time.size} samples, its channels {n}"
                )
            if dt is not None:
                dt = float(check_positive("dt", dt, "s"))
            dt = grid_step(time, dt)
        self._set(dt, time, data, name)

    def _set(self, dt, time, data, name):
        object.__setattr__(self, "_dt", dt)
        object.__setattr__(self, "_time", time)
        object.__setattr__(self, "_channels", data)
        object.__setattr__(self, "_name", str(name))

    def __setattr__(self, key, value):
        raise AttributeError(f"a Record is immutable; {key!r} cannot be set")

    def __reduce__(self):  # pickling (process pools) without __setattr__
        return (_restored, (self._dt, self._time, self._channels, self._name))

    # ----------------------------------------------------------------- grid
    @property
    def dt(self) -> float:
        """Sample interval (s)."""
        return self._dt

    @property
    def time(self) -> np.ndarray:
        """Sample times (s)."""
        return self._time

    @property
    def n(self) -> int:
        """Number of samples."""
        return self._time.size

    @property
    def sample_rate(self) -> float:
        """Samples per second (Hz)."""
        return 1.0 / self._dt

    @property
    def name(self) -> str:
        return self._name

    # ------------------------------------------------------------- channels
    @property
    def channels(self):
        """Channel name -> samples (read-only mapping, in the order of :data:`CHANNELS`)."""
        return MappingProxyType(self._channels)

    def __contains__(self, channel) -> bool:
        return channel in self._channels

    def __getitem__(self, channel) -> np.ndarray:
        if channel not in self._channels:
            raise KeyError(
                f"record {self._name!r} has no {channel!r} channel; it has "
                f"{', '.join(self._channels)}"
            )
        return self._channels[channel]

    @property
    def input_kind(self) -> str:
        """The record's input channel: ``base_displacement``, ``base_acceleration`` or ``force``.

        Raises
        ------
        ValueError
            If the record has none or several of them.
        """
        kinds = [kind for kind in INPUT_KINDS if kind in self._channels]
        if len(kinds) != 1:
            has = "no input channel" if not kinds else f"several input channels {kinds}"
            raise ValueError(
                f"record {self._name!r} has {has}; a record that drives the device has one of "
                f"{', '.join(INPUT_KINDS)}"
                + ("" if not kinds else " (choose one with `input_kind`)")
            )
        return kinds[0]

    @property
    def input(self) -> np.ndarray:
        """Samples of the input channel (:attr:`input_kind`, in its unit)."""
        return self._channels[self.input_kind]

    @property
    def z(self) -> np.ndarray:
        """The measured relative displacement z (m): the ``relative_displacement`` channel."""
        try:
            return self[OUTPUT_CHANNEL]
        except KeyError as missing:
            raise ValueError(
                f"{missing.args[0]}; identification fits the relative displacement"
            ) from None

    @property
    def voltage(self) -> np.ndarray | None:
        """The measured load voltage (V), or None when not recorded."""
        return self._channels.get("voltage")

    # ------------------------------------------------------------ derived
    def rows(self, start=None, stop=None, name=None) -> Record:
        """The samples ``start:stop`` (at their own times) as a new record."""
        sl = slice(start, stop)
        name = name or f"{self._name}[{start or 0}:{'' if stop is None else stop}]"
        time = self._time[sl]
        _check_length(time.size, name)
        # the samples' own times on the parent's grid: not checked again (a slice
        # of a record within tolerance may lie up to twice as far from its own start)
        return _restored(self._dt, time, {k: v[sl] for k, v in self._channels.items()}, name)

    def to_frame(self):
        """The record as a DataFrame: ``time`` and the channels, the CSV column names."""
        import pandas as pd

        return pd.DataFrame({TIME_COLUMN: self._time, **self._channels})

    def to_csv(self, path, *, overwrite: bool = False, float_format: str | None = "%.10g") -> None:
        """Write the record as the CSV :func:`read_record` reads.

        Parameters
        ----------
        path : path-like
        overwrite : bool
            Replace an existing file (refused by default).
        float_format : str or None
            Number format; None writes every float exactly (shortest
            round-trip representation), so the samples read back bit for bit.
        """
        path = Path(path)
        if path.exists() and not overwrite:
            raise FileExistsError(
                f"{str(path)!r} exists; records are not overwritten unless asked (overwrite=True)"
            )
        self.to_frame().to_csv(path, index=False, float_format=float_format)

    def __repr__(self) -> str:  # the record's size, not its samples
        duration = self.n * self._dt
        return (
            f"Record({self._name!r}: {self.n} samples at {self.sample_rate:.6g} Hz, "
            f"{duration:.6g} s; {', '.join(self._channels)})"
        )


def _channel_accessor(name: str) -> property:
    """``record.NAME``: the channel's samples, as ``record[NAME]``; the repr names them so."""

    def get(self) -> np.ndarray:
        if name not in self._channels:
            raise AttributeError(
                f"record {self._name!r} has no {name!r} channel; it has {', '.join(self._channels)}"
            )
        return self._channels[name]

    quantity = CHANNELS[name]
    get.__doc__ = (
        f"The ``{name}`` channel ({quantity.unit}); AttributeError when the record has none."
    )
    return property(get)


# every channel by the name the repr and the CSV give it (``voltage`` and ``z`` are above)
for _name in CHANNELS:
    if _name != "voltage":
        setattr(Record, _name, _channel_accessor(_name))
del _name


def _check_length(n: int, name: str) -> None:
    if n < MIN_SAMPLES:
        raise ValueError(f"record {name!r} has {n} samples; at least {MIN_SAMPLES} are needed")


def _restored(dt, time, channels, name) -> Record:
    """A record from checked parts (a slice, an unpickled copy)."""
    out = object.__new__(Record)
    out._set(dt, time, dict(channels), name)
    return out


def grid_step(time: np.ndarray, dt: float | None = None, *, name=TIME_COLUMN, source=None):
    """The step (s) of sample times on a uniform grid, checked (module docstring).

    Parameters
    ----------
    time : ndarray
        Finite sample times (s), at least two.
    dt : float, optional
        The grid's step, when given separately (a sample rate); default
        ``(t_last - t_0) / (n - 1)``.
    name : str
        The times' name in messages (a CSV column).
    source : str, optional
        What gave ``dt``, named in the message when the times disagree with it.
    """
    if dt is None:
        dt = (time[-1] - time[0]) / (time.size - 1)
        if not dt > 0:
            raise ValueError(
                f"`{name}` must increase, got {float(time[0])!r} s to {float(time[-1])!r} s"
            )
    off = np.abs(time - (time[0] + dt * np.arange(time.size)))
    i = int(np.argmax(off))
    if off[i] > GRID_TOLERANCE * dt:
        where = (
            f"sample {i} is at {float(time[i])!r} s, {off[i]:.3g} s off the uniform grid of "
            f"step {dt:.6g} s (allowed: {100 * GRID_TOLERANCE:g} % of a step)"
        )
        if source is not None:
            raise ValueError(f"{source} disagrees with `{name}`: {where}")
        raise ValueError(f"`{name}` must be evenly spaced: {where}; resample the record")
    return float(dt)


def _finite_column(name, values):
    """One channel as a 1-D float array (None passes), refused with its first bad sample."""
    if values is None:
        return None
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be numeric") from None
    if arr.ndim != 1:
        row = (
            " (one row of a batch: take it with [0], or BatchSimulation.to_record())"
            if arr.ndim == 2 and arr.shape[0] == 1
            else ""
        )
        raise ValueError(f"`{name}` must be one-dimensional, got shape {arr.shape}{row}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(
            f"`{name}` must be finite: {bad.size} NaN or infinite sample(s), first at sample "
            f"{bad[0]} (value {arr[bad[0]]!r}); clean or cut the record"
        )
    return arr


# --------------------------------------------------------------------- CSV
def read_csv(path, what: str = "record file"):
    """A CSV file as a DataFrame with string column names (never modified).

    ``what`` names the file in messages. A folder, a missing file and a file
    that is not CSV are refused.
    """
    import pandas as pd

    path = existing_file(path, what)
    _check_text_file(path, what)
    try:
        frame = pd.read_csv(path)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read {str(path)!r} as CSV: {exc}") from None
    frame.columns = [str(c) for c in frame.columns]
    return frame


#: Bytes read at each end of a CSV file to tell text from binary before parsing it.
SNIFF_BYTES = 65536
#: Memory a parsed CSV needs, in bytes per byte of file (pandas' buffers and columns).
PARSE_BYTES_PER_BYTE = 4.0


def _check_text_file(path: Path, what: str) -> None:
    """Refuse, before parsing, a file that is binary (or sparse) or too large to parse here.

    The work is bounded by the file's size: its two ends are read (a NUL byte
    is in no CSV text, and a sparse or binary file has them), and the memory
    that parsing needs is compared with what is available.
    """
    from randvib._resources import check_memory, size_text

    size = path.stat().st_size
    with open(path, "rb") as f:
        head = f.read(SNIFF_BYTES)
        tail = b""
        if size > 2 * SNIFF_BYTES:
            f.seek(size - SNIFF_BYTES)
            tail = f.read(SNIFF_BYTES)
    if b"\x00" in head or b"\x00" in tail:
        raise ValueError(
            f"{what} {str(path)!r} ({size_text(size)}) is not a CSV text file: it holds NUL "
            "bytes (a binary, sparse or corrupted file)"
        )
    check_memory(
        f"reading {what} {str(path)!r} ({size_text(size)})",
        PARSE_BYTES_PER_BYTE * size,
        "cut the file into shorter records",
    )


def _shown(columns, limit: int = 8, width: int = 24) -> str:
    """Column names for a one-line message: at most ``limit``, each cut to ``width`` chars."""
    names = [c if len(c) <= width else c[: width - 3] + "..." for c in map(str, columns)]
    more = f" and {len(names) - limit} more" if len(names) > limit else ""
    return repr(names[:limit]) + more


def read_record(
    path,
    *,
    input_column: str | None = None,
    input_kind: str | None = None,
    output_column: str | None = OUTPUT_CHANNEL,
    output_kind: str | None = None,
    time_column: str = TIME_COLUMN,
    sample_rate: float | None = None,
    rows: tuple[int | None, int | None] | None = None,
    name: str | None = None,
    outputs: dict | None = None,
) -> Record:
    """Read a record from CSV (the file is only read, never modified).

    The CSV needs a time column (s, evenly spaced) or ``sample_rate``; one
    input column named ``base_displacement`` (m), ``base_acceleration``
    (m/s^2) or ``force`` (N); and ``relative_displacement`` (m) unless
    ``output_column`` is None. Other names are mapped with
    ``input_column``/``input_kind`` and ``output_column``. A ``voltage``
    column (V), if any, is read too.

    Parameters
    ----------
    path : path-like
    input_column : str, optional
        Column holding the input; its kind is its name unless ``input_kind``
        is given.
    input_kind : {'base_displacement', 'base_acceleration', 'force'}, optional
    output_column : str or None
        Column holding the response (the relative displacement unless
        ``output_kind`` or its name says otherwise); None for a record of the
        input alone (a measured base acceleration, :meth:`randvib.Measured.from_csv`).
    output_kind : {'relative_displacement', 'relative_velocity', 'voltage', 'current'}, optional
        What ``output_column`` holds, declared; needed for a column whose name
        is not an output kind (``V2``, ``laser``: its values are then used in
        the column's own units). Undeclared, a column named as an output kind
        is read as that kind (``voltage``: the load voltage, not a
        displacement); a column named as another channel than its declared
        kind, or as no response (``force``), is refused
        (:func:`declared_output_kind`).
    time_column : str
        Column of sample times (s); ignored when absent and ``sample_rate``
        is given.
    sample_rate : float, optional
        Sample rate (Hz) for files without a time column; with one, the
        times must lie on its grid (module docstring).
    rows : (start, stop), optional
        Keep data rows ``start:stop`` (0-based, stop exclusive).
    name : str, optional
        Record label (default: the file name).
    outputs : dict, optional
        Output channels by kind: ``{kind: column}`` with kinds among
        ``relative_displacement``, ``relative_velocity``, ``voltage``,
        ``current`` (each column read as that channel only); replaces
        ``output_column``.

    Raises
    ------
    ValueError
        Missing or ambiguous columns, non-numeric, NaN or infinite samples,
        unevenly spaced times, a sample rate that disagrees with them.
    """
    path = Path(path)
    frame = read_csv(path)
    columns = list(frame.columns)
    input_column, input_kind = _input_column(path, columns, input_column, input_kind)
    wanted = _output_columns(path, columns, output_column, output_kind, outputs)
    if rows is not None:
        n_rows = len(frame)
        frame = frame.iloc[slice(*rows)]
        if len(frame) == 0:
            start, stop = ("" if r is None else r for r in rows)
            raise ValueError(
                f"`rows` = {start}:{stop} selects none of the {n_rows} data rows of "
                f"{path.name}; give START:STOP with 0 <= START < STOP (0-based, STOP excluded)"
            )
    channels = {input_kind: frame[input_column]}
    for kind, column in wanted.items():
        channels[kind] = frame[column]
    if wanted and "voltage" in columns and "voltage" not in wanted.values():
        channels.setdefault("voltage", frame["voltage"])  # the load voltage, for the figures
    _check_length(len(frame), name or path.stem)
    step = (
        None
        if sample_rate is None
        else 1.0 / float(check_positive("sample_rate", sample_rate, "Hz"))
    )
    if time_column not in columns:
        if step is None:
            raise ValueError(
                f"{path.name}: no {time_column!r} column (`time_column`); give the sample rate "
                "with `sample_rate`"
            )
        return Record(step, name=name or path.stem, **channels)
    time = _finite_column(time_column, frame[time_column])
    source = None if step is None else f"`sample_rate` = {sample_rate} Hz"
    step = grid_step(time, step, name=time_column, source=source)
    return Record(step, time=time, name=name or path.stem, **channels)


def declared_output_kind(source: str, column: str, kind: str | None) -> str:
    """What the output ``column`` of ``source`` holds: ``kind`` as declared, else its name.

    The one place that decides what a column may be fitted as: a declared
    kind must be one of :data:`OUTPUT_KINDS`, and a column named as another
    channel (``voltage`` declared ``relative_displacement``) is refused; an
    undeclared column must be named as an output kind (``voltage`` is then
    read as the load voltage). A column named as a channel that is no
    response (``force``) or by a name that says nothing (``V2``) is refused,
    in one line that says what to declare.
    """
    kinds = ", ".join(OUTPUT_KINDS)
    if kind is not None:
        if kind not in OUTPUT_KINDS:
            raise ValueError(f"`output_kind` must be one of {kinds}; got {kind!r}")
        if column in CHANNELS and column != kind:
            held = CHANNELS[column]
            raise ValueError(
                f"{source}: output column `{column}` holds the {held.description} ({held.unit}), "
                f"not the {CHANNELS[kind].description} it is declared as (`output_kind` {kind}); "
                + (
                    f"declare it as what it holds (`output_kind` {column})"
                    if column in OUTPUT_KINDS
                    else "name the column that holds one with `output_column`"
                )
            )
        return kind
    if column in OUTPUT_KINDS:
        return column
    if column in CHANNELS:
        held = CHANNELS[column]
        raise ValueError(
            f"{source}: output column `{column}` holds the {held.description} ({held.unit}), "
            f"not a response identification fits (`output_kind`: {kinds}); name the column "
            "that holds one with `output_column`"
        )
    raise ValueError(
        f"{source}: what output column `{column}` holds is not declared; give `output_kind` "
        f"({kinds}, in the column's own units) if it is that"
    )


def _output_columns(path: Path, columns, output_column, output_kind, outputs) -> dict:
    """``{kind: column}`` of the response channels read, each column's kind checked
    (:func:`declared_output_kind`); ``output_column`` is one channel, ``outputs`` several."""
    if outputs is None:
        if output_column is None:
            return {}
        wanted = {declared_output_kind(path.name, output_column, output_kind): output_column}
    else:
        if output_column not in (None, OUTPUT_CHANNEL) or output_kind is not None:
            raise ValueError(
                "give either `output_column` (with `output_kind`) or `outputs` (kind -> column), "
                "not both"
            )
        wanted = dict(outputs)
        for kind, column in wanted.items():
            if kind not in OUTPUT_KINDS:
                raise ValueError(
                    f"`outputs`: {kind!r} is not an output kind; allowed: {', '.join(OUTPUT_KINDS)}"
                )
            declared_output_kind(path.name, column, kind)
    for kind, column in wanted.items():
        if column not in columns:
            what = QUANTITIES[kind]
            raise ValueError(
                f"{path.name}: output column `{column}` not found ({what.description}, "
                f"{what.unit}); columns are {_shown(columns)}; map another name with "
                + (
                    "`output_column` and say what it holds with `output_kind`"
                    if outputs is None
                    else "`--output-column`"
                )
            )
    return wanted


def _input_column(path: Path, columns, input_column, input_kind) -> tuple[str, str]:
    """(column, kind) of the record's input.

    Without ``input_column`` the input is the one column named like an input
    kind (``input_kind``, when given, names it); without ``input_kind`` the
    column's name must be a kind.
    """
    if input_kind is not None and input_kind not in INPUT_KINDS:
        raise ValueError(
            f"`input_kind` must be one of {', '.join(INPUT_KINDS)}; got {input_kind!r}"
        )
    if input_column is None:
        present = [c for c in INPUT_KINDS if c in columns]
        if input_kind is not None:
            if input_kind not in columns:
                raise ValueError(
                    f"{path.name}: no `{input_kind}` column (`input_kind`); columns are "
                    f"{_shown(columns)}; name the input column with `input_column`"
                )
            present = [input_kind]
        if not present:
            raise ValueError(
                f"{path.name}: no input column; expected one of {', '.join(INPUT_KINDS)} "
                f"(or name it with `input_column`); columns are {_shown(columns)}"
            )
        if len(present) > 1:
            raise ValueError(
                f"{path.name}: several input columns {present}; choose one with `input_kind`"
            )
        input_column = present[0]
    if input_column not in columns:
        raise ValueError(
            f"{path.name}: input column {input_column!r} (`input_column`) not found; "
            f"columns are {_shown(columns)}"
        )
    if input_kind is None:
        if input_column not in INPUT_KINDS:
            raise ValueError(
                f"input column `{input_column}` is not one of {', '.join(INPUT_KINDS)}; "
                "say what it holds with `input_kind`"
            )
        input_kind = input_column
    return input_column, input_kind
