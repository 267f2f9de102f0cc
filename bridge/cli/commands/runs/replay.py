"""``hiyari replay``: a recording in the browser (viser), live or exported to static HTML."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from pathlib import Path

from hiyari.bridge.cli import numbers
from hiyari.bridge.cli.outputs import output_file
from hiyari.errors import HiyariError


def run(args: argparse.Namespace) -> int:
    from hiyari.bridge.record.reader import Recording
    from hiyari.bridge.replay.scene import ReplayOptions

    if not 0 <= args.port <= 65535:
        raise HiyariError(f"--port must be 0..65535, got {args.port}")
    # before any work: an export is minutes of work for a large recording
    for option, path in (("--export", args.export), ("--recover", args.recover)):
        if path is not None:
            output_file(path, option)
    if args.recover:
        from hiyari.bridge.record.recover import recover

        rec = recover(args.recording, args.recover)
        print(
            f"recovered {len(rec)} frames ({rec.times[0]:.1f}-{rec.times[-1]:.1f} s) of "
            f"{rec.path} into {args.recover}"
        )
        return 0
    rec = Recording.open(args.recording)
    if rec.problem:
        hint = " (--recover OUT.mcap writes a finished copy)"
        print(f"hiyari: warning: {rec.problem}{hint}", file=sys.stderr)
    options = ReplayOptions(lidar_colors=args.point_colors)
    span = f"{len(rec)} frames, {rec.times[0]:.1f}-{rec.times[-1]:.1f} s"
    if args.export:
        from hiyari.bridge.replay.export import export_html, frame_range

        frames = frame_range(rec, args.start, args.end, args.every)
        out = export_html(rec, args.export, options, frames, progress=not args.quiet)
        size = out.stat().st_size / 2**20
        print(f"static replay of {rec.path} ({len(frames)} of {span}): {out} ({size:.1f} MiB)")
        return 0
    from hiyari.bridge.replay.server import ReplayApp

    app = ReplayApp(rec, host=args.host, port=args.port, options=options)
    stop = threading.Event()
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, lambda *_: stop.set())
    print(f"replay of {rec.path} ({span}) at {app.url}  (Ctrl-C to stop)", flush=True)
    if args.browser:
        import webbrowser

        webbrowser.open(app.url)
    try:
        stop.wait()
    except KeyboardInterrupt:
        pass
    finally:
        app.close()
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    sub.add_parser(
        "replay",
        help="replay a recording (.mcap) in the browser, or export it as static HTML",
        setup=_arguments,  # the colour modes come with viser: loaded only when used
    )


def _arguments(p: argparse.ArgumentParser) -> None:
    from hiyari.bridge.replay.scene import LIDAR_COLOR_MODES

    p.add_argument("recording", type=Path, help="recording written by the Recorder (.mcap)")
    p.add_argument("--host", default="127.0.0.1", help="address to serve on")
    p.add_argument(
        "--port", type=numbers.count(0, 65535), default=8080, help="port (next free one if taken)"
    )
    p.add_argument("--browser", action="store_true", help="open the replay in a web browser")
    p.add_argument(
        "--point-colors",
        choices=LIDAR_COLOR_MODES,
        default="intensity",
        help="colour LiDAR points by intensity or by the actor they hit",
    )
    p.add_argument("--export", type=Path, help="write a static HTML replay here instead")
    p.add_argument("--start", type=numbers.seconds(lo_open=False), help="export from this time, s")
    p.add_argument("--end", type=numbers.seconds(lo_open=False), help="export up to this time, s")
    p.add_argument("--every", type=numbers.count(1), default=1, help="export every N-th frame")
    p.add_argument(
        "--recover",
        type=Path,
        metavar="OUT",
        help="write the complete part of an unfinished recording (.part) as a finished .mcap",
    )
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.set_defaults(func=run)
