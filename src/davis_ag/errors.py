"""The one exception type the command line turns into a one-line message."""


class UserError(Exception):
    """Bad input or an unusable environment: the message says what, where and how to fix it.

    The command line prints it as a single line and exits non-zero, never with a traceback.
    """
