"""The ``hiyari`` command line: argparse commands and demos (the only place that picks matplotlib's backend)."""
