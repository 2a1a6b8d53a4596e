"""``randvib record --out FILE``: a synthetic shaker record of a device, as ``identify`` reads it.

The device options are those of ``simulate`` and ``power``; the excitation is
the paper's band-limited shaker test (Sec. 3): ``--rms`` (m/s^2, scaled
exactly) or ``--psd`` (flat level, (m/s^2)^2/Hz) between ``--f-lo`` and
``--f-hi``. Sensor noise and offsets make it look like a measurement. The
parameters simulated (device, excitation, sensors, seed) are written beside
the record, ``FILE.json`` next to ``FILE.csv``.

``--device FILE.toml`` records an assembly
(:func:`~randvib.identification.assembly_record.assembly_record`): the input
and, per DOF, ``dof.I.relative_displacement`` / ``dof.I.relative_velocity``,
per transducer ``transducer.T.voltage`` / ``transducer.T.current``; every
option above applies, each noise and offset to every column of its kind.
"""

from __future__ import annotations

import math
from pathlib import Path

from randvib._io import claim_output_file, dumps, write_or_keep
from randvib._resources import check_memory
from randvib._validation import MAX_SEED, check_int, check_positive, integer_option
from randvib.cli import COMMAND_HELP
from randvib.cli._device import add_device_arguments, assembly_from_args, harvester_from_args
from randvib.cli._records import parse_assignments
from randvib.identification.assembly_record import assembly_record
from randvib.identification.circuit import OUTPUT_KINDS
from randvib.identification.synthetic import PAPER_BAND, SYNTHETIC_INPUTS, synthetic_record
from randvib.models.excitation import BandLimited


def register(sub) -> None:
    p = sub.add_parser(
        "record",
        help=COMMAND_HELP["record"],
        description="Simulate a device under band-limited base excitation and write the "
        "record (time, input, and the response channels: relative_displacement, "
        "relative_velocity, the load voltage or current of its circuit) with optional sensor "
        "noise and offsets. With --device FILE.toml (an assembly) the response columns are per "
        "DOF (dof.I.relative_displacement, dof.I.relative_velocity) and per transducer "
        "(transducer.T.voltage, transducer.T.current), simulated from rest by the assembly's "
        "Heun kernel.",
    )
    add_device_arguments(p)  # also --psd: the flat level of the band
    g = p.add_argument_group("excitation and record")
    g.add_argument("--rms", type=float, help="RMS base acceleration (m/s^2), instead of --psd")
    g.add_argument("--f-lo", type=float, default=PAPER_BAND[0], help="band start (Hz), default 4")
    g.add_argument("--f-hi", type=float, default=PAPER_BAND[1], help="band end (Hz), default 20")
    g.add_argument("--duration", type=float, default=10.0, help="record length (s), default 10")
    g.add_argument("--sample-rate", type=float, default=1000.0, help="Hz, default 1000")
    g.add_argument(
        "--input",
        default="base_acceleration",
        choices=tuple(SYNTHETIC_INPUTS),
        metavar="KIND",
        help=f"what the record's input column holds: {', '.join(SYNTHETIC_INPUTS)}",
    )
    g.add_argument(
        "--substeps", type=integer_option(1), default=8, help="steps per sample (default 8)"
    )
    g.add_argument(
        "--seed", type=integer_option(0, MAX_SEED), default=0, help="random seed (default 0)"
    )
    s = p.add_argument_group("sensors (measured = true + offset + noise)")
    s.add_argument(
        "--output-kind",
        action="append",
        choices=OUTPUT_KINDS,
        metavar="KIND",
        help=f"a response channel to record, one of {', '.join(OUTPUT_KINDS)} (repeat for "
        "several; default relative_displacement); voltage and current need --coupling: the "
        "load voltage R_L i of a coil (its current a state with --inductance), V of a piezo; "
        "with --device, displacement and velocity give a column per DOF, voltage and current "
        "one per transducer",
    )
    s.add_argument(
        "--noise-z", type=float, default=0.0, help="RMS noise on z (m; every DOF's, --device)"
    )
    s.add_argument("--noise-input", type=float, default=0.0, help="RMS noise on the input")
    s.add_argument("--offset-z", type=float, default=0.0, help="offset on z (m)")
    s.add_argument("--offset-input", type=float, default=0.0, help="offset on the input")
    s.add_argument(
        "--noise",
        action="append",
        metavar="KIND=RMS",
        help="RMS white noise on an output channel, in its unit (e.g. voltage=1e-3)",
    )
    s.add_argument(
        "--offset",
        action="append",
        metavar="KIND=VALUE",
        help="offset of an output channel, in its unit (e.g. voltage=2e-3)",
    )
    p.add_argument("--out", required=True, metavar="FILE.csv", help="output file (new)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out")
    p.set_defaults(handler=run, api_flags={"excitation (RMS base acceleration)": "--rms"})


def run(args) -> int:
    out = Path(args.out)
    if out.exists() and not out.is_dir() and not args.force:
        raise FileExistsError(f"`--out` {str(out)!r} exists; choose a new name or give --force")
    claim_output_file(out, "--out", overwrite=args.force)
    sidecar = claim_output_file(
        out.with_suffix(".json"), "--out's parameters", overwrite=args.force
    )
    check_int("--seed", args.seed, 0, MAX_SEED)
    if (args.rms is None) == (args.psd is None):
        raise ValueError("give exactly one of `--rms` (m/s^2) and `--psd` ((m/s^2)^2/Hz)")
    samples = float(args.duration) * float(args.sample_rate)
    if math.isfinite(samples):
        # the excitation, its spectrum, the response and the CSV text, about 12 floats a sample
        check_memory(f"a record of {samples:.3g} samples", 96.0 * samples, "shorten `--duration`")
    if args.psd is not None:  # named as the option, not as the band's `level`
        check_positive("--psd", args.psd, "(m/s^2)^2/Hz")
    excitation = args.rms if args.psd is None else BandLimited(args.psd, args.f_lo, args.f_hi)
    assembly = assembly_from_args(args)
    device = harvester_from_args(args) if assembly is None else assembly
    make = synthetic_record if assembly is None else assembly_record
    record = make(
        device,
        excitation,
        duration=args.duration,
        sample_rate=args.sample_rate,
        seed=args.seed,
        input=args.input,
        noise_z=args.noise_z,
        noise_input=args.noise_input,
        offset_z=args.offset_z,
        offset_input=args.offset_input,
        substeps=args.substeps,
        band=(args.f_lo, args.f_hi),
        name=out.stem,
        outputs=tuple(args.output_kind or ("relative_displacement",)),
        noise=_channel_values(args.noise, "--noise"),
        offsets=_channel_values(args.offset, "--offset"),
    )
    # Full precision, so that identify reads back exactly the simulated samples.
    text = record.to_frame().to_csv(index=False, float_format=None)
    if write_or_keep(out, text, "--out", overwrite=args.force) != out:
        return 1
    simulated = {
        "record": out.name,
        # an assembly's numbers by their dotted paths (docs/assemblies.md)
        "device": device.parameters(),
        "excitation": {"rms": args.rms, "psd": args.psd, "f_lo": args.f_lo, "f_hi": args.f_hi},
        "duration": args.duration,
        "sample_rate": args.sample_rate,
        "input": args.input,
        "substeps": args.substeps,
        "seed": args.seed,
        "outputs": list(args.output_kind or ("relative_displacement",)),
        "sensors": {
            "noise_z": args.noise_z,
            "noise_input": args.noise_input,
            "offset_z": args.offset_z,
            "offset_input": args.offset_input,
            "noise": _channel_values(args.noise, "--noise"),
            "offsets": _channel_values(args.offset, "--offset"),
        },
    }
    if assembly is not None:
        simulated["device_file"] = str(args.device)
        simulated["columns"] = list(record.columns)
        simulated["scheme"] = "heun"  # the assembly kernel's (the single mass's record: RK4)
    where = write_or_keep(
        sidecar, dumps(simulated, indent=2), "--out's parameters", overwrite=args.force
    )
    print(f"wrote {out} ({record.n} samples at {record.sample_rate:g} Hz, {args.input})")
    if where != sidecar:  # kept beside (write_or_keep said where): not saved as asked
        return 1
    print(f"wrote {where} (the parameters simulated)")
    return 0


def _channel_values(items, option: str) -> dict:
    """``KIND=VALUE`` of an output channel (``--noise``, ``--offset``)."""
    out = parse_assignments(items, option)
    for kind in out:
        if kind not in OUTPUT_KINDS:
            raise ValueError(f"`{option} {kind}`: not one of {', '.join(OUTPUT_KINDS)}")
    return out
