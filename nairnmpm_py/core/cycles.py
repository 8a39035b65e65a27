"""A clock-cycle counter callable from Numba code, for the per-task profile.

``cycles()`` reads the processor's cycle counter (LLVM ``readcyclecounter``): a few
nanoseconds, no call into Python, and it caches like any other jitted code.  The
profile turns cycles into seconds by the ratio of cycles to wall time over the run.
"""
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic
from numba import njit


@intrinsic
def _read_counter(typingctx):
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])
    return types.uint64(), codegen


@njit(cache=True, inline="always")
def cycles():
    return _read_counter()
