"""A truncated map's passes over all its prototypes, eight at a time: distances, minimum, list.

:func:`~gb_pin.learn.llm_kernels.truncated_predict` needs ||u_k||^2 of every prototype, their
minimum and the indices k with ||u_k||^2 <= min + c^2, in increasing k. As loops, the minimum (four
scalar lanes) and the list (``near[count + 1] = k; count += sq[k] <= limit``) are chains of scalar
steps, one per prototype, each as long as the distances themselves. Here (LLVM IR, eight doubles in
one register; every lane does the scalar loop's operations, no fused multiply-add):

- :func:`distances_smallest` (three inputs): the distances, stored, and their minimum in the same
  pass; :func:`smallest` the minimum of given distances (other input counts). A lane-wise ``v < m ?
  v : m`` then the lanes' minimum: a NaN never enters, as in the loop, and a set's minimum is the
  same in any order, bit for bit.
- :func:`list_within`: the comparison gives a mask, ``llvm.experimental.vector.compress`` packs the
  indices of its set lanes to the front of a register (one ``vpcompressq`` where the CPU has
  AVX-512; LLVM expands it elsewhere; an LLVM before 19 lacks it: the scalar loop, :data:`COMPRESS`),
  the whole register is stored at the list's end and the count grows by the mask's population (the
  lanes past it are overwritten by the next store or lie past the count). The same indices in the
  same order as the loop (NaN compares false in both).

Measured at K = 756 (200,000 calls each, this 2-core machine, AVX-512): the distances 0.111 us and
the scalar minimum 0.113, fused 0.109; the list 0.182 as a loop, 0.048 here (0.188 with
``llvm.masked.compressstore``, a compress to memory, which this CPU runs slowly). Packing the listed
prototypes' centres and distances with the same masks (no gathers after) cost more than it saved:
its stores run over all K, the gathers over the ~60 listed only. tests/test_llm_kernels.py checks
all three against the plain loops.
"""

from __future__ import annotations

from typing import Any

from llvmlite import binding, ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

WIDTH = 8  # doubles per step

COMPRESS = binding.llvm_version_info >= (19,)
"""Whether this LLVM has ``llvm.experimental.vector.compress`` (19 on); without it :func:`list_within`
runs the scalar loop (numba >= 0.59 is allowed, whose LLVM may be older)."""

_I64 = ir.IntType(64)
_DOUBLE = ir.DoubleType()
_VEC_D = ir.VectorType(_DOUBLE, WIDTH)
_VEC_I = ir.VectorType(_I64, WIDTH)
_MASK = ir.VectorType(ir.IntType(1), WIDTH)


def _vector(sq: Any, name: str) -> None:
    if not (isinstance(sq, types.Array) and sq.dtype == types.float64 and sq.ndim == 1):
        raise TypeError(f"{name} takes a float64 vector of squared distances")


@intrinsic
def smallest(typingctx: Any, sq: Any, K: Any) -> Any:
    """min_k sq[k] over k < K (NaNs skipped; inf if none): the scalar loop's minimum, eight lanes a step."""
    _vector(sq, "smallest")
    sig = types.float64(sq, types.intp)

    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        count_k = args[1]
        width = ir.Constant(_I64, WIDTH)
        least = cgutils.alloca_once_value(builder, ir.Constant(_VEC_D, [float("inf")] * WIDTH))
        blocks = builder.sdiv(count_k, width)
        with cgutils.for_range(builder, blocks) as loop:
            ptr = builder.bitcast(builder.gep(data, [builder.mul(loop.index, width)]), _VEC_D.as_pointer())
            v = builder.load(ptr, align=8)
            _keep_smaller(builder, v, least)
        result = _fold_lanes(builder, builder.load(least))
        start = builder.mul(blocks, width)
        with cgutils.for_range_slice(builder, start, count_k, ir.Constant(_I64, 1), inc=True) as (k, _):
            a = builder.load(builder.gep(data, [k]))
            _keep_smaller(builder, a, result)
        return builder.load(result)

    return sig, codegen


@intrinsic
def distances_smallest(typingctx: Any, x: Any, P: Any, inv: Any, sq: Any, K: Any) -> Any:
    """sq[k] = ||(x - P[:, k]) inv||^2 for k < K, three inputs; returns their minimum (:func:`smallest`).

    The distances as the loop writes them, u_j = (x_j - P[j, k]) * inv, (u0 u0 + u1 u1) + u2 u2
    (no fused multiply-add), eight prototypes a step, and the minimum taken in the same pass.
    """
    _vector(sq, "distances_smallest")
    _vector(x, "distances_smallest")
    if not (isinstance(P, types.Array) and P.dtype == types.float64 and P.ndim == 2 and P.layout == "C"):
        raise TypeError("distances_smallest takes a C-contiguous float64 matrix of centres")
    sig = types.float64(x, P, types.float64, sq, types.intp)

    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        x_data = context.make_array(signature.args[0])(context, builder, args[0]).data
        p_array = context.make_array(signature.args[1])(context, builder, args[1])
        p_data, p_row = p_array.data, cgutils.unpack_tuple(builder, p_array.shape)[1]
        sq_data = context.make_array(signature.args[3])(context, builder, args[3]).data
        inv, count_k = args[2], args[4]
        coords = [builder.load(builder.gep(x_data, [ir.Constant(_I64, j)])) for j in range(3)]
        rows = [builder.gep(p_data, [builder.mul(ir.Constant(_I64, j), p_row)]) for j in range(3)]
        width = ir.Constant(_I64, WIDTH)

        def squared(load: Any, splat: Any) -> ir.Value:
            u = [builder.fmul(builder.fsub(splat(coords[j]), load(rows[j])), splat(inv)) for j in range(3)]
            return builder.fadd(
                builder.fadd(builder.fmul(u[0], u[0]), builder.fmul(u[1], u[1])), builder.fmul(u[2], u[2])
            )

        least = cgutils.alloca_once_value(builder, ir.Constant(_VEC_D, [float("inf")] * WIDTH))
        blocks = builder.sdiv(count_k, width)
        with cgutils.for_range(builder, blocks) as loop:
            base = builder.mul(loop.index, width)

            def load_vec(row: ir.Value) -> ir.Value:
                return builder.load(builder.bitcast(builder.gep(row, [base]), _VEC_D.as_pointer()), align=8)

            v = squared(load_vec, lambda value: _splat(builder, value, _VEC_D))
            builder.store(v, builder.bitcast(builder.gep(sq_data, [base]), _VEC_D.as_pointer()), align=8)
            _keep_smaller(builder, v, least)
        result = _fold_lanes(builder, builder.load(least))
        start = builder.mul(blocks, width)
        with cgutils.for_range_slice(builder, start, count_k, ir.Constant(_I64, 1), inc=True) as (k, _):
            a = squared(lambda row: builder.load(builder.gep(row, [k])), lambda value: value)
            builder.store(a, builder.gep(sq_data, [k]))
            _keep_smaller(builder, a, result)
        return builder.load(result)

    return sig, codegen


@intrinsic
def list_within(typingctx: Any, sq: Any, limit: Any, K: Any, near: Any) -> Any:
    """near[1 + t] = the t-th k < K with sq[k] <= limit, in increasing k; returns their count.

    ``near`` holds at least K + 1 entries; near[0] and the entries past K are left as they were,
    those between the count and K may be overwritten.
    """
    _vector(sq, "list_within")
    if not (isinstance(near, types.Array) and near.dtype == types.int64 and near.ndim == 1):
        raise TypeError("list_within takes an int64 list")
    sig = types.intp(sq, types.float64, types.intp, near)

    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        sq_data = context.make_array(signature.args[0])(context, builder, args[0]).data
        near_data = context.make_array(signature.args[3])(context, builder, args[3]).data
        limit_v, count_k = args[1], args[2]
        module = builder.module
        compress = cgutils.get_or_insert_function(
            module,
            ir.FunctionType(_VEC_I, [_VEC_I, _MASK, _VEC_I]),
            f"llvm.experimental.vector.compress.v{WIDTH}i64",
        )
        popcount = cgutils.get_or_insert_function(
            module, ir.FunctionType(ir.IntType(WIDTH), [ir.IntType(WIDTH)]), f"llvm.ctpop.i{WIDTH}"
        )
        one = ir.Constant(_I64, 1)
        width = ir.Constant(_I64, WIDTH)
        count = cgutils.alloca_once_value(builder, ir.Constant(_I64, 0))
        limits = _splat(builder, limit_v, _VEC_D)
        lanes = ir.Constant(_VEC_I, list(range(WIDTH)))
        blocks = builder.sdiv(count_k, width) if COMPRESS else ir.Constant(_I64, 0)  # else: all scalar
        with cgutils.for_range(builder, blocks) as loop:
            # count <= base here, so the eight stored entries end at near[base + 8] <= near[K].
            base = builder.mul(loop.index, width)
            ptr = builder.bitcast(builder.gep(sq_data, [base]), _VEC_D.as_pointer())
            mask = builder.fcmp_ordered("<=", builder.load(ptr, align=8), limits)
            packed = builder.call(compress, [builder.add(_splat(builder, base, _VEC_I), lanes), mask,
                                             ir.Constant(_VEC_I, ir.Undefined)])  # fmt: skip
            c = builder.load(count)
            target = builder.bitcast(builder.gep(near_data, [builder.add(c, one)]), _VEC_I.as_pointer())
            builder.store(packed, target, align=8)
            bits = builder.bitcast(mask, ir.IntType(WIDTH))
            builder.store(builder.add(c, builder.zext(builder.call(popcount, [bits]), _I64)), count)
        start = builder.mul(blocks, width)
        with cgutils.for_range_slice(builder, start, count_k, one, inc=True) as (k, _):
            c = builder.load(count)
            builder.store(k, builder.gep(near_data, [builder.add(c, one)]))
            inside = builder.fcmp_ordered("<=", builder.load(builder.gep(sq_data, [k])), limit_v)
            builder.store(builder.add(c, builder.zext(inside, _I64)), count)
        return builder.load(count)

    return sig, codegen


def _keep_smaller(builder: ir.IRBuilder, value: ir.Value, least: ir.Value) -> None:
    """``*least = value < *least ? value : *least`` (lane-wise for vectors; a NaN never enters)."""
    m = builder.load(least)
    builder.store(builder.select(builder.fcmp_ordered("<", value, m), value, m), least)


def _fold_lanes(builder: ir.IRBuilder, vector: ir.Value) -> ir.Value:
    """A pointer to the smallest lane of ``vector`` (from inf, lane by lane with :func:`_keep_smaller`)."""
    result = cgutils.alloca_once_value(builder, ir.Constant(_DOUBLE, float("inf")))
    for lane in range(WIDTH):
        _keep_smaller(builder, builder.extract_element(vector, ir.Constant(ir.IntType(32), lane)), result)
    return result


def _splat(builder: ir.IRBuilder, value: ir.Value, vector: ir.VectorType) -> ir.Value:
    """A vector of copies of ``value``."""
    one = builder.insert_element(ir.Constant(vector, ir.Undefined), value, ir.Constant(ir.IntType(32), 0))
    zeros = ir.Constant(ir.VectorType(ir.IntType(32), WIDTH), [0] * WIDTH)
    return builder.shuffle_vector(one, ir.Constant(vector, ir.Undefined), zeros)
