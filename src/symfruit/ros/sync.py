"""Approximate-time synchronisation of a camera's topics, without ROS: :class:`ApproximateSync`.

ROS 2's ``message_filters`` has no wheel, so the ROS 2 node pairs its inputs here. The rule is small and
greedy, made for a camera driver whose topics carry (nearly) the same stamp per frame:

- every topic keeps its ``queue_size`` newest messages, ordered by header stamp;
- on each arrival, the newest message of the first topic (the *pivot*: the colour image) that has, on every
  other topic, a message within ``slop`` seconds of it makes a set, with the nearest such message of each;
- the set is emitted once; every queued message stamped at or before its members is dropped (an older
  pivot still waiting would only be a frame the node skips anyway), so each message is used at most once
  and the emitted pivots' stamps strictly increase;
- a message stamped at or before the last emitted set's member of its topic (out of order) is refused and
  counted in :attr:`ApproximateSync.late`; one stamped more than ``jump_back`` seconds before it (a bag
  replay restarted, a clock reset) clears the queues and starts afresh from it, counted in
  :attr:`ApproximateSync.resets`; a message without a stamp is refused and counted in
  :attr:`ApproximateSync.unstamped`.

Stamps come from :func:`symfruit.io.bags.header_stamp` (``sec``/``nanosec`` or ``secs``/``nsecs``), so any
message with a header works. Not thread-safe: call :meth:`ApproximateSync.add` from one thread (an rclpy
single-threaded executor's callbacks).
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence
from typing import Any

from ..io.bags import header_stamp

__all__ = ["ApproximateSync"]


class ApproximateSync:
    """Pair messages of ``n_topics`` topics by approximate header stamp (see the module docstring).

    Parameters
    ----------
    n_topics : int
        How many topics (>= 1); topic 0 is the pivot.
    callback : callable
        Called as ``callback(msg_0, ..., msg_{n-1})`` for every set, from :meth:`add`.
    slop : float, seconds
        Largest difference of a member's stamp from the pivot's (>= 0).
    queue_size : int
        Messages kept per topic (>= 1); the oldest is dropped first.
    jump_back : float, seconds
        A stamp this much older than the last set's starts afresh instead of being refused (> 0).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> def msg(sec, nanosec=0):
    ...     return NS(header=NS(stamp=NS(sec=sec, nanosec=nanosec)))
    >>> sets = []
    >>> sync = ApproximateSync(2, lambda a, b: sets.append((a, b)), slop=0.01)
    >>> sync.add(0, msg(5))
    >>> sync.add(1, msg(5, 3_000_000))  # 3 ms later: within slop
    >>> len(sets)
    1
    """

    def __init__(
        self,
        n_topics: int,
        callback: Callable[..., Any],
        *,
        slop: float = 0.05,
        queue_size: int = 5,
        jump_back: float = 1.0,
    ) -> None:
        if n_topics < 1:
            raise ValueError(f"n_topics must be at least 1, got {n_topics}")
        if not slop >= 0:  # also refuses NaN
            raise ValueError(f"slop must be seconds >= 0, got {slop!r}")
        if queue_size < 1:
            raise ValueError(f"queue_size must be at least 1, got {queue_size}")
        if not jump_back > 0:
            raise ValueError(f"jump_back must be seconds > 0, got {jump_back!r}")
        self.callback = callback
        self.slop_ns = round(slop * 1e9)
        self.jump_ns = round(jump_back * 1e9)
        self.queue_size = int(queue_size)
        self._queues: list[list[tuple[int, int, Any]]] = [[] for _ in range(n_topics)]  # (stamp, arrival, msg)
        self._last: list[int | None] = [None] * n_topics  # each topic's stamp in the last emitted set
        self._arrivals = 0
        self.emitted = 0
        self.late = 0
        self.unstamped = 0
        self.overflowed = 0
        self.resets = 0

    def add(self, topic: int, msg: Any) -> None:
        """Offer a message of ``topic`` (0-based); emits at most one set."""
        stamp = header_stamp(msg)
        if stamp is None:
            self.unstamped += 1
            return
        last = self._last[topic]
        if last is not None and stamp <= last:
            if last - stamp <= self.jump_ns:
                self.late += 1
                return
            self.reset()
            self.resets += 1
        queue = self._queues[topic]
        self._arrivals += 1
        bisect.insort(queue, (stamp, self._arrivals, msg), key=lambda entry: (entry[0], entry[1]))
        if len(queue) > self.queue_size:
            del queue[0]
            self.overflowed += 1
        self._emit_newest()

    def _nearest(self, queue: Sequence[tuple[int, int, Any]], stamp: int) -> tuple[int, int, Any] | None:
        """The queued message nearest ``stamp`` within the slop (the older one of two equally near)."""
        best = None
        for entry in queue:
            gap = abs(entry[0] - stamp)
            if gap <= self.slop_ns and (best is None or gap < abs(best[0] - stamp)):
                best = entry
        return best

    def _emit_newest(self) -> None:
        for pivot in reversed(self._queues[0]):
            members = [pivot]
            for queue in self._queues[1:]:
                match = self._nearest(queue, pivot[0])
                if match is None:
                    break
                members.append(match)
            else:
                for i, (queue, member) in enumerate(zip(self._queues, members, strict=True)):
                    queue[:] = [e for e in queue if e[0] > member[0]]
                    self._last[i] = member[0]
                self.emitted += 1
                self.callback(*(m[2] for m in members))
                return

    def reset(self) -> None:
        """Forget every queued message and the last set (counters stay)."""
        for queue in self._queues:
            queue.clear()
        self._last = [None] * len(self._queues)

    def pending(self) -> list[int]:
        """How many messages wait on each topic."""
        return [len(q) for q in self._queues]
