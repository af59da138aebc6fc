"""otonav's version, in one place (pyproject.toml reads it: ``[tool.hatch.version]``).

A constant of the code, so that what a run records (the MCAP header's ``library``, the
``otonav_version`` metadata) depends on the code that ran and nothing else. It used to
be looked up in the installed distribution's metadata on disk, three times a run: a
reinstall of the environment meanwhile (``make`` reinstalls the venv in place whenever
pyproject.toml changed; pip removes the old ``.dist-info`` before it writes the new
one) failed the lookup, and a run in that window recorded ``unknown``: the same config
and seed, other bytes.
"""

__version__ = "0.1.0"
