"""Embedding otonav in an asyncio service, on the service's own event loop.

Two shapes, one entry point each:

- :func:`open_live_stack` (from :mod:`otonav.engine`): a live robot on the host's (stock)
  loop in real-time mode: the world is stepped to follow the wall clock
  (``time=RealTime(scale)``). The host subscribes
  to topics (async iterators of typed messages), publishes goals and commands, reads
  the graph and its statistics; the stack closes cleanly, its recording finished, when
  the ``async with`` exits or the host task is cancelled.

      async with open_live_stack(record_to=Path("live.mcap")) as live:
          await live.publish_goal(4.0, 1.5)
          async with live.subscribe("/odom", Odometry, HOST_QOS) as odom:
              async for message in odom:
                  ...

- :func:`run_scenario_async`: a fast simulation on request. The scenario runs on its
  own virtual-time loop in a worker thread (at most ``limiter.total`` at once) while
  the host's loop keeps serving; it returns the verdict with its artifact paths.
  Cancelling the awaiting task stops the simulation and waits until its recording is
  finished (an indexed, readable file) before the cancellation propagates.

Blocking work on the host's loop: physics runs inside the real-time clock's advances. A
pacer task consults the clock every half ``max_step_batch`` of wall time, so the world
follows the wall clock in small batches (5 steps of 2 ms between the bridge's 100 Hz
wakes, at most 25) even while every actor sleeps; no advance steps more than
``max_step_batch`` (:data:`~otonav.runtime.MAX_STEP_BATCH`, 0.05 s of sim time: 25
MuJoCo steps, well under a millisecond for the shipped robot). After the host's loop
stalls for longer than that, the stack does not catch up in one long burst: sim time
*slips* (it falls behind the wall clock by the excess, counted in
:attr:`LiveStack.slip_s`), as a simulator running below real time does. The other work
on the host's loop is the actors' own (a lidar scan ~0.1 ms, an MCAP chunk compressed
every 64 KiB when recording).
"""

from otonav.embed._runs import DEFAULT_MAX_RUNS, check_run, default_limiter, run_scenario_async
from otonav.engine import HOST_QOS, LiveStack, LiveSubscription, open_live_stack

__all__ = (
    "DEFAULT_MAX_RUNS",
    "HOST_QOS",
    "LiveStack",
    "LiveSubscription",
    "check_run",
    "default_limiter",
    "open_live_stack",
    "run_scenario_async",
)
