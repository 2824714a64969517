"""Files a user gives to read: read within a bound, ``.npz`` members checked before inflating.

:func:`read_bounded` reads at most a given number of bytes of a file (a scene, a URDF, an
export's index) and refuses a larger one, so that neither a huge file nor an endless one
(``/dev/zero``) costs more memory than that. :class:`NpzArrays` opens an ``.npz`` file (a zip
of ``.npy`` files) and reads each member's declared size and ``.npy`` header, and nothing
else: the zip's central directory and the first few hundred bytes of each member. A caller
refuses a member whose shape is absurd for what it should hold before any of it is inflated;
:meth:`NpzArrays.read` then reads a member within its declared size, as an array only (never
pickled Python objects). Every refusal is an :class:`~dvqp.errors.InputFileError`.
"""

from __future__ import annotations

import math
import os
import zipfile
import zlib
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

import numpy as np

from dvqp.errors import InputFileError

MEMORY_SHARE = 0.8
"""Runs, and files read, whose arrays would need more than this share of the machine's memory
are refused."""
MAX_HEADER = 10_000
"""Longest ``.npy`` header read, bytes (numpy's own default bound)."""
_DAMAGE = (ValueError, EOFError, OSError, zipfile.BadZipFile, zlib.error, NotImplementedError)
"""What reading a damaged or unsupported zip member raises (``RuntimeError``, an encrypted
member, is caught where a member is opened)."""


def physical_memory() -> int | None:
    """The machine's memory, bytes (None where the system does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def size_text(nbytes: float) -> str:
    """``512 B``, ``3.2 kB``, ``112 MB``, ``2.1 GB`` (decimal units, 3 digits at most)."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes:.0f} B"


def read_bounded(path: str | Path, limit: int, what: str) -> bytes:
    """At most ``limit`` bytes of the file ``path``.

    Raises
    ------
    InputFileError
        ``<path>: cannot read: <reason>``, or ``<path>: larger than 16 MiB: not <what>``
        (``what`` says what the file should be, ``"a scene file"``).
    """
    try:
        with open(path, "rb") as fh:
            data = fh.read(limit + 1)
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        raise InputFileError(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}") from exc
    if len(data) > limit:
        raise InputFileError(path, f"larger than {limit >> 20} MiB: not {what}")
    return data


@dataclass(frozen=True)
class Member:
    """An ``.npy`` member as its header declares it: ``shape``, ``dtype`` and the ``nbytes``
    of its data (the zip's declared size of the member, less the header)."""

    shape: tuple[int, ...]
    dtype: np.dtype
    nbytes: int

    @property
    def width(self) -> int:
        """Values per row: the product of the shape after its first axis (1 for a scalar)."""
        return math.prod(self.shape[1:])


class NpzArrays:
    """The ``.npy`` members of the ``.npz`` file ``path``, by name without ``.npy``
    (:attr:`members`), checked against their declared sizes; :meth:`read` reads one.

    ``what`` names what the file should be (``"a dvqp trajectory"``): a file that is not one
    is refused as ``<path>: not <what> (<reason>)``. Use it as a context manager.

    Raises
    ------
    InputFileError
        ``cannot read: <reason>``; not a zip file; a member whose ``.npy`` header is damaged,
        declares another size than the zip does, or holds pickled Python objects.
    """

    def __init__(self, path: str | Path, what: str) -> None:
        self.path, self.what = str(path), what
        try:
            self._file = open(path, "rb")  # noqa: SIM115 - closed by close()
        except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
            reason = getattr(exc, "strerror", None) or exc
            raise InputFileError(path, f"cannot read: {reason}") from exc
        try:
            self._zip = zipfile.ZipFile(self._file)
        except (*_DAMAGE, RuntimeError) as exc:
            self._file.close()
            raise self.refused(f"damaged or not an .npz file: {exc}") from exc
        try:
            self.members = {
                info.filename[:-4]: self._header(info)
                for info in self._zip.infolist()
                if info.filename.endswith(".npy")
            }
        except BaseException:
            self.close()
            raise

    def refused(self, reason: str) -> InputFileError:
        """``<path>: not <what> (<reason>)``."""
        return InputFileError(self.path, f"not {self.what} ({reason})")

    def _header(self, info: zipfile.ZipInfo) -> Member:
        """The member's shape and type from its header (its first bytes, nothing more
        inflated), checked against the size the zip declares for it."""
        name = info.filename[:-4]
        try:
            with self._zip.open(info) as fp:
                version = np.lib.format.read_magic(fp)
                if version not in ((1, 0), (2, 0)):
                    raise ValueError(f".npy format version {version} is not read")
                read = (
                    np.lib.format.read_array_header_1_0
                    if version == (1, 0)
                    else np.lib.format.read_array_header_2_0
                )
                shape, _, dtype = read(fp, max_header_size=MAX_HEADER)
                data = info.file_size - fp.tell()
        except (*_DAMAGE, RuntimeError, SyntaxError) as exc:
            raise self.refused(f"member {name!r}: damaged: {exc}") from exc
        if dtype.hasobject:
            raise self.refused(f"member {name!r}: pickled Python objects are not read")
        member = Member(tuple(int(n) for n in shape), dtype, math.prod(shape) * dtype.itemsize)
        if member.nbytes != data:
            raise self.refused(
                f"member {name!r}: its header declares {member.shape} of {dtype} "
                f"({size_text(member.nbytes)}), the archive {size_text(max(data, 0))}"
            )
        return member

    def check_memory(self, names: Iterable[str]) -> None:
        """Refuse the file if the members ``names`` would need more than
        :data:`MEMORY_SHARE` of the machine's memory, before any is read."""
        total = sum(self.members[name].nbytes for name in names if name in self.members)
        memory = physical_memory()
        if memory and total > MEMORY_SHARE * memory:
            raise self.refused(
                f"its arrays declare {size_text(total)}, more than this machine's "
                f"{size_text(memory)} allow"
            )

    def read(self, name: str) -> np.ndarray:
        """The member ``name`` (one of :attr:`members`), read within its declared size."""
        try:
            with self._zip.open(f"{name}.npy") as fp:
                return np.lib.format.read_array(fp, allow_pickle=False, max_header_size=MAX_HEADER)
        except (*_DAMAGE, RuntimeError) as exc:
            raise self.refused(f"member {name!r}: damaged: {exc}") from exc

    def close(self) -> None:
        """Close the file."""
        self._zip.close()
        self._file.close()

    def __enter__(self) -> NpzArrays:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
