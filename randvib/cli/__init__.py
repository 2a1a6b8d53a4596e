"""Command line: ``randvib <command> [options]``.

Each command lives in its own module exposing ``register(subparsers)`` which
adds its parser and sets ``handler``; :data:`COMMANDS` lists the modules.
Every user error (bad value, unknown name, unreadable or unwritable file)
ends with one line on stderr and exit status 2, never a traceback; Ctrl-C
ends with exit status 130 and SIGTERM with 143 (128 + 15), both keeping
what was finished, releasing folder locks and ending worker processes.
Anything else that
escapes a command is a bug: one line naming it, exit status 1, and the
traceback only with ``RANDVIB_TRACEBACK=1``.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import re
import sys
import warnings

from randvib._interrupts import interrupted_exit, interrupts_seen, sigterm_stops
from randvib._locks import held, release_since

#: Command modules under randvib.cli, in the order shown by --help.
COMMANDS = [
    "power", "design", "simulate", "reliability", "study", "record", "identify", "validate",
    "compile",
]  # fmt: skip

#: Each command's line in ``randvib --help`` (its module's parser uses the same), here so
#: that the list of commands is printed without importing them (numba, scipy, pandas).
COMMAND_HELP = {
    "power": "analytic expected power under white noise or a coloured excitation",
    "design": "choose device parameters for the most power under a stroke budget",
    "simulate": "Monte Carlo simulation under white, coloured or recorded base acceleration",
    "reliability": "rare end-stop strikes: first-passage probability, crossing rate, exceedance",
    "study": "run a study script (figures, CSV, Markdown report)",
    "record": "write a synthetic shaker record of a device (CSV for identify/validate)",
    "identify": "identify device and friction parameters from a measured record (SaDE, Eq. 11)",
    "validate": "J (Eq. 11) of identified parameters on other records",
    "compile": "compile every numerical kernel now (once per install), so no command waits",
}

#: Options whose name differs from the Python API's argument (docs/command_line.md's table).
API_NAMES = {
    "--paths": "n_paths (randvib.simulate)",
    "--method (simulate)": "scheme (randvib.simulate)",
    "--method (power)": "method (randvib.predict)",
    "--generations": "SearchSettings.maxiter (randvib.identify)",
    "--popsize": "SearchSettings.popsize (randvib.identify)",
    "--no-polish": "SearchSettings.polish=False (randvib.identify)",
    "--psd": "psd, or an excitation's level",
    "--segments": "segments (randvib.monte_carlo_on_record)",
    "--dt (with --record)": "substeps = record step / dt (randvib.monte_carlo_on_record)",
    "--model": "model (randvib.identify)",
    "--output-kind": "outputs (randvib.identify, randvib.synthetic_record, randvib.predict_record)",
    "--weight": "weights (randvib.identify)",
    "--offset (record)": "offsets (randvib.synthetic_record)",
    "--from-fit": "IdentificationResult.from_dict(...).harvester()",
    "--no-progress": "progress=False",
}


class UserError(Exception):
    """An error caused by the user's input; printed as one line, exit 2."""


#: What argparse takes for a negative number (not an option): its own pattern
#: misses exponents, infinities and START:STOP:COUNT sweeps, so `--k3 -5e5` or
#: `--f0 -inf` would be read as a missing value rather than checked as a number.
_NUMBER = r"((\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|inf|infinity|nan)"
NEGATIVE_NUMBER = re.compile(rf"^-{_NUMBER}(:[-+]?{_NUMBER}){{0,2}}$", re.IGNORECASE)


#: argparse's refusal of a value outside ``choices`` (Python 3.11 and 3.12+ spellings).
_INVALID_CHOICE = re.compile(
    r"^argument (?P<flag>[^:]+): invalid choice: (?P<got>.+?) \(choose from (?P<allowed>.*)\)$"
)


class HelpFormatter(argparse.HelpFormatter):
    """Every option's default in its help: ``(default: X)`` unless the text already says it.

    Options whose default is None (not given) or False (a switch) have nothing
    to show; an option whose effective default is decided later (``--paths``)
    says it in its own text, which this formatter leaves alone.
    """

    def _get_help_string(self, action):
        text = action.help or ""
        # identity, not equality: a default of 0 or 0.0 is shown (0 == False)
        shown = not any(action.default is nothing for nothing in (None, False, argparse.SUPPRESS))
        if shown and action.option_strings and "default" not in text:
            text += " (default: %(default)s)"
        return text


def one_line_choice_error(message: str) -> str:
    """argparse's invalid-choice message in the project's words, else ``message`` itself.

    ``argument --x: invalid choice: 'c' (choose from 'a', 'b')`` becomes
    ``--x` must be one of a, b; got 'c'``, as the commands' own checks say it.
    """
    match = _INVALID_CHOICE.match(message)
    if match is None:
        return message
    flag = match["flag"].split("/")[-1]
    allowed = ", ".join(name.strip().strip("'") for name in match["allowed"].split(","))
    return f"`{flag}` must be one of {allowed}; got {match['got']}"


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):  # one line, no usage dump, exit 2
        raise UserError(f"{self.prog}: error: {one_line_choice_error(message)}")

    def print_help(self, file=None):
        """Print the help; a command's is kept for the next time (:mod:`randvib.cli._help`)."""
        text = self.format_help()
        command = self.prog.removeprefix("randvib ")
        if command in COMMANDS and file in (None, sys.stdout):
            from randvib.cli._help import keep_help

            keep_help(command, text)
        self._print_message(text, sys.stdout if file is None else file)


def build_parser(argv=None) -> argparse.ArgumentParser:
    """The ``randvib`` parser; with ``argv``, only the commands it names are built in full.

    Every command module imports the numerical stack (numba, scipy, pandas:
    seconds); to parse ``argv`` only its own command's module is needed, and
    ``randvib --help`` needs none (the others are listed by
    :data:`COMMAND_HELP`). Without ``argv`` every command is built (the
    reference docs, the tests of every option).
    """
    from randvib import __version__

    # the docstring's first line without its reStructuredText markup (``randvib ...``)
    parser = _Parser(prog="randvib", description=__doc__.splitlines()[0].replace("``", ""))
    parser.add_argument("--version", action="version", version=f"randvib {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    wanted = set(COMMANDS) if argv is None else {a for a in argv if a in COMMANDS}
    for name in COMMANDS:
        if name not in wanted:  # listed by its name and help line only
            sub.add_parser(name, help=COMMAND_HELP[name], add_help=False)
            continue
        try:
            module = importlib.import_module(f"randvib.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"randvib.cli.{name}":
                continue  # command not built yet
            raise
        module.register(sub)
    return parser


def main(argv=None) -> int:
    try:
        with sigterm_stops():
            code = _main_with_warnings(argv)
            swallowed = interrupts_seen()
            if swallowed is not None and code < 128:
                # an interrupt that a finaliser or a callback swallowed: the run went on,
                # but the user asked it to stop, and the status says it was stopped
                code, line = interrupted_exit(swallowed)
                print(line, file=sys.stderr)
        sys.stdout.flush()  # a pipe's buffer is written here, where its closing is handled
        return code
    except KeyboardInterrupt as exc:  # while warnings and advice classes were being set up
        code, line = interrupted_exit(exc)
        print(line, file=sys.stderr)
        return code
    except BrokenPipeError:
        # The reader (`head`, `less`) has gone: end quietly, as Unix tools do.
        # stdout is pointed at /dev/null so that the interpreter's final flush
        # does not raise the same error again at exit.
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):  # no real file descriptor (captured output)
            pass
        return 141  # 128 + SIGPIPE, what a shell reports for a tool ended by it
    except Exception:
        # an interrupt inside an extension module's import surfaces as an ImportError
        # ("initialization failed"): the interrupt is what happened
        if interrupts_seen() is None:
            raise
        code, line = interrupted_exit(interrupts_seen())
        print(line, file=sys.stderr)
        return code


def _main_with_warnings(argv) -> int:
    with warnings.catch_warnings():
        # numpy's floating-point warnings at extreme values: every result is
        # checked for finiteness instead, and refused with a message naming it
        warnings.filterwarnings("ignore", category=RuntimeWarning, module=r"(numpy|scipy|randvib)")
        warnings.filterwarnings("ignore", message=r"Matrix is exactly singular")
        # randvib's own advice, also RuntimeWarnings, is for the user: shown, by filters
        # set once the command is parsed (their classes import the numerical stack, which
        # `--help` does not need)
        warnings.showwarning = _show_warning
        locks_before = held()
        try:
            return _main(argv)
        finally:
            # in-process callers (tests, notebooks) get the API's words back
            _Running.prog, _Running.flags = "randvib", {}
            # the locks the command took go with it (an in-process caller keeps its own)
            release_since(locks_before)


def _advice_warnings() -> tuple:
    """randvib's warnings that say something about the user's run (a step size, a validity)."""
    from randvib.analytic.assembly_prediction import AssemblyLoadBoundWarning
    from randvib.analytic.averaging import AveragingValidityWarning
    from randvib.analytic.prediction import LoadBoundWarning
    from randvib.analytic.statistical_linearisation import LinearisationValidityWarning
    from randvib.montecarlo.bridge_step import BridgeIdleWarning
    from randvib.montecarlo.step_check import StepSizeWarning

    return (
        StepSizeWarning,
        BridgeIdleWarning,
        AveragingValidityWarning,
        LoadBoundWarning,
        LinearisationValidityWarning,
        AssemblyLoadBoundWarning,
    )


@contextlib.contextmanager
def advice_when_done():
    """Hold randvib's advice warnings until the block ends; drop them if it fails.

    For commands that compute several results and print them at the end (a
    `power` sweep): advice about one point must not precede the refusal of
    another, which ends the command with one line. Other warnings (a long
    run's notice) are shown at once; after an interrupt the held advice is
    shown, as the finished results are kept.
    """
    shown = warnings.showwarning
    advice = _advice_warnings()
    held = []

    def hold(message, category, *rest, **kwargs):
        if issubclass(category, advice):
            held.append((message, category, *rest))
        else:
            shown(message, category, *rest, **kwargs)

    warnings.showwarning = hold
    try:
        yield
    except KeyboardInterrupt:
        warnings.showwarning = shown
        for item in held:
            shown(*item)
        raise
    finally:
        warnings.showwarning = shown
    for item in held:
        shown(*item)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """A warning as one readable line (no kind, source file or code line)."""
    text = cli_wording(str(message).strip().splitlines()[0] if str(message).strip() else "")
    print(f"{_Running.prog}: warning: {text}", file=file or sys.stderr)


#: ``randvib.NAME(`` in the library's messages -> the command that does it here.
_API_TO_COMMAND = {
    "simulate": "randvib simulate",
    "simulate_transient": "randvib simulate --envelope",
    "transient_response": "randvib power --envelope",
    "predict": "randvib power",
    "expected_power": "randvib power",
    "identify": "randvib identify",
    "validate": "randvib validate",
    "synthetic_record": "randvib record",
}
_KEYWORD_CHOICE = re.compile(r"\b(?P<name>method|friction|coupling)='(?P<value>[\w-]+)'")
_API_NAME = re.compile(r"`?randvib\.(?P<name>[a-z_]+)(?:\(\))?`?")


def cli_wording(message: str, flags: dict | None = None) -> str:
    """A library message as the command line says it: ``randvib.simulate`` -> ``randvib simulate``.

    Only the functions a command runs are translated; other names stay as
    they are (they are the API the message is about). With ``flags`` (API
    argument -> the flag that sets it, :func:`api_flags`), the arguments the
    message names become the flags the user typed: `` `burn_in` must satisfy
    0 <= burn_in < t_end`` -> `` `--burn-in` must satisfy 0 <= --burn-in < --t-end``.
    """

    def command(match):
        name = _API_TO_COMMAND.get(match["name"])
        return match[0] if name is None else f"`{name}`"

    message = _API_NAME.sub(command, message)
    # a keyword choice of the API (method='fpk-fast') is an option here
    message = _KEYWORD_CHOICE.sub(lambda m: f"`--{m['name']} {m['value']}`", message)
    flags = _Running.flags if flags is None else flags
    if flags:
        message = _QUOTED_NAME.sub(lambda m: f"`{flags.get(m[1], m[1])}`", message)
        # bare names with an underscore in formulas and advice (dt is one too)
        message = _BARE_NAME.sub(lambda m: flags.get(m[1], m[1]), message)
    return message


class _Running:
    """The command being run: its name and API-argument -> flag map (errors and warnings)."""

    prog = "randvib"
    flags: dict = {}


#: API arguments whose flag is named differently (the table of renamed options in docs/command_line.md).
_RENAMED = {"n_paths": "--paths", "scheme": "--method", "maxiter": "--generations"}

_QUOTED_NAME = re.compile(r"`([A-Za-z_][\w ()-]*)`")
# not a coefficient in a formula (``c_m E[v^2]``): that is physics, not an option
_BARE_NAME = re.compile(r"(?<![\w`./-])([a-z][a-z0-9]*(?:_[a-z0-9]+)+|dt)(?![\w`/(-]| E\[)")


def api_flags(parser: argparse.ArgumentParser) -> dict:
    """API argument name -> the flag that sets it, for one command's parser.

    An option's ``dest`` is the API argument's name (``--burn-in`` sets
    ``burn_in``); a command may add names of its own with
    ``set_defaults(api_flags={...})`` (``record --rms`` sets the excitation).
    """
    flags = dict(_RENAMED)
    for action in parser._actions:
        longs = [o for o in action.option_strings if o.startswith("--")]
        if longs and action.dest != "help":
            flags[action.dest] = longs[0]
    flags.update(parser.get_default("api_flags") or {})
    return flags


#: What the compile notice says, once per run, on stderr.
COMPILING = (
    "randvib: compiling the numerical kernels this command needs (each once per install; "
    "`randvib compile` compiles them all now)"
)


@contextlib.contextmanager
def compile_notice():
    """Say on stderr, once, when numba compiles rather than loads from its cache.

    numba fires its ``numba:compile`` event only on a cache miss (a kernel
    loaded from the on-disk cache fires none), so a warm cache prints nothing
    and the first run after an install or an upgrade explains its pause.
    """
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover - numba is a dependency
        yield
        return

    class Notice(event.Listener):
        said = False

        def on_start(self, data):
            if not self.said:
                self.said = True
                print(COMPILING, file=sys.stderr, flush=True)

        def on_end(self, data):
            pass

    with event.install_listener("numba:compile", Notice()):
        yield


def _command_parser(parser, command: str) -> argparse.ArgumentParser:
    return next(a for a in parser._actions if a.dest == "command").choices[command]


def _main(argv) -> int:
    try:
        argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
        # only the command named is built: the first word that is one (no option's value is)
        named = next((a for a in argv if a in COMMANDS), None)
        if named is not None and {"-h", "--help"} & set(argv[argv.index(named) :]):
            from randvib.cli._help import kept_help

            text = kept_help(named)  # printed before by this package: no parser to build
            if text is not None:  # and ends as argparse's --help does, whichever printed it
                sys.stdout.write(text)
                raise SystemExit(0)
        parser = build_parser([] if named is None else [named])
        args, unknown = parser.parse_known_args(argv)
        # "randvib COMMAND" from here on, as argparse names it ("randvib" until then)
        prog = _Running.prog = f"randvib {args.command}"
        _Running.flags = api_flags(_command_parser(parser, args.command))
        if unknown:  # named by the command, with where to look (argparse names only "randvib")
            raise UserError(
                f"{prog}: error: unrecognized arguments: {' '.join(unknown)} (see `{prog} --help`)"
            )
        for advice in _advice_warnings():
            warnings.filterwarnings("default", category=advice)
        if args.command == "compile":  # it says what it compiles itself
            return int(args.handler(args) or 0)
        with compile_notice():
            return int(args.handler(args) or 0)
    except BrokenPipeError:
        raise  # handled in main: the reader went away, not a user error
    except (UserError, ValueError, OSError, NotImplementedError) as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        message = cli_wording(message)
        if not message.startswith("randvib"):
            message = f"{_Running.prog}: error: {message}"
        print(message, file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        code, line = interrupted_exit(exc)
        print(line, file=sys.stderr)
        return code
    except Exception as exc:  # a bug: one line, not a traceback (unless asked for)
        if interrupts_seen() is not None:  # an interrupt turned into another exception
            code, line = interrupted_exit(interrupts_seen())
            print(line, file=sys.stderr)
            return code
        if os.environ.get("RANDVIB_TRACEBACK"):
            raise
        text = str(exc).strip().splitlines()
        print(
            f"randvib: internal error: {type(exc).__name__}: {text[0] if text else ''} "
            "(please report it; RANDVIB_TRACEBACK=1 shows the traceback)",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
