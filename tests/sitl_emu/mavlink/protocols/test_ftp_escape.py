"""The FTP root is a sandbox: no request reads, lists, writes, creates, removes or renames anything outside it.

Every request goes over loopback UDP to a node in lockstep; after each one the test compares the whole tree outside
the root (names, kinds, contents, modification times) with a snapshot taken before, and checks the answer is PX4's
error code: FileProtected for a path refused by the sandbox ('..', a link leading out), FileNotFound for an absolute
host path (it names a path under the root, which does not exist), InvalidDataSize for a size over 239.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from support.fakes import FakeVehicle, Harness
from support.ftp_client import FtpClient

from sitl_emu.mavlink.protocols.ftp import MAX_DATA, Err, FtpProtocol, Op

SECRET = b"outside the root"
# Every path here, even one the sandbox let through by mistake, lands inside the test's own tmp_path: a suite that
# aims at real files (/etc/passwd) would destroy them the day the sandbox breaks and the tests run as root.


def _tree(top: Path, skip: Path) -> dict[str, tuple]:
    """Everything under `top` but `skip`: path -> (kind, content or link target, mtime_ns)."""
    out: dict[str, tuple] = {}
    for dirpath, dirnames, filenames in os.walk(top, followlinks=False):
        here = Path(dirpath)
        if here == skip or skip in here.parents:
            dirnames[:] = []
            continue
        for name in dirnames + filenames:
            path = here / name
            if path == skip:
                continue
            st = path.lstat()
            if path.is_symlink():
                out[str(path)] = ("link", os.readlink(path), st.st_mtime_ns)
            elif path.is_dir():
                out[str(path)] = ("dir", None, st.st_mtime_ns)
            else:
                out[str(path)] = ("file", path.read_bytes(), st.st_mtime_ns)
    return out


class World:
    """tmp/outside (a secret, an empty dir), tmp/fs_sibling (a name sharing the root's prefix), tmp/fs the root with
    links leading out, and an FTP client on a node serving tmp/fs."""

    def __init__(self, tmp: Path) -> None:
        self.tmp = tmp
        self.root = tmp / "fs"
        outside = tmp / "outside"
        (outside / "empty_dir").mkdir(parents=True)
        (outside / "secret.txt").write_bytes(SECRET)
        (tmp / "fs_sibling").mkdir()
        (tmp / "fs_sibling" / "secret.txt").write_bytes(SECRET)
        self.root.mkdir()
        (self.root / "inside.txt").write_bytes(b"inside")
        (self.root / "sub").mkdir()
        os.symlink("../outside", self.root / "link_dir")
        os.symlink("../outside/secret.txt", self.root / "link_file")
        os.symlink("../outside/new.txt", self.root / "dangling")
        os.symlink(str(outside), self.root / "sub" / "abs_link")
        self.harness = Harness(FakeVehicle(), handler_classes=[FtpProtocol.with_root(self.root)])
        self.ftp = FtpClient(self.harness)
        self.before = _tree(tmp, self.root)

    def deep_escape(self) -> bytes:
        """Up past tmp_path and back down into it: a long climb that still ends inside the test's own directory."""
        return b"../../" + os.fsencode(self.tmp.name) + b"/outside/secret.txt"

    def outside_unchanged(self) -> None:
        assert _tree(self.tmp, self.root) == self.before

    def close(self) -> None:
        self.harness.close()


@pytest.fixture()
def world(tmp_path: Path):
    w = World(tmp_path)
    yield w
    w.close()
    w.outside_unchanged()


DOTDOT = [b"..", b"../", b"../outside/secret.txt", b"/../outside/secret.txt", b"./../outside/secret.txt",
          b"sub/../../outside/secret.txt", b"sub/../inside.txt", b"../fs_sibling/secret.txt", b"//..//outside",
          b"../outside/../outside/secret.txt"]
THROUGH_LINKS = [b"link_dir/secret.txt", b"link_dir/new.txt", b"link_dir/empty_dir", b"/link_dir/../outside",
                 b"sub/abs_link/secret.txt", b"sub/abs_link/empty_dir/x"]
LINKS_THEMSELVES = [b"link_dir", b"link_file", b"dangling", b"sub/abs_link"]
PATH_OPS = [Op.LIST_DIRECTORY, Op.OPEN_FILE_RO, Op.CREATE_FILE, Op.OPEN_FILE_WO, Op.CALC_FILE_CRC32,
            Op.TRUNCATE_FILE, Op.REMOVE_FILE, Op.CREATE_DIRECTORY, Op.REMOVE_DIRECTORY]
FOLLOWING_OPS = [Op.LIST_DIRECTORY, Op.OPEN_FILE_RO, Op.CREATE_FILE, Op.OPEN_FILE_WO, Op.CALC_FILE_CRC32,
                 Op.TRUNCATE_FILE]


@pytest.mark.parametrize("path", DOTDOT + THROUGH_LINKS)
@pytest.mark.parametrize("op", PATH_OPS)
def test_dotdot_and_paths_through_links_are_file_protected(world, op, path):
    assert world.ftp.nak(op, path + b"\0") == (Err.FILE_PROTECTED, 0)
    world.outside_unchanged()


@pytest.mark.parametrize("op", PATH_OPS)
def test_a_long_climb_out_is_file_protected(world, op):
    assert world.ftp.nak(op, world.deep_escape() + b"\0") == (Err.FILE_PROTECTED, 0)
    world.outside_unchanged()


@pytest.mark.parametrize("path", LINKS_THEMSELVES)
@pytest.mark.parametrize("op", FOLLOWING_OPS)
def test_opening_listing_or_truncating_a_link_that_leads_out_is_file_protected(world, op, path):
    assert world.ftp.nak(op, path + b"\0") == (Err.FILE_PROTECTED, 0)
    world.outside_unchanged()


def test_a_link_inside_the_root_is_removed_or_renamed_as_a_link_never_its_target(world):
    ftp = world.ftp
    ftp.ok(Op.RENAME, b"link_file\0renamed_link\0")
    assert (world.root / "renamed_link").is_symlink()
    ftp.ok(Op.REMOVE_FILE, b"renamed_link\0")
    ftp.ok(Op.REMOVE_FILE, b"dangling\0")
    assert ftp.nak(Op.REMOVE_DIRECTORY, b"link_dir\0")[0] == Err.FAIL_ERRNO  # ENOTDIR: a link is no directory
    assert ftp.nak(Op.CREATE_DIRECTORY, b"link_dir\0") == (Err.FILE_EXISTS, 0)
    ftp.ok(Op.REMOVE_FILE, b"link_dir\0")
    assert sorted(p.name for p in world.root.iterdir()) == ["inside.txt", "sub"]
    world.outside_unchanged()


@pytest.mark.parametrize("bad", [b"../outside/moved.txt", b"link_dir/moved.txt", b"sub/abs_link/moved.txt", b"",
                                 b"/"])
def test_rename_never_moves_a_file_out_or_in_nor_replaces_the_root(world, bad):
    assert world.ftp.nak(Op.RENAME, b"inside.txt\0" + bad + b"\0") == (Err.FILE_PROTECTED, 0)
    assert world.ftp.nak(Op.RENAME, bad + b"\0inside2.txt\0") == (Err.FILE_PROTECTED, 0)
    assert (world.root / "inside.txt").read_bytes() == b"inside" and not (world.root / "inside2.txt").exists()
    world.outside_unchanged()


@pytest.mark.parametrize("op", [Op.REMOVE_DIRECTORY, Op.REMOVE_FILE])
@pytest.mark.parametrize("path", [b"", b"/", b".", b"./", b"//"])
def test_the_root_itself_cannot_be_removed(world, op, path):
    assert world.ftp.nak(op, path + b"\0") == (Err.FILE_PROTECTED, 0)
    assert world.root.is_dir()


@pytest.mark.parametrize("op", [Op.LIST_DIRECTORY, Op.OPEN_FILE_RO, Op.CALC_FILE_CRC32, Op.CREATE_FILE,
                                Op.OPEN_FILE_WO, Op.CREATE_DIRECTORY, Op.REMOVE_FILE, Op.TRUNCATE_FILE])
def test_an_absolute_host_path_names_a_path_under_the_root(world, op):
    host_path = os.fsencode(world.tmp / "outside" / "secret.txt")
    assert world.ftp.nak(op, host_path + b"\0") == (Err.FILE_NOT_FOUND, 0)
    world.outside_unchanged()


def test_a_path_ends_at_its_first_nul(world):
    ftp = world.ftp
    assert ftp.read_file(b"inside.txt\0../outside/secret.txt") == b"inside"
    ftp.ok(Op.CREATE_FILE, b"made\0/../../outside/evil")
    ftp.ok(Op.TERMINATE_SESSION)
    assert (world.root / "made").read_bytes() == b""
    world.outside_unchanged()


@pytest.mark.parametrize("size", [MAX_DATA + 1, 250, 255])
@pytest.mark.parametrize("op", [*PATH_OPS, Op.WRITE_FILE, Op.READ_FILE, Op.RENAME, Op.BURST_READ_FILE])
def test_a_size_over_239_is_invalid_data_size_and_does_nothing(world, op, size):
    before = _tree(world.root, world.tmp / "none")
    reply = world.ftp.call(op, b"new_name\0", size=size)
    assert (reply.opcode, reply.req_opcode, reply.size, reply.data[0]) == (Op.NAK, op, 1, Err.INVALID_DATA_SIZE)
    assert _tree(world.root, world.tmp / "none") == before


def test_a_write_with_a_bad_size_writes_nothing(world):
    ftp = world.ftp
    ftp.ok(Op.OPEN_FILE_WO, b"inside.txt\0")
    assert ftp.nak(Op.WRITE_FILE, b"X" * 10, size=MAX_DATA + 1)[0] == Err.INVALID_DATA_SIZE
    assert (world.root / "inside.txt").read_bytes() == b"inside"
    assert int.from_bytes(ftp.ok(Op.WRITE_FILE, b"XXXXXXXX", size=2).data[:4], "little") == 2  # size rules
    ftp.ok(Op.TERMINATE_SESSION)
    assert (world.root / "inside.txt").read_bytes() == b"XXside"


def test_very_long_names_stay_inside(world):
    ftp = world.ftp
    name = b"n" * MAX_DATA  # no room for a NUL: PX4 ends the string at data[238]
    ftp.ok(Op.CREATE_FILE, name, size=MAX_DATA)
    ftp.ok(Op.TERMINATE_SESSION)
    assert (world.root / ("n" * (MAX_DATA - 1))).is_file()
    deep = b"/".join([b"d" * 40] * 5)
    for depth in range(1, 6):
        ftp.ok(Op.CREATE_DIRECTORY, b"/".join([b"d" * 40] * depth) + b"\0")
    assert (world.root / os.fsdecode(deep)).is_dir()
    listed = ftp.list_dir(b"/")
    assert b"F" + b"n" * (MAX_DATA - 1) + b"\t0" not in listed  # too long for one packet: PX4 stops there
    world.outside_unchanged()


def test_nothing_outside_changed_after_a_whole_hostile_session(world):
    """Every path of the suite through every operation, then the outside compared once more."""
    for path in DOTDOT + THROUGH_LINKS + LINKS_THEMSELVES + [world.deep_escape()]:
        for op in PATH_OPS:
            world.ftp.call(op, path + b"\0")
            world.ftp.call(Op.RESET_SESSIONS)
        world.ftp.call(Op.RENAME, path + b"\0x\0")
        world.ftp.call(Op.RENAME, b"inside.txt\0" + path + b"\0")
    world.outside_unchanged()
