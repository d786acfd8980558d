"""A frame's fruit on kept worker processes (symfruit.fruitpool; issue 19, stop 53). No timing here: every wait in
the pool is bounded (minutes), and nothing below depends on which process takes which fruit but where a test makes
the workers take every fruit (``_caller_shares``)."""

import json
import multiprocessing
import os
import signal
import sys
import types
import warnings

import numpy as np
import pytest

from symfruit import InputError, SymfruitError
from symfruit import fruitpool as fp
from symfruit.core.frame import Frame
from symfruit.detect import _Fruit, detect
from symfruit.fruitpool import MAX_FRUIT_PROCESSES, FruitPool, check_fruit_processes, one_process_reason
from symfruit.writers import detection_record

from .conftest import SMALL_CAM, disc_frame

pytestmark = [
    pytest.mark.xdist_group("fruitpool"),  # one test process starts the workers, one forkserver
    pytest.mark.skipif(one_process_reason(1) != "", reason=f"no worker processes here: {one_process_reason(1)}"),
]


@pytest.fixture(scope="module")
def pool():
    with FruitPool(1, method=None) as made:
        assert made.active, made.reason
        yield made


@pytest.fixture
def workers_only(pool):
    """The pool with the workers taking every fruit (the calling process waits): what a test checks of the
    workers then happens whatever the host's load."""
    pool._caller_shares = False
    yield pool
    pool._caller_shares = True


def bench(seed):
    from symfruit.evaluate.bench import _bench_scene

    return _bench_scene(None, seed)[0]


def small(centres, labels=None):
    color, depth = disc_frame(centres, radius=15)
    return Frame("small", color, depth, SMALL_CAM, masks=labels)


def record(d):
    """A detection's record but for the seconds its completion took."""
    out = detection_record(d)
    out.pop("seconds", None)
    return json.dumps(out)


def assert_same(a, b):
    """Two frames' detections the same, bit for bit: their records (but for their time), masks, points and
    completions."""
    assert len(a.detections) == len(b.detections)
    for x, y in zip(a.detections, b.detections, strict=True):
        assert record(x) == record(y)
        assert np.array_equal(x.mask, y.mask) and x.mask.dtype == y.mask.dtype
        assert (x.extraction.silhouette is x.mask) == (y.extraction.silhouette is y.mask)
        assert np.array_equal(x.extraction.points, y.extraction.points)
        assert (x.result is None) == (y.result is None) and x.error == y.error
        if x.result is not None:
            for u, v in ((x.result.points, y.result.points), (x.result.score, y.result.score),
                         (x.result.scores, y.result.scores), (x.result.box.min, y.result.box.min)):  # fmt: skip
                assert np.asarray(u).tobytes() == np.asarray(v).tobytes()  # bit for bit (NaN too)
            assert repr(sorted(x.result.extras.items())) == repr(sorted(y.result.extras.items()))
        if x.occlusion is not None:
            assert np.array_equal(x.occlusion.hidden, y.occlusion.hidden) and x.occlusion.u0 == y.occlusion.u0
    assert a.timings.keys() == b.timings.keys() and a.registration == b.registration


def frames():
    """Generated frames: the benchmark's (9 fruit, more than the workers), one with a fruit too small to complete
    and one whose mask holds only the background (both reported with their error), one fruit, none."""
    tiny = np.zeros((120, 160), np.int32)
    tiny[45:76, 25:56], tiny[2:4, 2:4], tiny[50:70, 100:130] = 1, 2, 3
    grey = small([(40, 60), (120, 60)])
    yy, xx = np.mgrid[:120, :160]
    wall = np.zeros((120, 160), np.int32)
    wall[(xx - 40) ** 2 + (yy - 60) ** 2 <= 15**2] = 1
    wall[(xx - 120) ** 2 + (yy - 60) ** 2 <= 18**2] = 2
    depth = grey.depth.copy()
    depth[(xx - 120) ** 2 + (yy - 60) ** 2 <= 15**2] = 0.0
    return [
        ("benchmark 0", bench(0), "evidence"),
        ("benchmark 1", bench(1), "paper"),
        ("a fruit too small", small([(40, 60), (115, 60)], tiny), "evidence"),
        ("the background", Frame("wall", np.full_like(grey.color, 90), depth, SMALL_CAM, masks=wall), "raw"),
        ("one fruit", small([(40, 60)]), "evidence"),
        ("no fruit", small([]), "evidence"),
    ]


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_the_detections_are_the_same_with_the_pool(pool, shares):
    pool._caller_shares = shares
    try:
        before = pool.fruit_elsewhere
        errors, counts = 0, []
        for _, frame, method in frames():
            one, two = detect(frame, method=method), detect(frame, method=method, pool=pool)
            assert_same(one, two)
            errors += sum(bool(d.error) for d in two.detections)
            counts.append(len(two.detections))
        assert errors >= 2 and counts[0] == 9 and counts[-2:] == [1, 0]  # as frames() says
        if not shares:  # every fruit of every frame of two fruit or more
            assert pool.fruit_elsewhere - before == sum(n for n in counts if n >= 2)
    finally:
        pool._caller_shares = True


def test_the_frames_arrays_go_through_one_segment_grown_for_a_larger_frame(workers_only):
    pool = workers_only
    detect(small([(40, 60), (120, 60)]), method="raw", pool=pool)
    first = pool._state.segment.name
    assert os.path.exists(f"/dev/shm/{first}") and first in ours()
    frame = bench(0)
    one, two = detect(frame, pool=pool), detect(frame, pool=pool)
    assert_same(one, two)
    grown = pool._state.segment
    if grown.name != first:  # 640x480 needs more than the first segment's megabyte: a new one, the old unlinked
        assert not os.path.exists(f"/dev/shm/{first}") and grown.size >= 640 * 480 * (4 + 3 + 4 + 1)
    assert_same(detect(small([(40, 60), (120, 60)]), method="raw"),
                detect(small([(40, 60), (120, 60)]), method="raw", pool=pool))  # fmt: skip
    assert pool._state.segment is grown  # a smaller frame fits


class Failing(_Fruit):
    """A fruit task that raises for the fruit its ``fail`` names (a bug inside a fruit, not a fruit's ``error``), and
    ends the worker process it runs in for those its ``die`` names (both go to the workers with the task)."""

    def __call__(self, k, sl):
        if k in self.die and fp._IN_WORKER:
            os.kill(os.getpid(), signal.SIGKILL)
        if k in self.fail:
            raise (Unpicklable if self.fail[k] == "unpicklable" else ValueError)(self.fail[k])
        return super().__call__(k, sl)


class Unpicklable(Exception):
    def __init__(self, text):
        super().__init__(text)
        self.hook = lambda: text  # no pickle of it


def fruit_task(frame, cls=Failing, fail=None, die=()):
    """The per-fruit task and jobs ``detect`` makes for ``frame`` (its masks as given), of class ``cls``."""
    from symfruit.detect import _default_settings, _label_boxes

    labels = frame.masks.astype(np.int32)
    task = cls(labels, frame.depth, frame.color, frame.camera, _default_settings(), "raw", (0, 0), True, labels > 0,
               set())  # fmt: skip
    task.fail, task.die = fail or {}, set(die)
    return task, [(k, sl) for k, sl in enumerate(_label_boxes(labels, int(labels.max())), 1) if sl is not None]


def four():
    yy, xx = np.mgrid[:120, :160]
    labels = np.zeros((120, 160), np.int32)
    for k, (u, v) in enumerate([(30, 30), (90, 30), (30, 90), (120, 90)], 1):
        labels[(xx - u) ** 2 + (yy - v) ** 2 <= 12**2] = k
    return small([(30, 30), (90, 30), (30, 90), (120, 90)], labels)


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_the_first_failing_fruits_error_is_raised_as_one_process_raises_it(pool, monkeypatch, shares):
    monkeypatch.setattr(pool, "_caller_shares", shares)
    task, jobs = fruit_task(four(), fail={2: "fruit 2 failed", 4: "fruit 4 failed"})
    with pytest.raises(ValueError, match="fruit 2 failed"):
        [task(k, sl) for k, sl in jobs]
    starts = pool.starts
    with pytest.raises(ValueError, match="fruit 2 failed") as raised:
        pool.run(task, jobs)
    if not shares:  # raised there, told here with where it came from
        assert "in FruitPool worker" in "".join(getattr(raised.value, "__notes__", []))
    task.fail = {}
    assert pool.starts == starts, pool.last_loss  # no worker lost
    done, _ = pool.run(task, jobs)  # the pool goes on
    assert [d[0].id for d in done] == [1, 2, 3, 4]


def test_an_exception_that_does_not_pickle_comes_back_as_its_type_and_text(workers_only):
    task, jobs = fruit_task(four(), fail={3: "unpicklable"})
    starts = workers_only.starts
    with pytest.raises(RuntimeError, match=r"^Unpicklable: unpicklable$"):
        workers_only.run(task, jobs)
    assert workers_only.starts == starts, workers_only.last_loss


def test_a_worker_killed_between_frames_gives_the_next_frame_right_and_a_new_worker(pool):
    frame = bench(0)
    one = detect(frame)
    starts, (old,) = pool.starts, pool._state.workers
    old.process.kill()
    old.process.join(60)
    assert not old.process.is_alive()
    assert_same(one, detect(frame, pool=pool))  # in this process while the new worker warms up
    assert pool.starts == starts + 1 and pool.active
    assert pool._wait_ready(fp.START_TIMEOUT)
    (new,) = pool._state.workers
    assert new.process.pid != old.process.pid and new.process.is_alive()
    pool._caller_shares = False
    try:
        before = pool.fruit_elsewhere
        assert_same(one, detect(frame, pool=pool))
        assert pool.fruit_elsewhere == before + 9  # the new worker did them
    finally:
        pool._caller_shares = True


def test_a_worker_dying_within_a_frame_leaves_its_fruit_to_this_process(workers_only):
    pool = workers_only
    task, jobs = fruit_task(four(), die={3})
    alone = [task(k, sl) for k, sl in jobs]
    starts, segment = pool.starts, pool._state.segment
    done, _ = pool.run(task, jobs)
    assert [d[0].id for d in done] == [1, 2, 3, 4] and pool.starts == starts + 1
    for a, b in zip(alone, done, strict=True):
        assert record(a[0]) == record(b[0])
    assert pool._state.segment is segment and os.path.exists(f"/dev/shm/{segment.name}")
    task.die = set()
    assert pool._wait_ready(fp.START_TIMEOUT)
    assert [d[0].id for d in pool.run(task, jobs)[0]] == [1, 2, 3, 4]


class FruitWarning(UserWarning):
    pass


class Warns(_Fruit):
    """A fruit task that warns (``FruitWarning``, the same text and place each time) for the fruit its ``warn``
    names, and divides by zero in numpy (a ``RuntimeWarning`` where numpy's error handling says warn) for those its
    ``divide`` names, before its work; then raises for those its ``fail`` names."""

    warn: frozenset = frozenset()
    divide: frozenset = frozenset()

    def __call__(self, k, sl):
        if k in self.warn:
            warnings.warn("a fruit warns", FruitWarning, stacklevel=1)
        if k in self.divide:
            np.float64(1.0) / np.float64(0.0)
        if k in self.fail:
            raise ValueError(self.fail[k])
        return super().__call__(k, sl)


def given(run, action: str = "always") -> list:
    """What ``run()`` warned under the filter ``action``: (category, text, file, line) each, in order."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter(action)
        run()
    return [(w.category, str(w.message), w.filename, w.lineno) for w in caught]


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_a_workers_warnings_are_given_in_this_process_through_its_filters(pool, monkeypatch, shares):
    """Stop 53 left it: a warning in a worker was shown there (on its stderr), past the caller's filters. Now each
    is recorded there and given again here, in the frame's order: the same (category, text, file, line) as one
    process gives; shown once (``default``) where one process shows it once."""
    monkeypatch.setattr(pool, "_caller_shares", shares)
    task, jobs = fruit_task(four(), Warns)
    task.warn, task.divide = {2, 3}, {4}
    alone = given(lambda: [task(k, sl) for k, sl in jobs])
    elsewhere = pool.fruit_elsewhere
    pooled = given(lambda: pool.run(task, jobs))
    assert [(c, t) for c, t, *_ in alone] == [(FruitWarning, "a fruit warns")] * 2 + [
        (RuntimeWarning, "divide by zero encountered in scalar divide")]  # fmt: skip
    if shares:  # the ones this process did came as it did them
        assert sorted(pooled, key=str) == sorted(alone, key=str)
    else:
        assert pooled == alone and pool.fruit_elsewhere == elsewhere + 4
        assert given(lambda: pool.run(task, jobs), "default") == given(lambda: [task(k, sl) for k, sl in jobs],
                                                                       "default") == alone[1:]  # fmt: skip
        assert given(lambda: pool.run(task, jobs), "ignore") == []


def test_a_workers_warning_a_filter_makes_an_error_is_raised_as_one_process_raises_it(workers_only):
    pool = workers_only
    task, jobs = fruit_task(four(), Warns)
    task.warn, task.divide = {3}, {2}
    for error in (FruitWarning, RuntimeWarning):
        expected = "a fruit warns" if error is FruitWarning else "divide by zero"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            warnings.simplefilter("error", error)
            with pytest.raises(error, match=expected):
                [task(k, sl) for k, sl in jobs]
            starts = pool.starts
            with pytest.raises(error, match=expected):
                pool.run(task, jobs)
        assert pool.starts == starts, pool.last_loss  # no worker lost
    task.fail, task.divide = {3: "fruit 3 failed"}, set()  # after its warning: the warning made an error is raised
    with warnings.catch_warnings():
        warnings.simplefilter("error", FruitWarning)
        with pytest.raises(FruitWarning, match="a fruit warns"):
            [task(k, sl) for k, sl in jobs]
        with pytest.raises(FruitWarning, match="a fruit warns"):
            pool.run(task, jobs)
    task.fail, task.divide = {}, {2}
    with np.errstate(divide="raise"), pytest.raises(FloatingPointError, match="divide by zero"):
        given(lambda: pool.run(task, jobs))  # numpy's error handling of the caller, in the workers too
    with np.errstate(divide="ignore"):
        assert [c for c, *_ in given(lambda: pool.run(task, jobs))] == [FruitWarning]


class WarnsLocally(_Fruit):
    """A fruit task whose warning's category is a class made inside the call: no other process can import it."""

    def __call__(self, k, sl):
        class Local(UserWarning):
            pass

        warnings.warn("made here", Local, stacklevel=1)
        return super().__call__(k, sl)


def test_a_workers_warning_of_a_category_made_in_a_function_comes_as_a_user_warning_naming_it(workers_only):
    task, jobs = fruit_task(four(), WarnsLocally)
    assert [(c, t) for c, t, *_ in given(lambda: workers_only.run(task, jobs))] == [
        (UserWarning, "Local: made here")
    ] * 4


class Interrupted(_Fruit):
    def __call__(self, k, sl):
        if not fp._IN_WORKER:
            raise KeyboardInterrupt
        return super().__call__(k, sl)


def ours() -> set[str]:
    """This process's shared segments in /dev/shm (another test's process, a DDS one say, makes and removes its
    own meanwhile)."""
    return {n for n in os.listdir("/dev/shm") if n.startswith(f"{fp.SEGMENT_PREFIX}{os.getpid()}_")}


def test_an_interrupted_frame_ends_the_workers_and_close_leaves_no_segment():
    before = ours()  # a module-wide pool's
    with FruitPool(1, method=None) as pool:
        task, jobs = fruit_task(four(), Interrupted)
        first = pool._state.workers[0].process
        with pytest.raises(KeyboardInterrupt):
            pool.run(task, jobs)
        assert not first.is_alive() and pool.starts == 2  # ended, and new ones started
        segment = pool._state.segment.name
        assert os.path.exists(f"/dev/shm/{segment}")
        processes = [w.process for w in pool._state.workers]
    assert not os.path.exists(f"/dev/shm/{segment}") and not any(p.is_alive() for p in processes)
    assert pool.reason == "the pool is closed" and not pool.active
    pool.close()  # twice: harmless
    assert ours() - before == set()


def test_a_killed_workers_pool_closes_without_a_segment_left():
    with FruitPool(1, method=None) as pool:
        detect(four(), method="raw", pool=pool)
        segment = pool._state.segment.name
        pool._state.workers[0].process.kill()
    assert not os.path.exists(f"/dev/shm/{segment}")


@pytest.mark.parametrize("bad", [-1, MAX_FRUIT_PROCESSES + 1, True, 1.0, "1", None])
def test_the_number_of_processes_is_bounded(bad):
    with pytest.raises(InputError, match=f"processes must be a whole number from 0 to {MAX_FRUIT_PROCESSES}"):
        check_fruit_processes(bad)
    with pytest.raises(InputError, match="must be a whole number"):
        FruitPool(bad)
    assert check_fruit_processes(np.int64(2)) == 2


def test_fork_is_refused_and_zero_workers_is_one_process():
    with pytest.raises(InputError, match="never fork"):
        FruitPool(1, start_method="fork")
    with pytest.raises(SymfruitError, match="no-such-method"):
        FruitPool(1, method="no-such-method")  # before any worker starts
    with FruitPool(0) as none:
        assert not none.active and none.reason == "no worker process asked for (0)" and none.starts == 0
        frame = four()
        assert_same(detect(frame, method="raw"), detect(frame, method="raw", pool=none))
    with pytest.raises(InputError, match="pool must be a FruitPool"):
        detect(frame, pool=1)


def test_one_process_with_one_core_or_in_a_dask_worker(monkeypatch):
    monkeypatch.setattr(fp, "usable_cores", lambda: 1)
    assert one_process_reason(1).startswith("this process may use 1 core")
    with FruitPool(1) as pool:
        assert not pool.active and pool.starts == 0
    monkeypatch.undo()
    fake = types.SimpleNamespace(get_worker=lambda: object())
    monkeypatch.setitem(sys.modules, "distributed", fake)
    assert one_process_reason(1) == "this process is a Dask worker: it is one of several already"


def test_no_workers_in_a_daemonic_process():
    with multiprocessing.get_context("spawn").Pool(1) as daemonic:
        why = daemonic.apply(one_process_reason, (1,))
    assert why.startswith("this process was started by multiprocessing")


def test_a_shared_frame_runs_this_processs_blas_on_one_thread_and_lifts_it_after():
    """Two-thread BLAS on both sides of two cores made the pool slower than none with `paper` (stop 53's lead
    A/B: 66-68 against 45-48 ms): while a frame is shared, this process's BLAS runs on one thread (the workers
    limit their own at start), and the limit is lifted after the frame."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads() -> list[int]:
        return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]

    with threadpoolctl.threadpool_limits(2, user_api="blas"):
        before = blas_threads()
        assert before and max(before) == 2
        pool = FruitPool(0)  # no workers: the limit is the same code either way
        try:
            with pool._one_blas_thread():
                assert set(blas_threads()) == {1}
            assert blas_threads() == before
        finally:
            pool.close()
