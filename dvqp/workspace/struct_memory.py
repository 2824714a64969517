"""A packed struct's memory, laid out and filled from Python: no compile a struct type.

numba's way to make a StructRef is a compiled constructor per struct type; its CPython wrapper
unboxes every field, so each took 70 ms plus 12 ms a field to compile, about 2.5-3.5 s of a
cold plan's 16 struct types. :func:`build` does the same work with the runtime's own C
helpers, which numba's argument unboxing calls too:

- the memory is one NRT allocation (``NRT_MemInfo_alloc_dtor``), zeroed, laid out as numba's
  data model lays out the struct's payload (field offsets read from that model and the target's
  data layout, never assumed);
- an array field is filled by ``NRT_adapt_ndarray_from_python``, exactly as an array argument
  is: a meminfo holding a reference to the ndarray, its data pointer, shape and strides;
- a struct field holds a new reference to that struct's meminfo
  (``NRT_meminfo_from_pyobject``);
- a number is written in its data representation (a boolean as one byte, 0 or 1).

The destructor, run when the last reference goes (from Python or from compiled code), releases
every meminfo the struct holds then, read from the fields at that moment (as numba's generated
destructors do: a field a compiled function rebinds releases the array it holds then). It is
one small function for every struct type: it reads the offsets of the fields that hold a
meminfo from a trailer after the payload, ``[offset_1 … offset_k, k]`` (int64), and is built
once per process from LLVM IR (a few milliseconds; nothing to cache). It calls no Python code,
so a Ctrl-C can never be raised, and lost, inside it.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import cpu_target
from numba.core.runtime import _nrt_python
from numba.np.numpy_support import as_dtype

from solvers.linking import ir_functions

_HELPERS = _nrt_python.c_helpers
# PYFUNCTYPE, not CFUNCTYPE: ctypes keeps the GIL held through the call (CFUNCTYPE releases
# it, and adapt_ndarray_from_python increfs the ndarray: another thread's reference counting
# would race it).
_alloc = ctypes.PYFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p)(
    _HELPERS["MemInfo_alloc_dtor"]
)
_data_of = ctypes.PYFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p)(_HELPERS["MemInfo_data"])
_adapt = ctypes.PYFUNCTYPE(ctypes.c_int, ctypes.py_object, ctypes.c_void_p)(
    _HELPERS["adapt_ndarray_from_python"]
)
_acquired = ctypes.PYFUNCTYPE(ctypes.c_void_p, ctypes.py_object)(_HELPERS["meminfo_from_pyobject"])

_WORD = 8  # bytes of a trailer entry (int64), and the trailer's alignment


@dataclass(frozen=True)
class Layout:
    """Where a struct type's fields sit in its allocation.

    Attributes
    ----------
    size : int
        Bytes allocated: the payload, then the trailer.
    fields : tuple of (int, str, object)
        Per field in order: its offset (bytes), its kind (``"array"``, ``"struct"`` or
        ``"number"``) and what it must be given: an array's dtype and dimensions, a struct's
        numba type, the dtype a number is stored as.
    trailer : bytes
        The offsets of the fields holding a meminfo, then their count (int64 each), written
        at the end of the allocation for the destructor.
    """

    size: int
    fields: tuple[tuple[int, str, Any], ...]
    trailer: bytes


_LAYOUTS: dict[Any, Layout] = {}
_DESTRUCTOR: list[Any] = []  # the code library (kept alive) and the function's address


def layout(kind: Any) -> Layout:
    """The :class:`Layout` of the struct type ``kind`` (a ``types.StructRef``), made once."""
    found = _LAYOUTS.get(kind)
    if found is not None:
        return found
    for name, member in kind.field_dict.items():
        element = member.dtype if isinstance(member, types.Array) else member
        if not (isinstance(member, types.StructRef) or _numeric(element)):
            raise TypeError(f"{name}: cannot lay out a {member} field")
    context = cpu_target.target_context
    payload = context.data_model_manager[kind.get_data_type()]
    data_type = payload.get_data_type()
    target = context.target_data
    size = max(context.get_abi_sizeof(data_type), context.get_abi_sizeof(payload.get_value_type()))
    fields, held = [], []
    for index, member in enumerate(kind.field_dict.values()):
        offset = data_type.get_element_offset(target, index)
        if isinstance(member, types.Array):
            _meminfo_first(context, member)
            fields.append((offset, "array", (np.dtype(as_dtype(member.dtype)), member.ndim)))
            held.append(offset)
        elif isinstance(member, types.StructRef):
            _meminfo_first(context, member)
            fields.append((offset, "struct", member))
            held.append(offset)
        else:
            dtype = np.dtype(as_dtype(member))
            if dtype.itemsize != context.get_abi_sizeof(context.get_data_type(member)):
                raise TypeError(f"cannot lay out a {member} field")
            fields.append((offset, "number", dtype))
    start = -(-size // _WORD) * _WORD
    trailer = np.array([*held, len(held)], dtype=np.int64).tobytes()
    found = _LAYOUTS[kind] = Layout(start + len(trailer), tuple(fields), trailer)
    return found


def _numeric(member: Any) -> bool:
    """Whether ``member`` is a boolean, an integer or a float numba and NumPy share."""
    if not isinstance(member, types.Boolean | types.Integer | types.Float):
        return False
    try:
        as_dtype(member)
        cpu_target.target_context.data_model_manager[member]
    except NotImplementedError:  # e.g. a float16: a dtype, but no numba data model
        return False
    return True


def _meminfo_first(context: Any, member: Any) -> None:
    """Check that ``member``'s data starts with its meminfo (where the destructor reads it)."""
    model = context.data_model_manager[member]
    if model._fields[0] != "meminfo":  # numba's ArrayModel and StructRefModel both do
        raise TypeError(f"cannot lay out a {member} field: its data does not start with meminfo")


def build(kind: Any, items: list[Any]) -> Any:
    """A new struct of type ``kind`` holding ``items`` (its fields' values, in order), as the
    runtime's ``MemInfo`` object that owns it (wrap it with ``_numba_box_``).

    Raises
    ------
    MemoryError
        The runtime could not allocate it.
    TypeError
        An item that is not of its field's type (nothing is written for it: the fields
        filled before it are released with the struct).

    A Ctrl-C (KeyboardInterrupt) between two of these calls leaves no field half written;
    it may leak the allocation (raised before its owner exists) or one reference to a nested
    struct (raised between taking it and storing it): a reference is always taken before it
    is stored, so an interruption can never release one too many.
    """
    plan = layout(kind)
    address = _alloc(plan.size, destructor())
    if not address:
        raise MemoryError("the numba runtime could not allocate a struct")
    data = _data_of(address)
    ctypes.memset(data, 0, plan.size)  # a half-filled struct frees only what it holds
    ctypes.memmove(data + plan.size - len(plan.trailer), plan.trailer, len(plan.trailer))
    owner = _nrt_python._MemInfo(address)  # takes the allocation's reference
    for (offset, what, expected), item in zip(plan.fields, items, strict=True):
        if what == "array":
            if not isinstance(item, np.ndarray) or (item.dtype, item.ndim) != expected:
                raise TypeError(f"not a {expected[1]}-d {expected[0]} ndarray: {item!r:.60}")
            _adapt(item, data + offset)
        elif what == "struct":
            if getattr(item, "_numba_type_", None) != expected:
                raise TypeError(f"not a struct of type {expected}: {type(item).__name__}")
            ctypes.c_void_p.from_address(data + offset).value = _acquired(item._meminfo)
        else:
            number = np.array(item, dtype=expected)
            ctypes.memmove(data + offset, number.ctypes.data, number.itemsize)
    return owner


def destructor() -> int:
    """The address of the destructor every struct shares (built at the first call)."""
    if not _DESTRUCTOR:
        _build_destructor()
    return int(_DESTRUCTOR[1])


@global_compiler_lock
def _build_destructor() -> None:
    """Build :func:`destructor`'s function (once, whichever thread asks first)."""
    if not _DESTRUCTOR:
        names = ["dvqp_release_fields"]
        library, (address,) = ir_functions("dvqp.workspace.struct_memory", _release_fields, names)
        _DESTRUCTOR.extend([library, address])


def _release_fields(module: ir.Module) -> None:
    """Define ``void dvqp_release_fields(i8* data, i64 size, i8* info)``: release the meminfo
    at each offset the trailer at ``data + size`` lists (a NULL one is skipped)."""
    byte_pointer = ir.IntType(8).as_pointer()
    word = ir.IntType(64)
    kind = ir.FunctionType(ir.VoidType(), [byte_pointer, word, byte_pointer])
    function = ir.Function(module, kind, name="dvqp_release_fields")
    release = cgutils.get_or_insert_function(
        module, ir.FunctionType(ir.VoidType(), [byte_pointer]), "NRT_MemInfo_release"
    )
    data, size, _ = function.args
    builder = ir.IRBuilder(function.append_basic_block("entry"))

    def word_at(offset: ir.Value) -> ir.Value:
        at = builder.gep(data, [offset])
        return builder.load(builder.bitcast(at, word.as_pointer()))

    last = builder.sub(size, ir.Constant(word, _WORD))
    count = word_at(last)
    with cgutils.for_range(builder, count) as loop:
        back = builder.mul(builder.add(loop.index, ir.Constant(word, 1)), ir.Constant(word, _WORD))
        offset = word_at(builder.sub(last, back))
        field = builder.bitcast(builder.gep(data, [offset]), byte_pointer.as_pointer())
        meminfo = builder.load(field)
        with builder.if_then(cgutils.is_not_null(builder, meminfo)):
            builder.call(release, [meminfo])
    builder.ret_void()
