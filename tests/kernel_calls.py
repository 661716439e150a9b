"""Which numba kernels this test process has called (tests/conftest.py's `unit` guard)."""

from __future__ import annotations


class KernelCalls:
    """Counts numba dispatchers gaining an overload (a compile or a cache load: a kernel's first
    call with these argument types in this process)."""

    def __init__(self) -> None:
        self.names: list[str] = []
        try:
            from numba.core.dispatcher import Dispatcher
        except ImportError:  # no numba: nothing to count
            return
        original = Dispatcher.compile
        names = self.names

        def compile(self, sig):  # noqa: ANN001 -- numba's own signature
            before = len(self.overloads)
            try:
                return original(self, sig)
            finally:
                if len(self.overloads) > before:
                    names.append(getattr(self.py_func, "__qualname__", str(self)))

        Dispatcher.compile = compile


KERNEL_CALLS = KernelCalls()
