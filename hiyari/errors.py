"""The one error type the CLI turns into a single line and a non-zero exit."""


class HiyariError(Exception):
    """A user-facing problem (bad file, impossible parameter) described in one line.

    The message should name the file or parameter and say what is wrong with it.
    """
