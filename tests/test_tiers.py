"""The tiers' guard (tests/conftest.py): a kernel's first call is seen, so a `unit` test that
calls one fails."""

from __future__ import annotations

import numba

from kernel_calls import KERNEL_CALLS


def test_a_kernels_first_call_is_counted():
    @numba.njit
    def tiers_probe_kernel(x):
        return x + 1

    seen = len(KERNEL_CALLS.names)
    assert tiers_probe_kernel(1) == 2
    assert tiers_probe_kernel(2) == 3  # compiled already: not counted again
    assert [n for n in KERNEL_CALLS.names[seen:] if "tiers_probe_kernel" in n] \
        == ["test_a_kernels_first_call_is_counted.<locals>.tiers_probe_kernel"]
