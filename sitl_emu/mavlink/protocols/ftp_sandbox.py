"""The file system a MAVLink FTP client sees: one root directory, and nothing outside it (ftp.py uses it).

PX4 prepends its root directory to every requested path (src/modules/mavlink/mavlink_ftp.cpp, `_root_dir`: the SITL
working directory), so "/log" and "log" both name root/log. Older PX4 then let "../" walk out of the root; current
PX4 refuses any ".." component and, on POSIX, resolves symbolic links before it lets a path through. The emulator
does the same, strictly, for every operation:

- a path is bytes up to its first NUL (a C string, as PX4 reads it); leading "/" are dropped, so an absolute path
  names a path under the root, never the host's;
- a ".." component is refused outright, even one that would stay inside the root;
- the path is resolved with every symbolic link followed (os.path.realpath) and must stay the root or below it;
  operations on the entry itself (remove, rename, mkdir) resolve only its parent and keep its own name, so a link
  inside the root is removed or renamed as a link, never its target.
A refused path raises PathRefused; the protocol answers it with PX4's FileProtected. Clients have no opcode that
creates a symbolic link, so a link can only be put into the root by whoever runs the emulator.

Mounts: PX4 SITL's root is its working directory, which holds log/ (the logger's files), etc/ (ROMFS, with the
component metadata under etc/extras) and the parameter file. The emulator keeps its writable root apart and shows
those as read-only mounts, each a top-level name standing for a host directory or file: "/log/..." names a path
under the mounted log directory (contained in it as strictly as the root), the root's listing shows each mount that
exists (a directory as D, a file as F with its size), and any write, create, remove, rename or mkdir at or under a
mount is refused (PathRefused: FileProtected, as PX4 answers a write to its read-only storage).

Also here: PX4's directory listing format and its CRC32 (crc32part: the CRC-32 table without the initial and
final inversion, src/lib/crc/crc.c; MAVSDK's core/crc32.cpp computes the same).
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Iterator, Mapping

DIRENT_FILE = b"F"  # F<name>\t<size>\0
DIRENT_DIR = b"D"  # D<name>\0
DIRENT_SKIP = b"S"  # S\0: ".", "..", links, devices, sockets (PX4 sends only files and directories)
CRC_CHUNK = 256  # PX4 reads the file in 256-byte pieces (_work_buffer2_len)


class PathRefused(Exception):
    """A path that would leave the root, or an operation the root itself must not undergo."""


class Sandbox:
    """Paths under `root` (created on first use, then resolved once: the root may itself be reached through a link),
    and the read-only `mounts` (top-level name -> host directory or file)."""

    def __init__(self, root: str | os.PathLike[str],
                 mounts: Mapping[str, str | os.PathLike[str]] | None = None) -> None:
        self._root_given = os.fsencode(root)
        self._root: bytes | None = None
        self.mounts = {os.fsencode(name): os.fsencode(path) for name, path in (mounts or {}).items()}

    @property
    def root(self) -> bytes:
        if self._root is None:
            os.makedirs(self._root_given, exist_ok=True)
            self._root = os.path.realpath(self._root_given)
        return self._root

    def target(self, raw: bytes, write: bool = False) -> bytes:
        """The object the path names, every link followed: for open, read, list, truncate, CRC (`write`: for a
        change, refused under a mount)."""
        parts = _parts(raw)
        if parts and parts[0] in self.mounts:
            if write:
                raise PathRefused("a read-only mount")
            base = os.path.realpath(self.mounts[parts[0]])
            return _contained(os.path.realpath(os.path.join(base, *parts[1:])), base)
        return _contained(os.path.realpath(os.path.join(self.root, *parts)), self.root)

    def entry(self, raw: bytes) -> bytes:
        """The directory entry the path names, its parent resolved and its own name kept: remove, rename, mkdir."""
        parts = _parts(raw)
        if not parts:
            return self.root
        if parts[0] in self.mounts:
            raise PathRefused("a read-only mount")
        parent = _contained(os.path.realpath(os.path.join(self.root, *parts[:-1])), self.root)
        return os.path.join(parent, parts[-1])

    def is_root(self, path: bytes) -> bool:
        return path == self.root

    def mount_entries(self) -> dict[bytes, bytes]:
        """The root listing's entries for the mounts that exist: name -> entry (without its NUL)."""
        out: dict[bytes, bytes] = {}
        for name, path in self.mounts.items():
            if os.path.isdir(path):
                out[name] = DIRENT_DIR + name
            elif os.path.isfile(path):
                out[name] = DIRENT_FILE + name + b"\t%d" % os.stat(path).st_size
        return out


def _contained(resolved: bytes, base: bytes) -> bytes:
    if resolved != base and not resolved.startswith(base.rstrip(b"/") + b"/"):
        raise PathRefused("path leaves the root")
    return resolved


def _parts(raw: bytes) -> list[bytes]:
    parts = [p for p in raw.split(b"/") if p not in (b"", b".")]
    if b".." in parts:
        raise PathRefused("'..' in path")
    return parts


def c_string(data: bytes) -> bytes:
    """The bytes before the first NUL (all of them without one)."""
    end = data.find(b"\0")
    return data if end < 0 else data[:end]


def directory_entries(path: bytes, mounted: Mapping[bytes, bytes] | None = None) -> Iterator[bytes]:
    """PX4's listing entries in readdir order ("." and ".." first), each without its trailing NUL.

    Raises OSError if `path` is not a readable directory. Sizes are stat() sizes of regular files; anything that
    is neither a regular file nor a directory (a symbolic link included: PX4 looks at d_type) is a skip entry.
    `mounted` (the root's mounts: name -> entry) are listed among the names, in place of an entry of the same name.
    """
    mounted = mounted or {}
    with os.scandir(path) as it:
        found: list[tuple[bytes, os.DirEntry[bytes] | bytes]] = [(e.name, e) for e in it if e.name not in mounted]
    found.extend(mounted.items())
    yield DIRENT_SKIP
    yield DIRENT_SKIP
    for _, entry in sorted(found, key=lambda item: item[0]):
        if isinstance(entry, bytes):
            yield entry
            continue
        try:
            if entry.is_file(follow_symlinks=False):
                yield DIRENT_FILE + entry.name + b"\t%d" % entry.stat(follow_symlinks=False).st_size
            elif entry.is_dir(follow_symlinks=False):
                yield DIRENT_DIR + entry.name
            else:
                yield DIRENT_SKIP
        except OSError:  # vanished between readdir and stat: PX4 lists it with size 0 or skips it
            yield DIRENT_SKIP


def listing(path: bytes, offset: int, max_bytes: int,
            mounted: Mapping[bytes, bytes] | None = None) -> tuple[bytes, bool]:
    """(the packed entries from index `offset` that fit in `max_bytes`, whether the listing reached the end).

    Each entry takes its bytes plus a NUL; PX4 stops at the first entry that does not fit.
    """
    out = bytearray()
    for index, entry in enumerate(directory_entries(path, mounted)):
        if index < offset:
            continue
        if len(out) + len(entry) + 1 > max_bytes:
            return bytes(out), False
        out += entry + b"\0"
    return bytes(out), True


def crc32_file(path: bytes) -> int:
    """PX4's crc32part over the whole file, starting at 0."""
    crc = 0
    with open(path, "rb", buffering=0) as f:
        while chunk := f.read(CRC_CHUNK):
            crc = zlib.crc32(chunk, crc ^ 0xFFFFFFFF) ^ 0xFFFFFFFF
    return crc
