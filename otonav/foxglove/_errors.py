"""The live view's one-line error, importable without the ``otonav[foxglove]`` extra."""


class LiveViewError(ValueError):
    """The live view cannot start: one line saying why and what to do."""
