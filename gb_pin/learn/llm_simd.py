"""The local-linear map's two passes over its prototypes, eight outputs in one SIMD register.

A prediction's sum g(x) ~ sum_k b_k (o_k + W_k u_k) and a learning step's update of every o_k
and W_k run over the prototypes k in order; the sum over k is a chain of dependent additions
per output that must keep that order (the fingerprinted numbers). Held side by side in one
register of eight doubles, eight outputs advance together: one vector addition per prototype
instead of eight scalar ones, and the prototype's numbers o_k, W_k stored contiguously
(:class:`~gb_pin.learn.llm_kernels.MapArrays`: ``models[k, 0, :]`` = o_k, ``models[k, 1 + j, :]`` =
column j of W_k, eight outputs a block) are read as whole registers. numba's vectoriser does not
pack independent scalar chains into registers (its SLP pass is off), so these two loops are
written in LLVM IR: every lane does exactly the scalar operations of the plain loops (no fused
multiply-add, no reassociation), which tests/test_llm_kernels.py checks bit for bit.
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: Outputs per SIMD block (one register of doubles on AVX-512; LLVM splits it where narrower).
LANES = 8

_DOUBLE = ir.DoubleType()
_VECTOR = ir.VectorType(_DOUBLE, LANES)


def _check(models: Any, inputs: Any, act: Any) -> None:
    """Typing: C-contiguous float64 arrays of the expected ranks (else numba reports no match)."""
    for array, ndim in ((models, 3), (inputs, 2), (act, 1)):
        if not (isinstance(array, types.Array) and array.dtype == types.float64):
            raise TypeError("llm_simd takes float64 arrays")
        if array.ndim != ndim or array.layout != "C":
            raise TypeError("llm_simd takes C-contiguous arrays of the map's ranks")


def _splat(builder: ir.IRBuilder, value: ir.Value) -> ir.Value:
    """A vector of LANES copies of ``value`` (a double or an integer)."""
    vector = ir.VectorType(value.type, LANES)
    one = builder.insert_element(ir.Constant(vector, ir.Undefined), value, ir.Constant(ir.IntType(32), 0))
    zeros = ir.Constant(ir.VectorType(ir.IntType(32), LANES), [0] * LANES)
    return builder.shuffle_vector(one, ir.Constant(vector, ir.Undefined), zeros)


def _vector_at(builder: ir.IRBuilder, data: ir.Value, index: ir.Value) -> ir.Value:
    """Pointer to the LANES doubles from ``data[index]``."""
    return builder.bitcast(builder.gep(data, [index]), _VECTOR.as_pointer())


class _Arrays:
    """The data pointers and sizes of the map's arrays, read in the IR."""

    def __init__(self, context: Any, builder: ir.IRBuilder, sig: Any, args: Any) -> None:
        models = context.make_array(sig.args[0])(context, builder, args[0])
        inputs = context.make_array(sig.args[1])(context, builder, args[1])
        act = context.make_array(sig.args[2])(context, builder, args[2])
        self.models, self.inputs, self.act = models.data, inputs.data, act.data
        _, self.columns, self.width = cgutils.unpack_tuple(builder, models.shape)  # n + 1, lanes * blocks
        self.row = cgutils.unpack_tuple(builder, inputs.shape)[1]  # inputs[j, k] at j * row + k
        self.stride = builder.mul(self.columns, self.width)  # doubles per prototype


@intrinsic
def block_sum(typingctx: Any, models: Any, inputs: Any, act: Any, K: Any, block: Any) -> Any:
    """sum_k act[k] * y_k over k = 0..K-1 in order, y_k = o_k + W_k u_k (Eq. of Sec. II-C), one block.

    Lane r holds output i = LANES * block + r: y = models[k, 0, i], then y += models[k, 1 + j, i]
    * inputs[j, k] for j = 0..n-1 in order, then s += act[k] * y. Returns the LANES sums.
    """
    _check(models, inputs, act)
    sig = types.UniTuple(types.float64, LANES)(models, inputs, act, types.intp, types.intp)
    return sig, _sum_codegen(indexed=False)


@intrinsic
def block_sum_near(typingctx: Any, models: Any, inputs: Any, act: Any, nearby: Any, block: Any) -> Any:
    """:func:`block_sum` over the prototypes listed in ``nearby`` only: k = nearby[1 + t], t < nearby[0].

    Their inputs u_k side by side in the list's order: ``inputs[j, t]`` (``act[t]`` likewise).

    The sums of a truncated map (:func:`~gb_pin.learn.llm_kernels.llm_predict` with a cutoff), in
    the order of the list (increasing k).
    """
    _check(models, inputs, act)
    _check_index(nearby)
    sig = types.UniTuple(types.float64, LANES)(models, inputs, act, nearby, types.intp)
    return sig, _sum_codegen(indexed=True)


def _check_index(nearby: Any) -> None:
    if not (isinstance(nearby, types.Array) and nearby.dtype == types.int64 and nearby.ndim == 1):
        raise TypeError("llm_simd takes an int64 list of prototypes")


def _loop_k(builder: ir.IRBuilder, context: Any, signature: Any, args: Any, indexed: bool) -> Any:
    """The loop over the prototypes: k = 0..K-1 (args[3] = K), or k = nearby[1 + t] for t < nearby[0]."""
    if not indexed:
        count = args[3]
        return count, lambda index: index
    data = context.make_array(signature.args[3])(context, builder, args[3]).data
    count = builder.load(data)
    one = ir.Constant(count.type, 1)
    return count, lambda index: builder.load(builder.gep(data, [builder.add(index, one)]))


def _sum_codegen(indexed: bool) -> Any:
    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        a = _Arrays(context, builder, signature, args)
        blk = args[4]
        count, k_of = _loop_k(builder, context, signature, args, indexed)
        offset = builder.mul(blk, ir.Constant(blk.type, LANES))
        total = cgutils.alloca_once_value(builder, ir.Constant(_VECTOR, [0.0] * LANES))

        def body(inputs_n: int | None) -> None:
            # The loop over k; with a known input count n, the sum over j written out.
            with cgutils.for_range(builder, count) as loop_k:
                k = k_of(loop_k.index)
                base = builder.add(builder.mul(k, a.stride), offset)
                y = builder.load(_vector_at(builder, a.models, base), align=8)
                for j in range(inputs_n or 0):
                    y = builder.fadd(y, _product(builder, a, base, ir.Constant(k.type, j), loop_k.index))
                if inputs_n is None:
                    local = cgutils.alloca_once_value(builder, y)
                    count_j = builder.sub(a.columns, ir.Constant(a.columns.type, 1))
                    with cgutils.for_range(builder, count_j) as loop_j:
                        step = _product(builder, a, base, loop_j.index, loop_k.index)
                        builder.store(builder.fadd(builder.load(local), step), local)
                    y = builder.load(local)
                b = builder.load(builder.gep(a.act, [loop_k.index]))  # act in the loop's order
                builder.store(builder.fadd(builder.load(total), builder.fmul(_splat(builder, b), y)), total)

        _by_input_count(builder, a, body)
        result = builder.load(total)
        lanes = [builder.extract_element(result, ir.Constant(ir.IntType(32), r)) for r in range(LANES)]
        return context.make_tuple(builder, signature.return_type, lanes)

    return codegen


@intrinsic
def block_update(
    typingctx: Any, models: Any, inputs: Any, act: Any, K: Any, block: Any, errors: Any, scale: Any, used: Any
) -> Any:
    """o_k += c_k e, W_k += (c_k e) u_k^T with c_k = scale * act[k], for k = 0..K-1, one block.

    Lane r is output i = LANES * block + r: c = scale * act[k]; ce = c * errors[i];
    models[k, 0, i] += ce; models[k, 1 + j, i] += ce * inputs[j, k]. Lanes r >= ``used`` (the
    padding after the last output: the ones and zeros of the sums) are left as they are.
    """
    _check(models, inputs, act)
    if not (isinstance(errors, types.Array) and errors.dtype == types.float64 and errors.ndim == 1):
        raise TypeError("llm_simd takes float64 errors")
    sig = types.void(models, inputs, act, types.intp, types.intp, errors, types.float64, types.intp)
    return sig, _update_codegen(indexed=False)


@intrinsic
def block_update_near(
    typingctx: Any,
    models: Any,
    inputs: Any,
    act: Any,
    nearby: Any,
    block: Any,
    errors: Any,
    scale: Any,
    used: Any,
) -> Any:
    """:func:`block_update` of the prototypes listed in ``nearby`` only (k = nearby[1 + t], t < nearby[0]).

    Their inputs in the list's order, ``inputs[j, t]``, as :func:`block_sum_near` reads them.
    """
    _check(models, inputs, act)
    _check_index(nearby)
    if not (isinstance(errors, types.Array) and errors.dtype == types.float64 and errors.ndim == 1):
        raise TypeError("llm_simd takes float64 errors")
    sig = types.void(models, inputs, act, nearby, types.intp, errors, types.float64, types.intp)
    return sig, _update_codegen(indexed=True)


def _update_codegen(indexed: bool) -> Any:
    def codegen(context: Any, builder: ir.IRBuilder, signature: Any, args: Any) -> Any:
        a = _Arrays(context, builder, signature, args)
        blk, scale, used = args[4], args[6], args[7]
        count, k_of = _loop_k(builder, context, signature, args, indexed)
        errors_data = context.make_array(signature.args[5])(context, builder, args[5]).data
        offset = builder.mul(blk, ir.Constant(blk.type, LANES))
        e = builder.load(_vector_at(builder, errors_data, offset), align=8)
        lane = ir.Constant(ir.VectorType(used.type, LANES), list(range(LANES)))
        mask = builder.icmp_signed("<", lane, _splat(builder, used))

        def add(ptr: ir.Value, step: ir.Value) -> None:
            old = builder.load(ptr, align=8)
            builder.store(builder.select(mask, builder.fadd(old, step), old), ptr, align=8)

        def body(inputs_n: int | None) -> None:
            with cgutils.for_range(builder, count) as loop_k:
                k = k_of(loop_k.index)
                base = builder.add(builder.mul(k, a.stride), offset)
                c = builder.fmul(scale, builder.load(builder.gep(a.act, [loop_k.index])))
                ce = builder.fmul(_splat(builder, c), e)
                add(_vector_at(builder, a.models, base), ce)
                for j in range(inputs_n or 0):
                    _update_column(builder, a, base, ir.Constant(k.type, j), loop_k.index, ce, add)
                if inputs_n is None:
                    count_j = builder.sub(a.columns, ir.Constant(a.columns.type, 1))
                    with cgutils.for_range(builder, count_j) as loop_j:
                        _update_column(builder, a, base, loop_j.index, loop_k.index, ce, add)

        _by_input_count(builder, a, body)
        return context.get_dummy_value()

    return codegen


def _column(builder: ir.IRBuilder, a: _Arrays, base: ir.Value, j: ir.Value) -> ir.Value:
    """Pointer to column j of W_k (``models[k, 1 + j, block]``), ``base`` pointing at o_k's block."""
    return _vector_at(
        builder, a.models, builder.add(base, builder.mul(builder.add(j, ir.Constant(j.type, 1)), a.width))
    )


def _input(builder: ir.IRBuilder, a: _Arrays, j: ir.Value, t: ir.Value) -> ir.Value:
    """u_kj = ``inputs[j, t]`` (t the loop's index: k, or the place of k in the list), in every lane."""
    return _splat(builder, builder.load(builder.gep(a.inputs, [builder.add(builder.mul(j, a.row), t)])))


def _product(builder: ir.IRBuilder, a: _Arrays, base: ir.Value, j: ir.Value, t: ir.Value) -> ir.Value:
    """Column j of W_k times u_kj = inputs[j, t] (W first, as in the scalar loops)."""
    return builder.fmul(builder.load(_column(builder, a, base, j), align=8), _input(builder, a, j, t))


def _update_column(
    builder: ir.IRBuilder, a: _Arrays, base: ir.Value, j: ir.Value, t: ir.Value, ce: ir.Value, add: Any
) -> None:
    """Column j of W_k += ce * u_kj, u_kj = inputs[j, t]."""
    add(_column(builder, a, base, j), builder.fmul(ce, _input(builder, a, j, t)))


def _by_input_count(builder: ir.IRBuilder, a: _Arrays, body: Any) -> None:
    """``body(n)`` for the input counts 2 and 3 written out (constant n), ``body(None)`` otherwise."""
    inputs_n = builder.sub(a.columns, ir.Constant(a.columns.type, 1))
    is3 = builder.icmp_signed("==", inputs_n, ir.Constant(inputs_n.type, 3))
    with builder.if_else(is3) as (three, other):
        with three:
            body(3)
        with other:
            is2 = builder.icmp_signed("==", inputs_n, ir.Constant(inputs_n.type, 2))
            with builder.if_else(is2) as (two, rest):
                with two:
                    body(2)
                with rest:
                    body(None)
