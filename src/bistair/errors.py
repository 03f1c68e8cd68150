"""The one exception type bistair raises for bad input."""


class BistairError(ValueError):
    """Bad input: a spec that does not fit, captures that cannot be decoded, unreadable files.

    The message is one line that names the problem; the CLI prints it and exits with code 2.
    """
