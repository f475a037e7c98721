"""Reading a file a user named (a scenario, a sweep file, a table): a regular file, bounded, once.

Such a file is read whole into memory, so only a regular file is read: a FIFO, a device, a socket
or a folder is refused at once, never waited on (a FIFO opened for reading waits for a writer, a
device may stream without end). The file is opened without blocking and judged on the open
descriptor, so what is checked is what is read, even if the name is swapped in between. At most
`limit` bytes are read, in pieces, so a file that grows while it is read stops at the bound too.
Every refusal is a `ScenarioError` at the file's first line, naming what the file is.
"""

from __future__ import annotations

import os
import stat

from collide2d.runner.scenario.parse import ScenarioError

READ_CHUNK_BYTES = 2**20  # a file is read in pieces of this many bytes
_O_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_O_BINARY = getattr(os, "O_BINARY", 0)
_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def kind_of(mode: int) -> str:
    """What a file of stat mode `mode` is, in words ("a FIFO (named pipe)", ...)."""
    for test, words in _KINDS:
        if test(mode):
            return words
    return "not a regular file"


def read_regular(path, limit: int, shown: str, what: str = "file") -> bytes:
    """The bytes of the regular file at `path` (named `shown` in messages, `what` in words: "file",
    "table"), at most `limit` of them; a ScenarioError at `shown`:1:1 when it cannot be opened, is
    not a regular file, or holds more than `limit` bytes."""
    try:
        fd = os.open(path, os.O_RDONLY | _O_NONBLOCK | _O_BINARY)
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the {what}: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        mode = st.st_mode
        if not stat.S_ISREG(mode):
            raise ScenarioError(
                shown, 1, 1, f"cannot read the {what}: it is {kind_of(mode)}, not a regular file"
            )
        chunks: list[bytes] = []
        size = 0
        want = min(st.st_size, limit) + 1  # the whole file at once, and one byte to see it grew
        while chunk := os.read(fd, want):  # then in pieces: a growing file stops at the limit
            size += len(chunk)
            if size > limit:
                raise ScenarioError(
                    shown,
                    1,
                    1,
                    f"the {what} is larger than the limit of {limit:,} bytes; "
                    "raise it with --max-file-bytes",
                )
            chunks.append(chunk)
            want = READ_CHUNK_BYTES
    except OSError as exc:
        raise ScenarioError(shown, 1, 1, f"cannot read the {what}: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    return b"".join(chunks)
