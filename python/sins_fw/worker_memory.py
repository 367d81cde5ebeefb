"""Worker processes that keep the memory they free.

Every emulation hands its output columns to numpy as fresh memory (about 18 MB for 240 s of input),
and glibc gives freed blocks of that size back to the kernel, so the next run in the same process
takes the same minor page faults again: about 30 % of a warm run on the benchmark machine
(`benchmarks/README.md`). A worker process that only runs emulations is better off keeping freed
memory for the next run. This is set in the package's own worker processes only (``initializer=`` of
a process pool), never in the user's process.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import platform

# glibc's mallopt parameters (malloc.h).
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
#: The largest mmap threshold glibc accepts on 64-bit systems (DEFAULT_MMAP_THRESHOLD_MAX): blocks
#: below it come from the heap, which freed memory then stays in.
_MMAP_THRESHOLD_MAX = 32 * 1024 * 1024
#: Keep up to this much freed memory at the top of the heap instead of trimming it.
_TRIM_THRESHOLD = 1 << 30


def keep_freed_memory() -> bool:
    """In this process, keep freed memory for reuse (glibc's mallopt). Returns whether it was set:
    False where the C library is not glibc (nothing changes there)."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    mallopt = ctypes.CDLL(name).mallopt
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    mmap_set = bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD_MAX))
    return mmap_set and bool(mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD))
