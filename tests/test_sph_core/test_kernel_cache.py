"""The kernel cache: a save of one writer cannot interleave with another's, so an index never maps
an overload to another overload's machine code (sph_core.kernel_cache's docstring)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading

import pytest
from numba.core import caching

from sph_core.kernel_cache import kernel_cache_dir, lock_cache_files

pytest.importorskip("fcntl")


def _pause(method, arrived: threading.Event, go: threading.Event):
    def wrapped(*args):
        arrived.set()
        go.wait(5.0)
        return method(*args)
    return wrapped


def test_two_writers_of_one_index_leave_every_entry_with_its_own_data(tmp_path):
    """Two cache files on one index, as two processes compiling overloads of one function: A
    stops before writing the index, B before writing its data. Unlocked (numba's own), B picks the
    same data file as A, A's index and B's data win, and loading A's overload returns B's machine
    code (the segfault in the first kernel call). Locked, B waits for A's whole save."""
    assert lock_cache_files()
    assert lock_cache_files()   # idempotent: one lock, not two nested
    a = caching.IndexDataCacheFile(str(tmp_path), "kern", (1.0, 10))
    b = caching.IndexDataCacheFile(str(tmp_path), "kern", (1.0, 10))
    a_paused, a_go, b_paused, b_go = (threading.Event() for _ in range(4))
    a._save_index = _pause(a._save_index, a_paused, a_go)
    b._save_data = _pause(b._save_data, b_paused, b_go)
    ta = threading.Thread(target=a.save, args=("sig_a", ("code", "A")))
    tb = threading.Thread(target=b.save, args=("sig_b", ("code", "B")))
    ta.start()
    assert a_paused.wait(5.0)
    tb.start()
    # unlocked, B runs to its data write now; locked, it waits on A's lock
    assert not b_paused.wait(0.5)
    a_go.set()
    ta.join(5.0)
    b_go.set()
    tb.join(5.0)
    reader = caching.IndexDataCacheFile(str(tmp_path), "kern", (1.0, 10))
    assert reader.load("sig_a") == ("code", "A")
    assert reader.load("sig_b") == ("code", "B")


NESTED = textwrap.dedent("""
    import numpy as np
    from numba import njit, prange

    @njit(parallel=True, cache=True)
    def inner(n):
        a = np.zeros(n)
        for i in prange(n):
            a[i] = i
        return a

    @njit(cache=True)
    def outer(n):
        return inner(n).sum()
    """)


def test_a_kernel_compiled_against_cached_parallel_callees_loads_in_a_new_process(tmp_path):
    """The closed-tank segfault in miniature (kernel_cache's docstring): process 1 caches the
    parallel ``inner``; process 2 compiles ``outer`` with ``inner`` loaded from that cache; process
    3 loads ``outer`` first. Without the threading layer started on import, process 3 calls a
    null pointer (numba 0.68.1, numba issue #8578)."""
    (tmp_path / "nested.py").write_text(NESTED)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "NUMBA_NUM_THREADS": "1",
           "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    for call in ("nested.inner(10)", "nested.outer(10)", "print(nested.outer(10))"):
        r = subprocess.run([sys.executable, "-c", f"import sph_core, nested; {call}"], env=env,
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, (call, r.returncode, r.stderr[-2000:])
    assert r.stdout.strip() == "45.0"


def test_the_cache_folder_is_named_by_the_sources(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    d = kernel_cache_dir()
    assert d.startswith(str(tmp_path)) and d.rsplit("kernels-", 1)[1].isalnum()
    assert kernel_cache_dir() == d



def test_a_lock_that_cannot_be_made_steps_aside(tmp_path):
    """Where the lock file cannot be made (here its folder would be inside a file) the save or
    load goes on unlocked, as numba's own: the lock must not be what fails."""
    from sph_core.kernel_cache import _locked
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    ran = []
    with _locked(str(blocker / "cache" / "kern.nbi"), True):
        ran.append(True)
    assert ran == [True]
