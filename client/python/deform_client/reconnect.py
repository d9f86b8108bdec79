"""ReconnectPolicy: how a Deform stream survives the loss of its server, in both clients.

The C++ library's policy (client/lib/deform_client.h, ReconnectPolicy; reconnecting_stream.cc),
for a replica that died or drained, or a mesh still being built on the replica a balancer chose
(docs/cluster.md). With a policy, a stream that ends UNAVAILABLE (or CANCELLED without the caller
cancelling it: a balancer resets the streams of a server that died) is opened again on the same
mesh id after a delay, and the latest pose and the latest stiffness update are sent again; the
caller's frames go on from the new server in the same iterator, `stream.reconnects` counts the
re-opened calls and `on_reconnect(loss, attempt)` (optional) hears of each.

Delays: the server's google.rpc.RetryInfo when the loss carried one (DeformError.retry_delay),
else initial_backoff doubling with each attempt since the last frame up to max_backoff; each
with up to 20% added at random, so that the clients of one lost server do not come back at once.
It gives up, and the stream fails with the last loss's DeformError, once give_up_after seconds
have passed since the loss (the first since the stream's last frame). Off by default.
"""

from __future__ import annotations

import dataclasses
import random
from typing import Callable, Optional, Union

import grpc

from .errors import DeformError

_JITTER = 0.2

OnReconnect = Callable[[DeformError, int], None]
"""on_reconnect(loss, attempt): the stream was lost with `loss` and has been opened again (its
`attempt`-th try since the last frame); called from the thread (or task) that reads the stream,
before the new server's frames."""


@dataclasses.dataclass(frozen=True)
class ReconnectPolicy:
    initial_backoff: float = 0.05   # seconds before the first attempt (without a RetryInfo)
    max_backoff: float = 1.0        # the doubling stops here
    give_up_after: float = 10.0     # seconds since the loss after which the stream fails

    def __post_init__(self) -> None:
        if not (0 < self.initial_backoff <= self.max_backoff and self.give_up_after >= 0):
            raise ValueError("a ReconnectPolicy needs 0 < initial_backoff <= max_backoff and "
                             "give_up_after >= 0")

    def delay(self, attempt: int, retry_delay: float, rng: random.Random) -> float:
        """Seconds to wait before `attempt` (1 for the first since the last frame)."""
        if retry_delay > 0:
            base = retry_delay
        else:
            base = min(self.initial_backoff * 2.0 ** max(0, attempt - 1), self.max_backoff)
        return base * (1.0 + rng.uniform(0.0, _JITTER))


Reconnect = Union[bool, ReconnectPolicy, None]
"""What stream(reconnect=) takes: False or None (off), True (the default policy) or a policy."""


def policy_of(reconnect: Reconnect) -> Optional[ReconnectPolicy]:
    if isinstance(reconnect, ReconnectPolicy):
        return reconnect
    return ReconnectPolicy() if reconnect else None


def is_loss(error: DeformError, cancelled_by_caller: bool) -> bool:
    """Whether a stream's failure means its server was lost (and not the stream refused)."""
    return error.code == grpc.StatusCode.UNAVAILABLE or (
        error.code == grpc.StatusCode.CANCELLED and not cancelled_by_caller)
