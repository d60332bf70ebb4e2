"""The process environment the GPU stack expects, set up before the first GPU
probe (``backend="gpu"``, or ``"auto"`` where a GPU could win).

wgpu looks for a Wayland display when it lists adapters, and libwayland prints
"error: XDG_RUNTIME_DIR is invalid or not set in the environment." on stderr,
once per probe, when that variable is missing (containers, CI, bare X
sessions). It is harmless but reads as a failure. Such a process gets a private
runtime directory, as the ``pmvc`` command line gives itself one:
``pmvc-runtime-UID`` in the temporary directory, owned by the user, mode 0700,
as the XDG specification describes one. Set through ``os.environ``, so that
Python and the native code agree; a process that has the variable keeps it.
"""

from __future__ import annotations

import os
import stat
import sys
import tempfile


def ensure_runtime_dir() -> None:
    if not sys.platform.startswith("linux") or os.environ.get("XDG_RUNTIME_DIR"):
        return
    uid = os.getuid()
    directory = os.path.join(tempfile.gettempdir(), f"pmvc-runtime-{uid}")
    try:
        os.mkdir(directory, 0o700)
    except FileExistsError:
        pass
    except OSError:
        return
    try:
        status = os.lstat(directory)
    except OSError:
        return
    # Someone else's directory, a link, or one others can enter is not ours to use.
    if stat.S_ISDIR(status.st_mode) and status.st_uid == uid and status.st_mode & 0o077 == 0:
        os.environ["XDG_RUNTIME_DIR"] = directory
