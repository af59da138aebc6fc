"""The base of every message: a frozen pydantic model that knows its ROS 2 type name."""

from __future__ import annotations

from typing import ClassVar

from pydantic import BaseModel, ConfigDict


class Message(BaseModel):
    """A frozen, validated message. ``ros_type`` is the ROS 2 type it stands for
    (``pkg/msg/Name``); recordings use it as the schema name.

    Messages built inside the stack from already-typed values use ``model_construct``
    (no validation) on the hot path; data entering from outside is validated.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    ros_type: ClassVar[str]
