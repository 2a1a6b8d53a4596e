"""The stop flag a compiled loop reads to end early on Ctrl-C.

:func:`randvib._interrupts.interruptible` runs a compiled loop in a worker
thread and, on Ctrl-C, sets ``stop[0] = 1`` from the main thread. The loop
must read that element from memory at each of its checks. A plain
``stop[0] != 0`` does not promise it: once the loop's step helpers were
inlined without reference counts (no opaque calls left in the loop), LLVM
proved that nothing in the loop writes ``stop`` and read it once, before the
loop; a Ctrl-C then waited for the whole run to end (a minute in the test,
hours in a long study). :func:`stop_requested` reads it with an atomic
(monotonic) load, which the optimiser may neither hoist out of the loop nor
merge with an earlier read.
"""

from __future__ import annotations

from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic


@intrinsic
def stop_requested(typingctx, stop):
    """``stop[0] != 0``, read from memory every time it is called (int64[1] array).

    Parameters
    ----------
    stop : int64[:]
        The flag array: non-zero in its first element asks the loop to stop.

    Returns
    -------
    bool
    """
    if not (isinstance(stop, types.Array) and stop.dtype == types.int64 and stop.ndim == 1):
        return None  # numba then reports the argument's type as unsupported
    signature = types.boolean(stop)

    def codegen(context, builder, sig, args):
        array = context.make_array(sig.args[0])(context, builder, args[0])
        value = builder.load_atomic(array.data, ordering="monotonic", align=8)
        return builder.icmp_signed("!=", value, ir.Constant(value.type, 0))

    return signature, codegen
