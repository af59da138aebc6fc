"""Waiting for a future without letting the waiter's cancellation cancel it."""

from __future__ import annotations

import asyncio
from typing import Any

import anyio
import anyio.to_thread


async def _wait_done(future: asyncio.Future[Any]) -> bool:
    """Wait until ``future`` is done whatever cancels the caller meanwhile (anyio cancel
    scopes are shielded, asyncio's ``task.cancel()`` is absorbed). Returns True when the
    caller was cancelled while waiting; the caller re-raises then."""
    cancelled = False
    with anyio.CancelScope(shield=True):
        while not future.done():
            try:
                await asyncio.wait((future,))
            except asyncio.CancelledError:
                cancelled = True
    return cancelled
