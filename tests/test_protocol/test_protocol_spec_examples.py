"""The example frames printed in PROTOCOL.md, checked in both directions against the code."""

from __future__ import annotations

import ast
import re
import shlex
from pathlib import Path

import numpy as np
import pytest

from protocol import NO_SCENE_HASH, decode_frame, encode_frame
from protocol.messages import MESSAGE_CLASSES
from protocol.wire import MessageType

SPEC = Path(__file__).resolve().parents[2] / "protocol" / "PROTOCOL.md"
BLOCK = re.compile(r"```hex (?P<info>[^\n]*)\n(?P<hex>.*?)```", re.S)


def _examples():
    out = []
    for match in BLOCK.finditer(SPEC.read_text()):
        name, *pairs = shlex.split(match["info"])
        fields = dict(p.split("=", 1) for p in pairs)
        seq = int(fields.pop("seq"))
        # numbers and lists are Python literals; anything else (quotes removed by shlex) is text
        values = {k: (NO_SCENE_HASH if k == "scene_hash" and v == "0" else
                      ast.literal_eval(v) if _literal(v) else v) for k, v in fields.items()}
        out.append(pytest.param(name, seq, values, bytes.fromhex(match["hex"]), id=name))
    return out


def _literal(v: str) -> bool:
    try:
        ast.literal_eval(v)
        return True
    except (ValueError, SyntaxError):
        return False


EXAMPLES = _examples()


def test_spec_has_examples_of_the_main_messages():
    assert {p.values[0] for p in EXAMPLES} >= {"HELLO", "SET", "SOLVE", "RESULT", "ERROR", "BYE"}


@pytest.mark.parametrize("name,seq,values,data", EXAMPLES)
def test_spec_bytes_decode_to_the_stated_message(name, seq, values, data):
    got_seq, msg = decode_frame(data)
    assert got_seq == seq and msg.TYPE is MessageType[name]
    for key, value in values.items():
        assert np.array_equal(getattr(msg, key), value), key


@pytest.mark.parametrize("name,seq,values,data", EXAMPLES)
def test_stated_message_encodes_to_the_spec_bytes(name, seq, values, data):
    msg = MESSAGE_CLASSES[MessageType[name]](**values)
    assert encode_frame(msg, seq) == data
