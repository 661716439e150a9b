"""Hypothesis strategies producing every protocol message with valid field values."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from protocol import messages as m

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
u32 = st.integers(0, 0xFFFFFFFF)
text = st.text(max_size=40)
hashes = st.binary(min_size=32, max_size=32)


def f64s(n: int):
    return st.lists(finite, min_size=n, max_size=n).map(lambda v: np.array(v, dtype=np.float64))


def u32s(n: int):
    return st.lists(u32, min_size=n, max_size=n).map(lambda v: np.array(v, dtype=np.uint32))


counts = st.integers(0, 6)

messages = st.one_of(
    st.builds(m.Hello, u32, hashes, text, text),
    st.builds(m.Welcome, u32, hashes, finite, finite, finite, finite, finite, finite, finite,
              finite, finite, u32, u32, u32, text, text),
    st.just(m.GetNodes()),
    counts.flatmap(lambda n: counts.flatmap(lambda g: st.builds(m.Nodes, f64s(n), f64s(n), u32s(n), f64s(g)))),
    counts.flatmap(lambda n: st.builds(m.Set, finite, finite, f64s(n), f64s(n), f64s(n))),
    st.just(m.Solve()),
    st.just(m.Get()),
    counts.flatmap(lambda g: st.builds(m.Result, finite, u32, f64s(g), u32s(g), f64s(g), f64s(g))),
    st.just(m.GoBack()),
    st.builds(m.Error, u32, text),
    st.builds(m.Bye, text),
)
