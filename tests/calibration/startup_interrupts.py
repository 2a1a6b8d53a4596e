"""Ctrl-C while the command line starts: where a SIGINT lands, by its delay after spawning.

Run by hand (not collected by pytest), from the repository root::

    python tests/calibration/startup_interrupts.py randvib 300 3 1

Arguments: the executable, the largest delay (ms), the delay step (ms), the
repetitions. Sends SIGINT to ``randvib power --preset coulomb-td1 --psd 0.1``
at each delay and counts the outcomes: killed before Python's handler exists,
a traceback inside the interpreter's own start-up (site, .pth files), a
traceback from randvib code, or one line with exit 130. docs/development.md
gives the numbers.
"""

import collections
import signal
import subprocess
import sys
import time

exe, top, step, reps = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
counts = collections.Counter()
where = collections.defaultdict(list)
for _rep in range(reps):
    off = 0.0
    while off <= top + 1e-9:
        p = subprocess.Popen(
            [exe, "power", "--preset", "coulomb-td1", "--psd", "0.1"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < off / 1000:
            pass
        p.send_signal(signal.SIGINT)
        _, err = p.communicate()
        err = err.decode(errors="replace")
        if "Traceback" in err or "Exception ignored" in err:
            frames = [line for line in err.splitlines() if line.strip().startswith("File ")]
            ours = any("/randvib/" in f and "__editable__" not in f for f in frames)
            kind = (
                "traceback in randvib code"
                if ours
                else "traceback in interpreter start-up (site, .pth)"
            )
        else:
            kind = f"one line or none, exit {p.returncode}"
        counts[kind] += 1
        where[kind].append(round(off))
        off += step
for k, v in counts.items():
    print(f"{v:4d}  {k}: offsets {min(where[k])}..{max(where[k])} ms")
