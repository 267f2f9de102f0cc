"""Run ``hiyari ARGS`` with files limited to LIMIT bytes, as a full disk stops writes:
``python tests/support/disk_limit.py LIMIT ARGS...``. SIGXFSZ is ignored, so a write past the limit
fails with EFBIG (an OSError, as ENOSPC would) instead of killing the process. Only this
process is limited: forked children (the campaign pool's workers) get the limit lifted."""

from __future__ import annotations

import os
import resource
import signal
import sys

if __name__ == "__main__":
    limit = int(sys.argv[1])
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    _, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    os.register_at_fork(
        after_in_child=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (hard, hard))
    )
    from hiyari.bridge.cli.main import main

    sys.exit(main(sys.argv[2:]))
