"""Software prefetch for the traversal: a hint that a row of an array will be read soon.

``prefetch(a, i)`` asks the CPU to start loading the cache line holding the start of row
``i`` of an array (``llvm.prefetch``: read, keep in all cache levels, data).
It neither reads nor faults: an address past the array is harmless, so callers need not
check bounds. Compiled into each caller (a numba intrinsic), so numba's on-disk cache
keeps it with the kernel; it is not a compiled function of its own, so the project's
jit policy (core/jit.py) is unaffected.
"""
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic


@intrinsic
def prefetch(typingctx, arr, idx):
    """Prefetch the line holding ``arr[idx, 0]`` (or ``arr[idx]`` for a 1-d array)."""
    if not isinstance(arr, types.Array) or not isinstance(idx, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        aryty, idxty = sig.args
        ary = context.make_array(aryty)(context, builder, args[0])
        strides = cgutils.unpack_tuple(builder, ary.strides, aryty.ndim)
        i = context.cast(builder, args[1], idxty, types.intp)
        _emit(builder, builder.add(builder.ptrtoint(ary.data, cgutils.intp_t), builder.mul(i, strides[0])))
        return context.get_dummy_value()

    return types.void(arr, idx), codegen


@intrinsic
def prefetch_lines(typingctx, arr, idx):
    """Prefetch every cache line of row ``idx`` of a 2-d array whose rows are at most 192
    bytes long (a leaf block of the BVH: 160 bytes, up to three or four lines)."""
    if not isinstance(arr, types.Array) or arr.ndim != 2 or not isinstance(idx, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        aryty, idxty = sig.args
        ary = context.make_array(aryty)(context, builder, args[0])
        strides = cgutils.unpack_tuple(builder, ary.strides, aryty.ndim)
        i = context.cast(builder, args[1], idxty, types.intp)
        addr = builder.add(builder.ptrtoint(ary.data, cgutils.intp_t), builder.mul(i, strides[0]))
        last = builder.sub(builder.add(addr, strides[0]), ir.Constant(cgutils.intp_t, 1))
        for a in (addr, builder.add(addr, ir.Constant(cgutils.intp_t, 64)),
                  builder.add(addr, ir.Constant(cgutils.intp_t, 128)), last):
            _emit(builder, a)
        return context.get_dummy_value()

    return types.void(arr, idx), codegen


def _emit(builder, addr):
    i8p = ir.IntType(8).as_pointer()
    i32 = ir.IntType(32)
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]),
                                        "llvm.prefetch.p0")
    builder.call(fn, [builder.inttoptr(addr, i8p), i32(0), i32(3), i32(1)])
