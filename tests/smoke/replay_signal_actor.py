"""A replayed node that signals its own process at 1 s of sim time (the signal's name is
in ``OTONAV_TEST_SIGNAL``): ``otonav replay --node replay_signal_actor:SignalsItself``.
A signal at a known instant of the replay, not at a wall-clock guess."""

from __future__ import annotations

import os
import signal

from otonav.msgs import Odometry, Twist
from otonav.runtime import SENSOR_DATA_QOS, Actor, Input, Output, QoS


class SignalsItself(Actor):
    odom = Input("/odom", Odometry, SENSOR_DATA_QOS)
    cmd = Output("/cmd_vel_nav", Twist, QoS(depth=10))

    async def run(self) -> None:
        rate = self.clock.rate(20.0)
        sent = False
        while True:
            await rate.sleep()
            self.odom.take_latest()
            if not sent and self.clock.now() >= 1.0:
                sent = True
                os.kill(os.getpid(), signal.Signals[os.environ["OTONAV_TEST_SIGNAL"]])
            await self.cmd.publish(Twist())
