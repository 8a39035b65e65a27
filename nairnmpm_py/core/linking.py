"""Calling compiled tasks through their addresses.

Numba links the code of every function a jitted function calls into the caller's own
module and optimizes and compiles it all again.  A driver that called the step's
tasks directly therefore compiled the whole step twice: each task once, and all of
them again inside the driver.  The driver instead calls each task through its
address, a runtime number: it is compiled once for all scenes that share the
bundles' types, and a task's code is compiled once.  Measured cold: the driver's
own compile fell from 16-19 s to 6.6 s on the DCB and from 4.7 s to 3.0 s on the
vibrating bar (what is left is mostly passing and unboxing the bundles' arrays).

``call_task(address, args)`` calls the Numba function compiled at ``address`` with
the values of the tuple ``args`` (Numba's own calling convention, so an exception
the task raises propagates as usual).  ``address_of(function, types)`` compiles a
jitted function for those argument types (or loads it from the cache) and returns
that address.
"""
from __future__ import annotations

from numba import types
from numba.extending import intrinsic


@intrinsic
def call_task(typingctx, address, args):
    """Call the function at ``address`` (int64) with the values of the tuple ``args``;
    it must have been compiled for exactly their types and return nothing."""
    if not isinstance(args, types.BaseTuple):
        return None
    sig = types.none(types.int64, args)

    def codegen(context, builder, signature, llargs):
        address, packed = llargs
        argtypes = list(signature.args[1].types)
        values = [builder.extract_value(packed, i) for i in range(len(argtypes))]
        fnty = context.call_conv.get_function_type(types.none, argtypes)
        function = builder.inttoptr(address, fnty.as_pointer())
        status, _ = context.call_conv.call_function(builder, function, types.none, argtypes,
                                                    values)
        with builder.if_then(status.is_error, likely=False):
            context.call_conv.return_status_propagate(builder, status)
        return context.get_dummy_value()
    return sig, codegen


def address_of(function, argtypes: tuple) -> int:
    """Address of ``function`` (a Numba dispatcher) compiled for ``argtypes``."""
    function.compile(argtypes)
    compiled = function.overloads[tuple(argtypes)]
    return int(compiled.library.get_pointer_to_function(compiled.fndesc.llvm_func_name))
