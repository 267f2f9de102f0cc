"""One module per ``hiyari`` subcommand; each has ``register(subparsers)``."""
