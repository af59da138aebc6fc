"""ROS 2 CDR for otonav messages, both ways: :func:`encode` (the bytes ROS 2 puts on the
wire and in bags) and :func:`decode` (the same pydantic message back, bit for bit), both
compiled per message class from one layout (:mod:`otonav.record.cdr._layout`).
``mcap_ros2``'s generic decoder stays in the tests as the independent oracle."""

from otonav.record.cdr._decode import decode, flat_values
from otonav.record.cdr._encode import encode
from otonav.record.cdr._layout import ENCAPSULATION

__all__ = ("ENCAPSULATION", "decode", "encode", "flat_values")
