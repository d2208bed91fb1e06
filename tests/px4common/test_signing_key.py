"""The one signing key file reader (px4common/signing_key.py) that `sitl-emu serve --signing-key` and `joyfly fly
--signing-key` share: the key as hex or raw, PX4's own 40-byte file, and one sentence for anything else."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from px4common.signing_key import SigningKeyError, read_signing_key

KEY = hashlib.sha256(b"px4common signing").digest()


@pytest.mark.parametrize("content", [
    KEY.hex().encode(),  # what `openssl rand -hex 32` writes
    b"  " + KEY.hex().upper().encode() + b"\r\n",  # white space around the digits, either case
    KEY,  # the raw 32 bytes
    KEY + (1234).to_bytes(8, "little"),  # PX4's mavlink-signing-key.bin: the key, then the timestamp
], ids=["hex", "hex-upper-spaced", "raw", "px4-file"])
def test_every_kind_of_key_file_gives_the_key(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "key"
    path.write_bytes(content)
    assert read_signing_key(path) == KEY
    assert read_signing_key(str(path)) == KEY


@pytest.mark.parametrize("content", [b"", b"short", b"0" * 63, b"0" * 65, KEY.hex()[:-1].encode() + b"g", KEY + b"x"],
                         ids=["empty", "short", "63-digits", "65-digits", "not-hex", "33-bytes"])
def test_a_file_without_a_key_is_one_sentence_that_says_how_to_make_one(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "my.key"
    path.write_bytes(content)
    with pytest.raises(SigningKeyError) as err:
        read_signing_key(path)
    text = str(err.value)
    assert text.startswith(f"--signing-key {path}: not a MAVLink signing key") and "\n" not in text
    assert "openssl rand -hex 32 > my.key" in text


def test_an_unreadable_file_is_one_sentence(tmp_path: Path) -> None:
    missing = tmp_path / "missing"
    with pytest.raises(SigningKeyError, match=r"cannot read it \(No such file or directory\)\.$"):
        read_signing_key(missing)
    if os.name == "posix" and os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.write_text(KEY.hex())
        locked.chmod(0)
        with pytest.raises(SigningKeyError, match=r"cannot read it \(Permission denied\)\.$"):
            read_signing_key(locked)
