"""Completeness checks: every value a bathymetry file declares must be in the file.

A download cut short leaves a file whose header still declares the whole grid. NetCDF-3
readers then return the missing values as fill values, which the planner would take as two
thirds of no-data plus garbage rows; GDAL fails with a message that names neither the file
nor the count. Each check here compares the size the header declares with the bytes (or
values) present and raises :class:`~auvplan.errors.DataFormatError` naming the missing
fraction, before any value is read.
"""

from __future__ import annotations

import struct
from typing import TYPE_CHECKING, BinaryIO, Final

import numpy as np

from auvplan.errors import DataFormatError

if TYPE_CHECKING:
    from pathlib import Path

    from rasterio.io import DatasetReader

#: What the messages suggest; every check here is about a file cut short.
_ADVICE: Final = "an interrupted download or copy? fetch the file again"

#: Bytes per value of each NetCDF-3 external type (CDF-1, CDF-2 and CDF-5 / 64-bit data).
_NC_TYPE_SIZES: Final = {1: 1, 2: 1, 3: 2, 4: 4, 5: 4, 6: 8, 7: 1, 8: 2, 9: 4, 10: 8, 11: 8}
_NC_DIMENSION, _NC_VARIABLE, _NC_ATTRIBUTE = 0x0A, 0x0B, 0x0C
_NC_STREAMING: Final = 0xFFFFFFFF

#: Bytes read per step when counting the values of a text grid.
_CHUNK_BYTES: Final = 1 << 24


def check_netcdf_complete(path: Path) -> None:
    """Raise DataFormatError if ``path`` (NetCDF-3 or NetCDF-4/HDF5) is shorter than declared.

    NetCDF-3: every variable's data, placed by the header's offsets, must lie inside the file.
    NetCDF-4: the file must reach the end-of-file address of its HDF5 superblock.
    """
    size = path.stat().st_size
    with path.open("rb") as stream:
        magic = stream.read(8)
        stream.seek(4 if magic.startswith(b"CDF") else 0)
        if magic.startswith(b"CDF"):
            _check_classic(_Header(stream, version=magic[3]), size)
        elif magic == b"\x89HDF\r\n\x1a\n":
            _check_hdf5(stream, size)


def check_tiff_complete(source: DatasetReader, size: int) -> None:
    """Raise DataFormatError if a strip or tile of band 1 of a GeoTIFF ends past ``size`` [B].

    The offsets and byte counts are the TIFF header's (GDAL's ``BLOCK_OFFSET_*`` and
    ``BLOCK_SIZE_*`` items); sparse blocks (offset 0) are no data by design and not missing.
    """
    n_missing = 0
    for (row, col), window in source.block_windows(1):
        offset = source.get_tag_item(f"BLOCK_OFFSET_{col}_{row}", "TIFF", bidx=1)
        count = source.get_tag_item(f"BLOCK_SIZE_{col}_{row}", "TIFF", bidx=1)
        if offset is None or count is None:
            return  # not a plain TIFF layout GDAL reports: leave the check to the read
        if int(offset) > 0 and int(offset) + int(count) > size:
            n_missing += int(window.width * window.height)
    if n_missing:
        n_values = source.width * source.height
        raise DataFormatError(
            f"truncated GeoTIFF: the file has {size} bytes but its header places data past "
            f"them; {n_missing} of the {n_values} values ({_percent(n_missing, n_values)}) are "
            f"missing ({_ADVICE})"
        )


def check_ascii_grid_complete(path: Path, n_rows: int, n_cols: int) -> None:
    """Raise DataFormatError unless an ESRI ASCII grid holds its ``n_rows * n_cols`` values.

    ``n_rows`` and ``n_cols`` are the header's ``nrows`` and ``ncols``. The values are the
    whitespace-separated words after the header's keyword lines (``ncols``, ``nrows``,
    ``xllcorner`` …, each a keyword and a value).
    """
    n_declared = n_rows * n_cols
    n_words = 0
    is_space_before = True
    with path.open("rb") as stream:
        while line := stream.readline():  # the header: lines starting with a keyword
            if not line.lstrip()[:1].isalpha():
                n_words += _count_words(line, is_space_before=True)
                is_space_before = line[-1:].isspace()
                break
        while chunk := stream.read(_CHUNK_BYTES):
            n_words += _count_words(chunk, is_space_before=is_space_before)
            is_space_before = chunk[-1:].isspace()
    if n_words < n_declared:
        raise DataFormatError(
            f"ESRI ASCII grid cut short: the header declares {n_rows} x {n_cols} = "
            f"{n_declared} values, the file holds {n_words} "
            f"({_percent(n_declared - n_words, n_declared)} missing; {_ADVICE})"
        )


def _percent(part: int, whole: int) -> str:
    """``part / whole`` as a percentage with 2 significant digits (``"67 %"``, ``"0.0074 %"``)."""
    return f"{100.0 * part / whole:.2g} %"


def _count_words(chunk: bytes, *, is_space_before: bool) -> int:
    """Number of whitespace-separated words starting in ``chunk``."""
    is_space = np.isin(
        np.frombuffer(chunk, dtype=np.uint8), np.frombuffer(b" \t\r\n\v\f", np.uint8)
    )
    previous = np.concatenate(([is_space_before], is_space[:-1]))
    return int(np.count_nonzero(previous & ~is_space))


class _Header:
    """Big-endian reader of a NetCDF-3 header; sizes are 4 bytes (CDF-1, -2) or 8 (CDF-5)."""

    def __init__(self, stream: BinaryIO, *, version: int) -> None:
        if version not in (1, 2, 5):
            raise DataFormatError(f"unknown NetCDF-3 version {version}")
        self.stream = stream
        self.count_format = ">Q" if version == 5 else ">I"
        self.offset_format = ">I" if version == 1 else ">Q"

    def read(self, n_bytes: int) -> bytes:
        data = self.stream.read(n_bytes)
        if len(data) < n_bytes:
            raise DataFormatError(f"truncated NetCDF: the file ends inside its header ({_ADVICE})")
        return data

    def unpack(self, form: str) -> int:
        value: int = struct.unpack(form, self.read(struct.calcsize(form)))[0]
        return value

    def count(self) -> int:
        return self.unpack(self.count_format)

    def offset(self) -> int:
        return self.unpack(self.offset_format)

    def name(self) -> str:
        length = self.count()
        return self.read(length + (-length) % 4)[:length].decode("utf-8", errors="replace")

    def list_length(self, tag: int) -> int:
        """Number of elements of the next list (``tag`` or ABSENT)."""
        found = self.unpack(">I")
        n_elements = self.count()
        if found not in (tag, 0) or (found == 0 and n_elements != 0):
            raise DataFormatError(f"malformed NetCDF header (list tag {found:#x})")
        return n_elements

    def skip_attributes(self) -> None:
        for _ in range(self.list_length(_NC_ATTRIBUTE)):
            self.name()
            n_bytes = self.value_size(self.unpack(">I")) * self.count()
            self.read(n_bytes + (-n_bytes) % 4)

    @staticmethod
    def value_size(nc_type: int) -> int:
        if nc_type not in _NC_TYPE_SIZES:
            raise DataFormatError(f"malformed NetCDF header (type {nc_type})")
        return _NC_TYPE_SIZES[nc_type]


def _check_classic(header: _Header, size: int) -> None:
    """Every NetCDF-3 variable's data must end inside the file of ``size`` bytes."""
    n_records = header.count()
    lengths = []
    for _ in range(header.list_length(_NC_DIMENSION)):
        header.name()
        lengths.append(header.count())
    header.skip_attributes()
    variables = []  # (name, begin [B], bytes per record or in all, is a record variable)
    for _ in range(header.list_length(_NC_VARIABLE)):
        name = header.name()
        dimensions = [header.count() for _ in range(header.count())]
        header.skip_attributes()
        value_size = header.value_size(header.unpack(">I"))
        header.count()  # vsize: padded, and clamped for huge variables; recomputed below
        begin = header.offset()
        is_record = bool(dimensions) and lengths[dimensions[0]] == 0
        shape = (
            [lengths[d] for d in dimensions[1:]] if is_record else [lengths[d] for d in dimensions]
        )
        variables.append((name, begin, value_size * int(np.prod(shape)), is_record))
    record_slabs = [n_bytes for _, _, n_bytes, is_record in variables if is_record]
    # one record variable: records are not padded (NetCDF classic format specification)
    stride = record_slabs[0] if len(record_slabs) == 1 else sum(n + (-n) % 4 for n in record_slabs)
    if n_records == _NC_STREAMING:
        n_records = 0  # the number of records follows from the file's size: nothing to check
    worst = ("", 0, 0)  # (name, missing bytes, declared bytes)
    for name, begin, n_bytes, is_record in variables:
        if is_record:
            n_present = sum(begin + r * stride + n_bytes <= size for r in range(n_records))
            missing, declared = (n_records - n_present) * n_bytes, n_records * n_bytes
        else:
            missing, declared = min(n_bytes, max(0, begin + n_bytes - size)), n_bytes
        if missing > worst[1]:
            worst = (name, missing, declared)
    name, missing, declared = worst
    if missing:
        raise DataFormatError(
            f"truncated NetCDF: the file has {size} bytes but its header places data past "
            f"them; {_percent(missing, declared)} of the values of {name} are missing "
            f"({_ADVICE})"
        )


def _check_hdf5(stream: BinaryIO, size: int) -> None:
    """The file must reach the end-of-file address its HDF5 superblock (at byte 0) records."""
    head = stream.read(64)
    if len(head) < 16:
        raise DataFormatError(f"truncated NetCDF-4: the file ends inside its header ({_ADVICE})")
    version = head[8]
    # superblock layouts (HDF5 file format specification, section II.A): where the byte
    # "size of offsets" and the first address are; the end-of-file address is the third
    if version in (0, 1):
        n_offset_bytes, first_address = head[13], 24 if version == 0 else 28
    elif version in (2, 3):
        n_offset_bytes, first_address = head[9], 12
    else:
        return  # a superblock this check does not know: leave it to the HDF5 library
    start = first_address + 2 * n_offset_bytes
    field = head[start : start + n_offset_bytes]
    if n_offset_bytes not in (2, 4, 8) or len(field) < n_offset_bytes:
        return
    end_of_file = int.from_bytes(field, "little")
    if end_of_file != (1 << (8 * n_offset_bytes)) - 1 and size < end_of_file:
        raise DataFormatError(
            f"truncated NetCDF-4: the file has {size} of the {end_of_file} bytes its HDF5 "
            f"superblock declares ({_percent(end_of_file - size, end_of_file)} missing; "
            f"{_ADVICE})"
        )
