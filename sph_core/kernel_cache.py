"""The on-disk cache of the compiled kernels: where it lives, and a lock that makes it safe for
several processes at once.

Where: a folder named by a hash of this package's sources (numba checks only a function's own
file, and a kernel holds the code of every function it calls from other modules: ``step.run``
holds every pass, so after an edit of one module the old folder would serve stale machine code).
``NUMBA_CACHE_DIR`` (if set) is the parent of that folder, else ``~/.cache/wavesph``.

The lock: numba saves a new overload by reading the function's index, picking the first free data
file name, writing the index, then the data, with nothing held in between. Two processes
compiling overloads of one function at once (dask workers of a sweep, runs side by side) can pick
the same name: the index then maps one overload to the other's machine code, and every later
process that loads it crashes (a segfault in the first kernel call; reproduced with six
processes compiling overloads of one toy function, docs/developer/testing.md). A reader between
the index and the data write gets the same mismatch. ``lock_cache_files`` takes an exclusive
``flock`` on a lock file next to the index for a save and a shared one for a load, so a reader
sees an index and its data files as one writer left them.
It costs one lock per kernel compile or load, not per call; where the lock file cannot be made
(a read-only cache) numba's own, unlocked handling goes on.

The threading layer: a cached parallel kernel needs numba's threading layer started before its
first call (its machine code calls the layer's ``numba_parallel_for``), and numba starts it when
it compiles or loads a parallel function. A kernel compiled while the parallel functions it calls
were loaded from the cache forgets that need (numba copies it only from callees it compiled
itself: numba issue #8578, fix proposed in numba PR #9950), so a later process that loads that
kernel first calls a null pointer: the segfault in ``step.initialise`` seen on this project's
machine with no two processes at once (a closed-tank run's overload compiled beside the flume
runs' helpers). ``launch_threading_layer`` starts the layer once, when sph_core is imported.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

try:
    import fcntl
except ImportError:  # not POSIX: numba's unlocked cache, as before
    fcntl = None  # type: ignore[assignment]


def kernel_cache_dir() -> str:
    """The kernel cache folder of this exact source tree (module docstring)."""
    h = hashlib.sha1()
    for path in sorted(Path(__file__).parent.rglob("*.py")):
        h.update(path.read_bytes())
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(Path.home(), ".cache"), "wavesph")
    return os.path.join(base, f"kernels-{h.hexdigest()[:16]}")


@contextlib.contextmanager
def _locked(index_path: str, exclusive: bool) -> Iterator[None]:
    try:
        os.makedirs(os.path.dirname(index_path) or ".", exist_ok=True)
        fh = open(index_path + ".lock", "a")
    except OSError:   # a cache folder we cannot write: numba's own handling, unlocked
        yield
        return
    with fh:
        fcntl.flock(fh, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def launch_threading_layer() -> None:
    """Start numba's threading layer now (module docstring), as numba does on loading a parallel
    kernel it compiled with its callees; idempotent."""
    from numba.np.ufunc.parallel import _launch_threads

    _launch_threads()


def lock_cache_files() -> bool:
    """Wrap numba's cache index save (exclusive) and load (shared) in a file lock (module
    docstring); idempotent. Returns False where there is no ``fcntl`` (nothing wrapped)."""
    if fcntl is None:
        return False
    from numba.core import caching

    cls = caching.IndexDataCacheFile
    if getattr(cls, "_wavesph_locked", False):
        return True
    save, load = cls.save, cls.load

    def locked_save(self: Any, key: Any, data: Any) -> None:
        with _locked(self._index_path, True):
            save(self, key, data)

    def locked_load(self: Any, key: Any) -> Any:
        with _locked(self._index_path, False):
            return load(self, key)

    cls.save = locked_save
    cls.load = locked_load
    cls._wavesph_locked = True
    return True
