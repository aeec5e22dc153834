"""The shared text/TOML reader: every way a user file can be unreadable is one named line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from auvplan.errors import DataFormatError
from auvplan.io.text import read_text, read_toml


def _write(tmp_path: Path, content: bytes, name: str = "file.toml") -> Path:
    path = tmp_path / name
    path.write_bytes(content)
    return path


def test_reads_utf8_and_drops_a_byte_order_mark(tmp_path: Path) -> None:
    path = _write(tmp_path, '\ufeffname = "Ø-boat"\n[hull]\nm = 3\n'.encode())
    assert read_toml(path, what="vehicle file") == {"name": "Ø-boat", "hull": {"m": 3}}
    assert read_text(path, what="vehicle file").startswith("name")


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b'name = "x\xff"\n', "not UTF-8 text (byte 0xff at offset 9)"),
        (b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n", "nested too deeply"),
        (b"a = 1" + b"0" * 5000 + b"\n", "not valid TOML (Exceeds the limit"),
        (b"name = = 1\n", "not valid TOML (Invalid value (at line 1, column 8))"),
        (b"a = 1\x00\n", "not valid TOML"),
    ],
    ids=["latin-1", "deep-array", "huge-integer", "syntax", "nul-byte"],
)
def test_bad_content_is_one_line_naming_what_and_file(
    tmp_path: Path, content: bytes, message: str
) -> None:
    path = _write(tmp_path, content)
    with pytest.raises(DataFormatError, match=re.escape(message)) as info:
        read_toml(path, what="mission file")
    text = str(info.value)
    assert text.startswith(f"mission file {path}: ")
    assert "\n" not in text


def test_missing_file_and_folder(tmp_path: Path) -> None:
    with pytest.raises(DataFormatError, match=r"vehicle file .*nope\.toml: file not found"):
        read_toml(tmp_path / "nope.toml", what="vehicle file")
    with pytest.raises(DataFormatError, match="is a folder, not a file"):
        read_text(tmp_path, what="propeller table")
