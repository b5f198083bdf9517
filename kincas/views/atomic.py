"""Files written whole or not at all: every file kincas writes (the views' writers, the
command line's outputs and scenes) goes through here.

`replacing(path)` gives a temporary name in the same folder (so that the final rename stays
on one file system, where it is atomic); the writer writes there; when it returns, the
temporary file takes the final name (`os.replace`), and on any failure (a full disk,
Ctrl-C, an error of the writer) it is removed. A reader never sees half a file under the
final name, and a file already there stays as it was until the new one is complete. The
temporary name keeps the extension, for writers that choose the format by it (matplotlib,
Pillow). A path that exists and is not a regular file (/dev/null, /dev/stdout, a pipe) is
written as it is: there is nothing to replace.

`same_file(a, b)` tells whether two paths name one file (symbolic links resolved), for the
command line's refusal to write an output over its own scene.

>>> import os, tempfile
>>> d = tempfile.mkdtemp()
>>> with open_replacing(os.path.join(d, "t.csv")) as f:
...     _ = f.write("a,b\\n")
>>> os.listdir(d)
['t.csv']
"""
from __future__ import annotations

import contextlib
import os
import stat
import tempfile


@contextlib.contextmanager
def replacing(path, *, fsync: bool = False):
    """Yield a temporary path beside `path`; it becomes `path` when the block ends normally
    and is removed when it ends by any exception. `fsync`: flush it to the disk first."""
    path = os.fspath(path)
    if os.path.islink(path):  # write to the file the link names, keep the link
        path = os.path.realpath(path)
    try:
        mode = os.stat(path).st_mode
    except OSError:
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        yield path  # a device or a pipe: written through
        return
    folder, name = os.path.split(path)
    stem, ext = os.path.splitext(name)
    fd, tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=f".part{ext}", dir=folder or ".")
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, stat.S_IMODE(mode) if mode is not None else 0o666 & ~_umask())
        if fsync:
            with open(tmp, "rb") as f:
                os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def open_replacing(path, mode: str = "w", **kw):
    """`open(temporary, mode, **kw)` in `replacing(path)`: the file becomes `path` when it is
    complete and closed."""
    with replacing(path) as tmp, open(tmp, mode, **kw) as f:
        yield f


def same_file(a, b) -> bool:
    """Whether the paths `a` and `b` name one file (the same inode, or the same real path
    when one does not exist yet)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


def _umask() -> int:
    """The process's umask (read by setting it and putting it back)."""
    u = os.umask(0o022)
    os.umask(u)
    return u


def savefig(fig, path, **kw) -> None:
    """`fig.savefig(path, **kw)`, the file whole or not at all."""
    with replacing(path) as tmp:
        fig.savefig(tmp, **kw)
