"""Turn an unfinished recording (a ``.part`` left by a killed run, or a cut copy) into a
finished MCAP file that every reader opens: the OSI trace readers and Foxglove need the
summary section that only a finished file has."""

from __future__ import annotations

from pathlib import Path

from mcap.records import Attachment, Channel, Message, Metadata, Schema
from mcap.writer import Writer

from hiyari.atomic import atomic_path
from hiyari.bridge.record.reader import Recording
from hiyari.errors import HiyariError
from hiyari.version import __version__


def recover(source: str | Path, out: str | Path) -> Recording:
    """Copy every complete chunk of ``source`` into a finished MCAP file ``out``.

    Returns the source as opened (its frames and times are what ``out`` holds). Schemas,
    channels, metadata and attachments are copied as they are; a ``hiyari.recovered``
    metadata record names the source and what was missing.
    """
    out = Path(out)
    if out.suffix != ".mcap":
        raise HiyariError(f"{out}: a recording file name must end in .mcap")
    if out.resolve() == Path(source).resolve():
        raise HiyariError(f"{out}: write the recovered recording to another file")
    rec = Recording.open(source)
    with atomic_path(out) as tmp, tmp.open("wb") as f:
        w = Writer(f)
        w.start(profile="", library=f"hiyari {__version__}")
        schemas: dict[int, int] = {0: 0}
        channels: dict[int, int] = {}
        for r in rec.records():
            if isinstance(r, Schema):
                schemas[r.id] = w.register_schema(r.name, r.encoding, r.data)
            elif isinstance(r, Channel):
                channels[r.id] = w.register_channel(
                    r.topic, r.message_encoding, schemas[r.schema_id], r.metadata
                )
            elif isinstance(r, Metadata):
                w.add_metadata(r.name, r.metadata)
            elif isinstance(r, Attachment):
                w.add_attachment(r.create_time, r.log_time, r.name, r.media_type, r.data)
            elif isinstance(r, Message):
                w.add_message(
                    channels[r.channel_id], r.log_time, r.data, r.publish_time, r.sequence
                )
        w.add_metadata(
            "hiyari.recovered",
            {"source": Path(source).name, "frames": str(len(rec)), "problem": rec.problem or ""},
        )
        w.finish()
    return rec
