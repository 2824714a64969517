"""A dataclass of arrays as one numba struct: many arrays cross into compiled code as one.

Calling a compiled function from Python checks and unboxes each of its arguments, about 50 ns
an array; a step's stages read about a hundred. :func:`as_struct` packs a frozen dataclass whose
fields are arrays, numbers or other such dataclasses into one numba structure (a StructRef
holding the very same arrays, shared, not copied). Compiled code reads it field by field
(``s.state.q``); from Python it crosses into compiled code in about half a microsecond, whatever
it holds.

Its numba type is made from the field names and types only, so two dataclasses of the same
layout have the same type: a compiled function taking it is compiled once per layout and then
loaded from numba's cache. Arrays must therefore keep their kind from run to run: every array
field is C-contiguous and writable (:func:`as_struct` refuses others). Making a struct
compiles nothing: its memory is laid out and filled from Python
(:mod:`dvqp.workspace.struct_memory`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.core.extending import NativeValue, box, unbox
from numba.experimental import structref
from numba.experimental.structref import _Utils

from dvqp.workspace.struct_memory import build


@structref.register
class ArraysType(types.StructRef):
    """The numba type of a packed dataclass: its fields' names and types."""

    def preprocess_fields(self, fields):  # type: ignore[no-untyped-def]
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class Arrays(structref.StructRefProxy):
    """A packed dataclass on the Python side (only handed to compiled code).

    Its numba type is a plain attribute, not numba's property: numba reads it on every call
    with ``PyObject_HasAttr``, which clears any exception. Python code run there (a property)
    is where a pending Ctrl-C is raised, and the KeyboardInterrupt would be lost.
    """

    _numba_type_: Any = None  # shadows StructRefProxy's property; set per instance when boxed

    @classmethod
    def _numba_box_(cls, ty: Any, mi: Any) -> Arrays:
        instance = super()._numba_box_(ty, mi)
        instance._numba_type_ = ty
        return instance  # type: ignore[no-any-return]


@box(ArraysType)
def _box(typ, val, c):  # type: ignore[no-untyped-def]
    """An :class:`Arrays` holding the struct, or NULL with the exception raised on the way.

    numba's own boxing of a StructRef fetches the constructor and the type with two
    ``numba_unpickle`` calls, which run Python code, where a pending Ctrl-C is raised; it
    then calls the constructor with whatever came back. A NULL ends the argument list, so
    the constructor was called with none and a TypeError replaced the KeyboardInterrupt.
    Here each step runs only if the one before succeeded (no Python code runs with an
    exception set), and a failure returns NULL with that exception.
    """
    meminfo = _Utils(c.context, c.builder, typ).get_struct_ref(val).meminfo
    held = c.box(types.MemInfoPointer(types.voidptr), meminfo)  # owns the struct's reference
    result = cgutils.alloca_once_value(c.builder, c.pyapi.get_null_object())
    make = c.pyapi.unserialize(c.pyapi.serialize_object(Arrays._numba_box_))
    with c.builder.if_then(cgutils.is_not_null(c.builder, make), likely=True):
        kind = c.pyapi.unserialize(c.pyapi.serialize_object(typ))
        with c.builder.if_then(cgutils.is_not_null(c.builder, kind), likely=True):
            c.builder.store(c.pyapi.call_function_objargs(make, [kind, held]), result)
        c.pyapi.decref(kind)
    c.pyapi.decref(make)
    c.pyapi.decref(held)  # NULL-safe; on failure this frees the struct
    return c.builder.load(result)


@unbox(ArraysType)
def _unbox(typ, obj, c):  # type: ignore[no-untyped-def]
    """The struct an :class:`Arrays` holds (as numba's own unboxing of a StructRef)."""
    held = c.pyapi.object_getattr_string(obj, "_meminfo")
    meminfo = c.unbox(types.MemInfoPointer(types.voidptr), held).value
    value = _Utils(c.context, c.builder, typ).new_struct_ref(meminfo)._getvalue()
    c.pyapi.decref(held)
    return NativeValue(value)


def as_struct(value: Any) -> Arrays:
    """``value`` (a dataclass instance) as one numba struct of the same fields.

    Fields may be arrays (C-contiguous, writable), Python or NumPy numbers and booleans, or
    dataclasses of the same kind (packed recursively). Nothing is compiled: the struct is laid
    out in Python (:mod:`dvqp.workspace.struct_memory`), field by field as numba's own
    constructor would, each array holding a reference to its ndarray as an argument's does.

    Raises
    ------
    TypeError
        A field of another kind, or an array that is not C-contiguous and writable.
    """
    names, items = [], []
    for field in dataclasses.fields(value):
        item = getattr(value, field.name)
        names.append(field.name)
        items.append(as_struct(item) if dataclasses.is_dataclass(item) else _packable(field, item))
    fields = tuple((name, _type_of(item)) for name, item in zip(names, items, strict=True))
    kind = _kind(fields)
    return Arrays._numba_box_(kind, build(kind, items))  # type: ignore[no-any-return]


def struct_type(value: Any) -> ArraysType:
    """The numba type :func:`as_struct` gives ``value``, without packing it (e.g. to compile a
    kernel for a struct before it exists)."""
    fields = []
    for field in dataclasses.fields(value):
        item = getattr(value, field.name)
        if dataclasses.is_dataclass(item):
            fields.append((field.name, struct_type(item)))
        else:
            fields.append((field.name, _type_of(_packable(field, item))))
    return _kind(tuple(fields))


def _packable(field: dataclasses.Field[Any], item: Any) -> Any:
    """``item``, if :func:`as_struct` can pack it (else TypeError)."""
    if isinstance(item, np.ndarray):
        if not (item.flags.c_contiguous and item.flags.writeable):
            raise TypeError(f"{field.name}: a packed array must be C-contiguous, writable")
    elif not isinstance(item, bool | int | float | np.number | np.bool_):
        raise TypeError(f"{field.name}: cannot pack a {type(item).__name__}")
    return item


def _kind(fields: tuple[tuple[str, Any], ...]) -> ArraysType:
    """The struct type of these fields (made once)."""
    kind = _KINDS.get(fields)
    if kind is None:
        kind = _KINDS[fields] = ArraysType(list(fields))
    return kind


_KINDS: dict[tuple[tuple[str, Any], ...], ArraysType] = {}
"""The struct types made, by their fields' names and types (one took ~75 µs to make,
under cProfile)."""


_ARRAY_TYPES: dict[tuple[np.dtype[Any], int], Any] = {}
"""numba's type of a C-contiguous, writable, aligned array, by dtype and dimensions."""


def _type_of(item: Any) -> Any:
    """``numba.typeof(item)``; for an array as :func:`as_struct` takes them (C-contiguous,
    writable), from a table by dtype and dimensions (``typeof`` took ~16 µs an array under
    cProfile, and a struct of a step's buffers holds over a hundred)."""
    if not (isinstance(item, np.ndarray) and item.flags.aligned):
        return numba.typeof(item)
    key = (item.dtype, item.ndim)
    found = _ARRAY_TYPES.get(key)
    if found is None:
        found = _ARRAY_TYPES[key] = numba.typeof(item)
    return found
