"""Replay: re-simulate actors against a recording (scale and forensics layer).

- ``recording``: what replay reads from an MCAP file (config, types, messages in order).
- ``nodes``: which actors can be replayed, by name or import path.
- ``feed``: the time source and feeder that reproduce the recorded order.
- ``compare``: replayed against recorded outputs, per topic and field.
- ``runner``: :func:`replay_recording`, putting it together.
- ``output``: a new MCAP with the replayed outputs beside the recorded inputs.
"""

from otonav.replay._compare import Divergence, TopicComparison
from otonav.replay._recording import ReplayInputError
from otonav.replay._runner import ReplayResult, replay_recording

__all__ = (
    "Divergence",
    "ReplayInputError",
    "ReplayResult",
    "TopicComparison",
    "replay_recording",
)
