"""Protocol-buffer wire encoding of many same-shaped messages at once, with numpy.

The recorder writes one OSI moving object and one Foxglove cube per actor and step; building
those field by field in Python costs microseconds per actor. Messages whose fields are all
doubles have a fixed byte layout (tags, lengths and 8-byte values), so a template row can be
tiled and the values written into it column by column. Variable parts (ids, names) are
encoded once per actor by the protobuf library and spliced in. The result parses with the
protobuf library to the same message as building it field by field (tested).

Wire format: a field is its key ``(number << 3) | wire_type`` as a varint, then the value:
wire type 1 is 8 little-endian bytes (double), wire type 2 a varint length and the bytes of a
sub-message. Fields may come in any order and repeated fields are appended, so concatenated
encodings merge.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from google.protobuf.descriptor import Descriptor, FieldDescriptor

_WIRE_FIXED64 = 1
_WIRE_LEN = 2


def varint(n: int) -> bytes:
    """Base-128 varint of a non-negative integer."""
    out = bytearray()
    while True:
        byte, n = n & 0x7F, n >> 7
        if n:
            out.append(byte | 0x80)
        else:
            out.append(byte)
            return bytes(out)


def key(number: int, wire_type: int) -> bytes:
    """The key (tag) of a field."""
    return varint((number << 3) | wire_type)


class FixedLayout:
    """One message of double fields and sub-messages of doubles, as a byte template.

    ``spec`` maps field names of ``descriptor`` to ``None`` (a double) or to a nested spec
    (a sub-message); the order of the spec is the order on the wire. ``wrap`` = (parent
    descriptor, field name) encodes the message as that field of its parent instead (key and
    length in front), so that repeated entries can be concatenated.
    """

    def __init__(
        self,
        descriptor: Descriptor,
        spec: Mapping[str, Any],
        wrap: tuple[Descriptor, str] | None = None,
    ) -> None:
        self.leaves: list[tuple[str, ...]] = []
        self._offsets: list[int] = []
        body = self._build(descriptor, spec, (), 0)
        if wrap is not None:
            number = self._field(*wrap).number
            head = key(number, _WIRE_LEN) + varint(len(body))
            self._offsets = [o + len(head) for o in self._offsets]
            body = head + body
        self.template = np.frombuffer(body, np.uint8)

    @staticmethod
    def _field(descriptor: Descriptor | None, name: str) -> FieldDescriptor:
        if descriptor is None or name not in descriptor.fields_by_name:
            raise ValueError(f"no field {name!r} in {descriptor and descriptor.full_name}")
        return descriptor.fields_by_name[name]

    def _build(self, descriptor: Descriptor, spec: Mapping[str, Any], path: tuple, start: int):
        out = bytearray()
        for name, sub in spec.items():
            field = self._field(descriptor, name)
            if sub is None:
                if field.type != FieldDescriptor.TYPE_DOUBLE:
                    raise ValueError(f"{descriptor.full_name}.{name} is not a double")
                out += key(field.number, _WIRE_FIXED64)
                self.leaves.append((*path, name))
                self._offsets.append(start + len(out))
                out += bytes(8)
            else:
                inner_start = len(self._offsets)
                body = self._build(field.message_type, sub, (*path, name), 0)
                head = key(field.number, _WIRE_LEN) + varint(len(body))
                base = start + len(out) + len(head)
                for i in range(inner_start, len(self._offsets)):
                    self._offsets[i] += base
                out += head + body
        return bytes(out)

    @property
    def size(self) -> int:
        """Bytes per message."""
        return len(self.template)

    def encode(self, columns: Sequence[np.ndarray]) -> np.ndarray:
        """(N, size) uint8 rows; ``columns`` holds one (N,) array per leaf, in leaf order."""
        if len(columns) != len(self.leaves):
            raise ValueError(f"expected {len(self.leaves)} columns, got {len(columns)}")
        n = len(columns[0]) if columns else 0
        rows = np.tile(self.template, (n, 1))
        for offset, col in zip(self._offsets, columns, strict=True):
            values = np.ascontiguousarray(col, dtype="<f8").reshape(n, 1)
            rows[:, offset : offset + 8] = values.view(np.uint8)
        return rows


def splice(field_key: bytes, fixed: np.ndarray, tails: Sequence[bytes]) -> bytes:
    """Repeated length-delimited entries ``key, varint(len), fixed[i], tails[i]`` as bytes."""
    n = len(tails)
    if n == 0:
        return b""
    fixed = np.ascontiguousarray(fixed, np.uint8).reshape(n, -1)
    width = fixed.shape[1]
    tail_len = np.fromiter((len(t) for t in tails), np.int64, n)
    body = width + tail_len
    if body.max() >= 1 << 14:
        raise ValueError("entries of 16 KiB or more are not supported")
    vlen = np.where(body < 128, 1, 2)
    k = len(field_key)
    total = k + vlen + body
    start = np.concatenate([[0], np.cumsum(total)[:-1]])
    out = np.empty(int(total.sum()), np.uint8)
    out[(start[:, None] + np.arange(k)).ravel()] = np.tile(np.frombuffer(field_key, np.uint8), n)
    one = vlen == 1
    out[start[one] + k] = body[one]
    out[start[~one] + k] = (body[~one] & 0x7F) | 0x80
    out[start[~one] + k + 1] = body[~one] >> 7
    fixed_at = start + k + vlen
    out[(fixed_at[:, None] + np.arange(width)).ravel()] = fixed.ravel()
    tail_at = fixed_at + width
    tail_start = np.concatenate([[0], np.cumsum(tail_len)[:-1]])
    idx = np.repeat(tail_at - tail_start, tail_len) + np.arange(int(tail_len.sum()))
    out[idx] = np.frombuffer(b"".join(tails), np.uint8)
    return out.tobytes()
