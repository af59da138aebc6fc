"""``otonav bench``: the stack against bare physics, measured in one session.

The one home of the stack's end-to-end figures (ADR 0056): bare physics, the stack, the
stack with its recorder, fixed costs, the clutter curve, a long run's memory. The
scripts in ``benchmarks/`` (not installed) measure subsystems on their own. The interface
is the command (``otonav bench``, ``make bench``): no Python API is exported.
"""

__all__ = ()
