"""``python -m hiyari`` runs the CLI."""

import sys

from hiyari.bridge.cli.main import main

sys.exit(main())
