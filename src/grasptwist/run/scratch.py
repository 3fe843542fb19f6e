"""Scratch files and folders named after the process that owns them.

SIGKILL (the out-of-memory killer's signal) cannot be caught, so a run
killed by it leaves whatever it had on disk.  Each scratch entry is named
``<stem><host>-<pid>-<random>``, and a later run that makes scratch entries
in the same folder first removes those whose owner, on this host, is gone.
"""

from __future__ import annotations

import os
import shutil

__all__ = ["owned_prefix", "remove_orphans"]


def _host() -> str:
    return os.uname().nodename.replace("/", "_")


def owned_prefix(stem: str) -> str:
    """The name prefix of this process's scratch entries (a random part follows).

    >>> owned_prefix(".grasptwist-").endswith(f"-{os.getpid()}-")
    True
    """
    return f"{stem}{_host()}-{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    return True


def remove_orphans(folder: str, stem: str) -> list[str]:
    """Remove the scratch entries in ``folder`` whose owner process is gone; return their names.

    Entries from another host, or whose process id is in use again, are
    left alone: a removal must never touch a live run's files.
    """
    removed = []
    host = _host()
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        if not entry.name.startswith(stem):
            continue
        parts = entry.name[len(stem) :].rsplit("-", 2)  # host names may hold '-'; the rest never does
        if len(parts) != 3 or parts[0] != host or not parts[1].isdigit() or _alive(int(parts[1])):
            continue
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)
        except OSError:  # another run got there first, or no permission: not ours to insist
            continue
        removed.append(entry.name)
    return removed
