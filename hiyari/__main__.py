"""``python -m hiyari`` runs the CLI."""

import sys

from hiyari.bridge.cli import main

sys.exit(main())
