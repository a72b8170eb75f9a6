"""Worker processes that end with the process that started them.

A pool's workers are killed along with their parent only where the parent exits cleanly; after a
``kill -9`` of ``vcage generate --workers 2`` they went on simulating (about 530 MB each) with no
one to read their results. On Linux a worker asks the kernel for SIGKILL when its parent dies
(``prctl(PR_SET_PDEATHSIG)``), and exits at once if the parent is already gone; elsewhere nothing
changes.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys

PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def die_with_parent(parent: int) -> None:
    """Run first in a worker started by the process ``parent`` (a pool's ``initializer``): the worker
    is killed when that process dies, however it dies."""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
        return  # not granted: the worker lives as it did before
    if os.getppid() != parent:  # the parent died before the request was made
        os._exit(1)
