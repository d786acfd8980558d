"""symfruit.ros.sync: the approximate-time synchroniser of the ROS 2 node, on plain stamped objects."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from symfruit.ros.sync import ApproximateSync

MS = 1_000_000  # nanoseconds


def msg(t_ns: int, name: str = "") -> SimpleNamespace:
    """A message stamped ``t_ns`` (ROS 2 fields), named for the assertions."""
    return SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(sec=t_ns // 10**9, nanosec=t_ns % 10**9)),
                           name=name)  # fmt: skip


class Recorder:
    def __init__(self) -> None:
        self.sets: list[tuple[str, ...]] = []

    def __call__(self, *msgs: SimpleNamespace) -> None:
        self.sets.append(tuple(m.name for m in msgs))


def make(n: int = 3, **kw) -> tuple[ApproximateSync, Recorder]:
    rec = Recorder()
    return ApproximateSync(n, rec, **kw), rec


def test_a_camera_frame_is_paired_whatever_the_arrival_order():
    for order in [(0, 1, 2), (2, 1, 0), (1, 2, 0), (2, 0, 1)]:
        sync, rec = make(slop=0.05)
        for topic in order:
            sync.add(topic, msg(10**9 + (3 * MS if topic == 1 else 0), f"{topic}"))
        assert rec.sets == [("0", "1", "2")], order
        assert sync.pending() == [0, 0, 0]


def test_the_nearest_member_within_slop_is_taken():
    sync, rec = make(2, slop=0.02)
    sync.add(1, msg(100 * MS, "far"))  # 30 ms before: outside the slop
    sync.add(1, msg(125 * MS, "near"))  # 5 ms before
    sync.add(1, msg(140 * MS, "after"))  # 10 ms after
    sync.add(0, msg(130 * MS, "pivot"))
    assert rec.sets == [("pivot", "near")]
    assert sync.pending() == [0, 1]  # "after" (newer than the member used) still waits


def test_nothing_within_slop_emits_nothing_and_the_queue_is_bounded():
    sync, rec = make(2, slop=0.01, queue_size=3)
    for k in range(5):
        sync.add(0, msg(k * 100 * MS, f"c{k}"))
        sync.add(1, msg(k * 100 * MS + 50 * MS, f"d{k}"))  # 50 ms apart: never a pair
    assert rec.sets == [] and sync.pending() == [3, 3] and sync.overflowed == 4
    sync.add(1, msg(400 * MS + 5 * MS, "d4b"))
    assert rec.sets == [("c4", "d4b")]


def test_the_newest_complete_set_wins_and_older_waiting_pivots_are_dropped():
    sync, rec = make(2, slop=0.005)
    sync.add(0, msg(100 * MS, "c1"))
    sync.add(0, msg(133 * MS, "c2"))  # c1's partner never comes
    sync.add(1, msg(133 * MS, "d2"))
    assert rec.sets == [("c2", "d2")]
    assert sync.pending() == [0, 0]  # c1 went with the set's past
    sync.add(1, msg(100 * MS, "d1"))  # now too late for c1
    assert sync.late == 1 and rec.sets == [("c2", "d2")]


def test_each_message_is_used_once_and_pivots_only_move_forward():
    sync, rec = make(2, slop=0.05)
    sync.add(1, msg(100 * MS, "d"))
    sync.add(0, msg(100 * MS, "c1"))
    sync.add(0, msg(110 * MS, "c2"))  # d was used by c1
    assert rec.sets == [("c1", "d")]
    sync.add(0, msg(90 * MS, "old"))  # out of order, within a second: refused
    sync.add(0, msg(100 * MS, "same"))  # the same stamp again: refused
    assert sync.late == 2 and sync.pending() == [1, 0]
    sync.add(1, msg(111 * MS, "d2"))
    assert rec.sets == [("c1", "d"), ("c2", "d2")]


def test_a_jump_back_in_time_starts_afresh():
    sync, rec = make(2, slop=0.01, jump_back=1.0)
    sync.add(0, msg(50 * 10**9, "c"))
    sync.add(1, msg(50 * 10**9, "d"))
    sync.add(0, msg(2 * 10**9, "c-replay"))  # 48 s back: a bag replay restarted
    assert sync.resets == 1 and sync.late == 0 and sync.pending() == [1, 0]
    sync.add(1, msg(2 * 10**9, "d-replay"))
    assert rec.sets == [("c", "d"), ("c-replay", "d-replay")]


def test_ros1_stamps_and_unstamped_messages():
    sync, rec = make(2, slop=0.0)
    ros1 = SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(secs=3, nsecs=5)), name="ros1")
    sync.add(0, ros1)
    sync.add(1, msg(3 * 10**9 + 5, "ros2"))  # slop 0: the very same stamp pairs
    sync.add(1, SimpleNamespace(name="no header"))
    assert rec.sets == [("ros1", "ros2")] and sync.unstamped == 1


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"n_topics": 0}, "n_topics must be at least 1"),
        ({"slop": -0.1}, "slop must be seconds >= 0"),
        ({"slop": float("nan")}, "slop must be seconds >= 0"),
        ({"queue_size": 0}, "queue_size must be at least 1"),
        ({"jump_back": 0.0}, "jump_back must be seconds > 0"),
    ],
)
def test_bad_settings_are_refused(kw, message):
    args = {"n_topics": 3, **kw}
    with pytest.raises(ValueError, match=message):
        ApproximateSync(args.pop("n_topics"), print, **args)
