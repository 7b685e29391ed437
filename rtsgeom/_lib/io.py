"""Safe output: files written atomically, output folders swapped in whole, paths checked first.

Three promises, kept here for every command (the CLI only calls these):

* A file output (:func:`atomic_path`, :func:`write_bytes`, ...) is written to a temporary file
  beside the target and renamed over it: a killed run never leaves a half-written file. A
  replaced file keeps its mode; a symlink is written through (its target is replaced, the link
  stays); devices, FIFOs, sockets and directories are never replaced.
* An output folder (:func:`staged_dir`) is one run or nothing: the command writes into a private
  staging folder next to the target, which is swapped in as a whole at the end (one atomic
  ``renameat2(RENAME_EXCHANGE)`` on Linux). An interrupted or crashed run leaves the old folder
  as it was and at most a staging folder named ``.NAME.rtsgeom-staging-PID``, which the next run
  into the same folder removes. A lock file ``.NAME.rtsgeom-lock`` (an ``flock`` that the kernel
  drops when its holder dies, with the holder's pid inside for the message) makes a second
  concurrent run into the same folder stop at once.
* Every output path is checked before any computing (:func:`check_output_file`,
  :func:`check_output_dir`): an empty path, a directory where a file is expected (or the
  reverse), a special file, an input of the command, or a folder that cannot be written is an
  :class:`OutputError` naming the path (exit 2 in the CLI).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import errno
import fcntl
import json
import os
import re
import shutil
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Iterator
from ..errors import OutputError

__all__ = ["OutputError", "atomic_path", "write_text", "write_bytes", "write_json",
           "check_output_file", "check_output_dir", "staged_dir", "OUTPUT_NAMES"]

#: Names of the files rtsgeom writes into an output folder. A non-empty existing folder is
#: replaced only when it holds nothing else (or carries the marker file): ``--out ~`` must never
#: swap a user's home folder away.
OUTPUT_NAMES = re.compile(
    r"(detections\.csv|summary\.json|report\.html|range_(doppler|angle)\.png|maps\.(npz|mat|nc)|"
    r"calibration(_\d+|_sweep)?\.(png|json)|linearity\.(png|json)|tolerance\.(png|json)|"
    r"design(_\w+)?\.(png|json)|nearfield\.(png|json)|ghosts\.(png|json)|"
    r"programme\.csv|tracks\.csv|playback\.(png|gif)|kpi\.(json|html|pdf)|"
    r"\.rtsgeom-output)")
MARKER = ".rtsgeom-output"


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISDIR, "a directory")):
        if test(mode):
            return name
    return "not a regular file"


def _nonempty(path) -> Path:
    if path is None or str(path) == "":
        raise OutputError("output path '': an empty path names no file or folder")
    return Path(path)


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def _check_parent_writable(target: Path) -> None:
    """The nearest existing ancestor of ``target`` must be a folder we can create files in
    (tried for real: ``os.access`` says yes for /proc as root)."""
    parent = target.parent
    while not parent.exists():
        if parent == parent.parent:
            break
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"{target}: {parent} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(prefix=".rtsgeom-probe-", dir=parent)
    except OSError as exc:
        raise OutputError(f"{target}: cannot write into {parent} "
                          f"({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)


def check_output_file(path, inputs: Iterable = ()) -> Path:
    """Check an output file path before computing; return the path to write (a symlink's
    final target, so that the link itself stays).

    Raises :class:`OutputError` naming ``path`` for: an empty path, an existing directory, a
    device, FIFO or socket, a file that is one of ``inputs``, a folder that cannot be written.
    """
    path = _nonempty(path)
    if str(path).endswith(os.sep):
        raise OutputError(f"{path}: names a folder, a file is expected")
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    try:
        st = os.stat(target)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise OutputError(f"{path}: {exc.strerror or exc}") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        what = _kind(st.st_mode)
        hint = " (a file is expected)" if stat.S_ISDIR(st.st_mode) else \
            ": refusing to replace it"
        raise OutputError(f"{path} is {what}{hint}")
    for inp in inputs:
        if inp is not None and st is not None and _same(target, Path(inp)):
            raise OutputError(f"{path} is an input of this command: refusing to overwrite it")
    _check_parent_writable(target)
    return target


def check_output_dir(path, inputs: Iterable = ()) -> Path:
    """Check an output folder path before computing; return the folder to swap (a symlink's
    final target). Raises :class:`OutputError` naming ``path``."""
    path = _nonempty(path)
    target = Path(os.path.realpath(path))
    if target == Path(target.anchor):
        raise OutputError(f"{path}: the root folder cannot be an output folder")
    if target.exists():
        st = os.stat(target)
        if not stat.S_ISDIR(st.st_mode):
            raise OutputError(f"{path} is {_kind(st.st_mode) if not stat.S_ISREG(st.st_mode) else 'a file'}"
                              " (an output folder is expected)")
        foreign = sorted(e for e in os.listdir(target) if not OUTPUT_NAMES.fullmatch(e))
        if foreign and not (target / MARKER).exists():
            raise OutputError(
                f"{path} holds files rtsgeom did not write ({', '.join(foreign[:3])}"
                f"{', ...' if len(foreign) > 3 else ''}): an output folder is replaced as a "
                "whole, so choose an empty or new folder")
    for inp in inputs:
        if inp is None:
            continue
        real = Path(os.path.realpath(inp))
        if real == target or target in real.parents:
            raise OutputError(f"{path} contains the input {inp}: an output folder is replaced "
                              "as a whole, choose another folder")
    _check_parent_writable(target)
    return target


def _mode_for(target: Path) -> int:
    try:
        return stat.S_IMODE(os.stat(target).st_mode)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; on success it is renamed to ``path``.

    A symlink is written through (its final target is replaced); an existing file keeps its
    mode; a directory, device, FIFO or socket at ``path`` raises :class:`OutputError`.
    """
    target = check_output_file(path) if Path(path).exists() or Path(path).is_symlink() \
        else _nonempty(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    mode = _mode_for(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part" + target.suffix,
                               dir=target.parent)
    os.close(fd)
    os.chmod(tmp, mode)
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_bytes(path: str | Path, data: bytes) -> None:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | Path, text: str) -> None:
    write_bytes(path, text.encode("utf-8"))


def write_json(path: str | Path, obj) -> None:
    write_text(path, json.dumps(obj, indent=2, sort_keys=False, allow_nan=False) + "\n")


# --- whole-folder outputs -------------------------------------------------------------------

_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    rc = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _lock_path(target: Path) -> Path:
    return target.parent / f".{target.name}.rtsgeom-lock"


@contextmanager
def _folder_lock(target: Path) -> Iterator[None]:
    """Exclusive ``flock`` on ``.NAME.rtsgeom-lock`` (released by the kernel when the holder
    dies, so a stale lock file of a dead pid is simply taken over)."""
    lock = _lock_path(target)
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 64, 0).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            raise OutputError(f"{target} is being written by another rtsgeom run (pid {holder}, "
                              f"lock {lock}): wait for it or choose another --out") from None
        try:  # the holder before us may have removed the file after we opened it: retry
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        try:
            os.unlink(lock)
        except FileNotFoundError:
            pass
        os.close(fd)


def _clean_stale(target: Path) -> None:
    """Under the lock: restore a folder left half-swapped by a killed fallback swap, and remove
    staging / old folders of dead runs."""
    parent = target.parent
    prefix = f".{target.name}.rtsgeom-"
    olds = sorted(parent.glob(glob_escape(prefix) + "old-*"))
    if not target.exists() and olds:
        os.rename(olds[0], target)
        olds = olds[1:]
    for p in list(parent.glob(glob_escape(prefix) + "staging-*")) + olds:
        shutil.rmtree(p, ignore_errors=True)


def glob_escape(text: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", text)


@contextmanager
def staged_dir(path, inputs: Iterable = (), before_swap=None) -> Iterator[Path]:
    """The one way a command writes an output folder: one run or nothing.

    Checks ``path`` (:func:`check_output_dir`), takes the folder's lock (another run holding it
    raises :class:`OutputError`), cleans stale staging folders, and yields a fresh private
    staging folder ``.NAME.rtsgeom-staging-PID`` beside it. When the block ends normally the
    staging folder replaces ``path`` as a whole (atomically where the kernel can exchange two
    paths); on any exception (KeyboardInterrupt, the CLI's SIGTERM included) it is removed and
    ``path`` stays as it was. Enter it before computing, so that a bad path fails at once.

    ``before_swap``: called immediately before the swap, after the block's last write; it
    raises to keep the old folder (the CLI's: a signal the command received, whose exception
    something swallowed or has not raised yet, so that the staged run, possibly cut short, is
    never swapped in).
    """
    target = check_output_dir(path, inputs)
    target.parent.mkdir(parents=True, exist_ok=True)
    with _folder_lock(target):
        _clean_stale(target)
        stage = target.parent / f".{target.name}.rtsgeom-staging-{os.getpid()}"
        stage.mkdir()
        try:
            mode = stat.S_IMODE(os.stat(target).st_mode) if target.exists() else None
            if mode is None:
                umask = os.umask(0)
                os.umask(umask)
                mode = 0o777 & ~umask
            os.chmod(stage, mode)
            (stage / MARKER).write_bytes(b"")
            yield stage
            if before_swap is not None:
                before_swap()
            if not target.exists():
                os.rename(stage, target)
            elif _exchange(stage, target):
                shutil.rmtree(stage)  # now the old folder
            else:  # no atomic exchange: old aside, new in, old away (restored by _clean_stale)
                old = target.parent / f".{target.name}.rtsgeom-old-{os.getpid()}"
                os.rename(target, old)
                os.rename(stage, target)
                shutil.rmtree(old)
        finally:
            if stage.exists():
                try:
                    shutil.rmtree(stage, ignore_errors=True)
                except BaseException:  # a signal's exception raised mid-removal (the CLI's
                    # deferred SIGTERM can fire here after the staged run was refused): the
                    # folder is still removed whole, then the exception goes on
                    shutil.rmtree(stage, ignore_errors=True)
                    raise
