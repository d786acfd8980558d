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
from symfruit.detect import DetectStream, _Fruit, _Masks, _shared_masks, _trim_labels, detect, frame_masks
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


def shifted():
    """Three fruit whose masks are 3 px too large (colour trimming takes it off) on depth registered 6 px right of
    and 4 px below the colour (the masks move by (6, 4))."""
    centres = [(40, 40), (110, 45), (75, 90)]
    color, depth = disc_frame(centres, radius=18)
    moved = np.full_like(depth, 1.0)
    moved[4:, 6:] = depth[:-4, :-6]  # what colour pixel (u, v) sees lies at depth pixel (u + 6, v + 4)
    yy, xx = np.mgrid[:120, :160]
    masks = np.zeros((120, 160), np.int32)
    for k, (u, v) in enumerate(centres, 1):
        masks[(xx - u) ** 2 + (yy - v) ** 2 <= 21**2] = k
    return Frame("shifted", color, moved, SMALL_CAM, masks=masks)


def frames():
    """Generated frames: the benchmark's (9 fruit, more than the workers), three fruit whose masks are trimmed and
    moved (:func:`shifted`), one with a fruit too small to complete
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
        ("trimmed and moved", shifted(), "raw"),
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
        before, masks_before = pool.fruit_elsewhere, pool.masks_elsewhere
        errors, counts, masks, moves = 0, [], [], []
        for _, frame, method in frames():
            one, two = detect(frame, method=method), detect(frame, method=method, pool=pool)
            assert_same(one, two)
            errors += sum(bool(d.error) for d in two.detections)
            counts.append(len(two.detections))
            masks.append(len(np.unique(frame_masks(frame)[0])) - 1)
            moves.append(two.registration)
        assert errors >= 2 and counts[:2] == [9, 3] and counts[-2:] == [1, 0]  # as frames() says
        assert moves[1] == (6, 4)  # the masks trimmed by colour (assert_same: the same masks) and moved
        if not shares:  # every fruit and every mask of every frame of two fruit or more
            assert pool.fruit_elsewhere - before == sum(n for n in counts if n >= 2)
            assert pool.masks_elsewhere - masks_before == sum(n for n in masks if n >= 2)
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
    pool.run(*fruit_task(four()))  # the segment made (when this test runs first)
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


# --- stop 54 (pool54): each mask's colour trimming and registration outline on the workers too


def mask_task(frame, cls=_Masks):
    """The per-mask task and jobs ``detect`` makes for ``frame`` (its masks as given), of class ``cls``."""
    from symfruit.detect import _default_settings, _label_boxes

    labels = frame.masks.astype(np.int32)
    s = _default_settings().extract
    task = cls(labels, frame.depth, frame.color, s, float(np.sqrt(frame.camera.fx * frame.camera.fy)))
    return task, [(k, sl) for k, sl in enumerate(_label_boxes(labels, int(labels.max())), 1) if sl is not None]


class FailingMasks(_Masks):
    """A mask task whose trimming raises for the masks ``fail`` names (``ValueError("trim k")``), whose outline
    raises for those ``fail_outline`` names (``"outline k"``), and that ends the worker process it runs in for
    those ``die`` names (class attributes: ``detect`` makes the task; a worker imports its class from here)."""

    fail: tuple[int, ...] = ()
    fail_outline: tuple[int, ...] = ()
    die: tuple[int, ...] = ()

    def _trim(self, k, sl):
        if k in self.die and fp._IN_WORKER:
            os.kill(os.getpid(), signal.SIGKILL)
        if k in self.fail:
            raise ValueError(f"trim {k}")
        return super()._trim(k, sl)

    def _outline(self, k, box, dropped):
        if k in self.fail_outline:
            raise ValueError(f"outline {k}")
        return super()._outline(k, box, dropped)


class TrimFails(FailingMasks):
    fail, fail_outline = (3, 4), (1,)


class OutlineFails(FailingMasks):
    fail_outline = (4, 2)


class DiesOnMask3(FailingMasks):
    die = (3,)


class InterruptedMasks(_Masks):
    def _trim(self, k, sl):
        if not fp._IN_WORKER:
            raise KeyboardInterrupt
        return super()._trim(k, sl)


def four_shifted():
    """four() with its masks 2 px larger than its fruit and its depth 6 px right of the colour."""
    frame = four()
    moved = np.full_like(frame.depth, 1.0)
    moved[:, 6:] = frame.depth[:, :-6]
    yy, xx = np.mgrid[:120, :160]
    labels = np.zeros((120, 160), np.int32)
    for k, (u, v) in enumerate([(30, 30), (90, 30), (30, 90), (120, 90)], 1):
        labels[(xx - u) ** 2 + (yy - v) ** 2 <= 17**2] = k
    return Frame("four shifted", frame.color, moved, SMALL_CAM, masks=labels)


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_the_masks_trimming_and_registration_with_the_pool_are_one_processs(pool, monkeypatch, shares):
    """The trimmed labels, the colour-trimmed masks, their boxes, and the shift searched from the outlines, from each
    mask's part done on the workers (or shared), are what trim_labels and register give in one process."""
    from symfruit.core.surface import registration_search
    from symfruit.detect import _box_within, _default_settings, _label_boxes
    from symfruit.extract import register
    from symfruit.settings import Settings

    monkeypatch.setattr(pool, "_caller_shares", shares)
    no_search = Settings().replace(extract={"registration_px": 0}).extract
    no_trim = Settings().replace(extract={"colour_trim_px": 0}).extract
    usual = _default_settings().extract
    cases = [
        (shifted(), usual),
        (four_shifted(), usual),
        (bench(0), usual),
        (shifted(), no_search),
        (shifted(), no_trim),
    ]
    for frame, s in cases:
        labels = frame_masks(frame)[0]
        boxes = _label_boxes(labels, int(labels.max()))
        # by the colour alone, as detect trims before the registration (the fruit's cap keeps its pixels after it)
        trimmed, colour_trimmed = _trim_labels(frame.color, labels, s, boxes)
        new_boxes = [_box_within(trimmed, k, sl) if k in colour_trimmed else sl for k, sl in enumerate(boxes, 1)]
        _, shift = register(trimmed, frame.depth, frame.camera, s, boxes=new_boxes)
        before = pool.masks_elsewhere
        got = _shared_masks(pool, frame, labels, boxes, s, object())
        assert np.array_equal(got[0], trimmed) and got[1] == colour_trimmed and got[2] == new_boxes
        assert registration_search(got[3], max_px=s.registration_px) == shift
        if not shares:
            assert pool.masks_elsewhere - before == sum(sl is not None for sl in boxes)
        if frame.name != "bench":  # each part at work where the settings ask for it
            assert bool(colour_trimmed) == (s.colour_trim_px > 0) and (shift != (0, 0)) == (s.registration_px > 0)


def shared_masks(pool, frame):
    from symfruit.detect import _default_settings, _label_boxes

    labels = frame.masks.astype(np.int32)
    return _shared_masks(pool, frame, labels, _label_boxes(labels, int(labels.max())), _default_settings().extract,
                         object())  # fmt: skip


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_the_first_failing_masks_error_is_raised_its_trimmings_before_any_outlines(pool, monkeypatch, shares):
    """As trim_labels runs before register in one process: a mask's trimming error before any mask's outline
    error, each the first failing mask's in the frame's order; the pool goes on."""
    monkeypatch.setattr(pool, "_caller_shares", shares)
    frame = four_shifted()
    starts = pool.starts
    for cls, first in ((TrimFails, "trim 3"), (OutlineFails, "outline 2")):
        monkeypatch.setattr("symfruit.detect._Masks", cls)
        with pytest.raises(ValueError, match=rf"^{first}\b") as raised:
            detect(frame, method="raw", pool=pool)
        if not shares and first.startswith("trim"):  # raised there, told here with where it came from
            assert "in FruitPool worker" in "".join(getattr(raised.value, "__notes__", []))
    assert pool.starts == starts, pool.last_loss  # no worker lost
    monkeypatch.undo()
    assert_same(detect(frame, method="raw"), detect(frame, method="raw", pool=pool))


def test_a_worker_dying_on_a_mask_leaves_its_masks_to_this_process(workers_only, monkeypatch):
    pool = workers_only
    frame = four_shifted()
    one = detect(frame, method="raw")
    starts = pool.starts
    monkeypatch.setattr("symfruit.detect._Masks", DiesOnMask3)
    assert_same(one, detect(frame, method="raw", pool=pool))  # the masks the worker left done here, the fruit too
    assert pool.starts == starts + 1 and pool.active and "within a frame" in pool.last_loss
    monkeypatch.undo()
    assert pool._wait_ready(fp.START_TIMEOUT)
    before = pool.masks_elsewhere
    assert_same(one, detect(frame, method="raw", pool=pool))
    assert pool.masks_elsewhere == before + 4  # the new worker did them


def test_an_interrupt_among_the_masks_ends_the_workers_and_close_leaves_no_segment(monkeypatch):
    before = ours()
    with FruitPool(1, method=None) as pool:
        first = pool._state.workers[0].process
        monkeypatch.setattr("symfruit.detect._Masks", InterruptedMasks)
        with pytest.raises(KeyboardInterrupt):
            detect(four_shifted(), method="raw", pool=pool)
        assert not first.is_alive() and pool.starts == 2  # ended, and new ones started
        processes = [w.process for w in pool._state.workers]
    assert not any(p.is_alive() for p in processes)
    assert ours() - before == set()


def test_an_array_shared_again_for_the_same_frame_is_not_copied_again(pool):
    """detect shares the frame's depth and colour once for its two tasks (the same ``same``); the same array for
    another frame, or a new array, is copied."""
    a, b = np.arange(1000.0), np.ones(500, np.int32)
    frame, other = object(), object()
    _, _, layout = pool._share({"a": a, "b": b}, frame)
    view = np.ndarray(layout["a"][2], layout["a"][1], buffer=pool._state.segment.buf, offset=layout["a"][0])
    view[:] = -1.0  # what a copy would overwrite
    pool._share({"a": a, "b": b.copy()}, frame)
    assert (view == -1.0).all()
    pool._share({"a": a, "b": b}, other)
    assert np.array_equal(view, a)
    view[:] = -1.0
    pool._share({"a": a}, None)
    assert np.array_equal(view, a)


def test_the_fruit_go_with_the_last_shift_while_the_search_runs_and_again_when_it_was_wrong(workers_only):
    """detect sends the fruit moved by the pool's guess (the last shift found) while it searches for the frame's:
    right, the workers' fruit are the frame's; wrong, they are dropped and the fruit sent again with the shift
    found. The detections are the same either way."""
    pool = workers_only
    frame = shifted()  # its masks move by (6, 4)
    one = detect(frame, method="raw")
    for guess in [(0, 0), (6, 4), (-2, 0)]:
        pool.registration_guess = guess
        before, starts = pool.fruit_elsewhere, pool.starts
        assert_same(one, detect(frame, method="raw", pool=pool))
        assert pool.registration_guess == (6, 4) and pool.starts == starts, pool.last_loss
        assert pool.fruit_elsewhere == before + 3  # the right run's alone: a wrong one's are not counted


def test_a_guessed_run_called_off_drops_the_workers_fruit_and_a_failing_check_ends_them(pool, monkeypatch):
    task, jobs = fruit_task(four())
    alone = [task(k, sl) for k, sl in jobs]
    for shares in (True, False):
        monkeypatch.setattr(pool, "_caller_shares", shares)
        calls, before, starts = [], pool.fruit_elsewhere, pool.starts
        assert pool.run_guessed(task, jobs, None, lambda calls=calls: calls.append(1) or False) is None
        assert calls == [1] and pool.fruit_elsewhere == before and pool.starts == starts, pool.last_loss
        done, _ = pool.run_guessed(task, jobs, None, lambda calls=calls: calls.append(2) or True)
        assert calls == [1, 2] and [record(d[0]) for d in done] == [record(d[0]) for d in alone]

    def failing():
        raise ValueError("the search failed")

    starts = pool.starts
    with pytest.raises(ValueError, match="the search failed"):
        pool.run_guessed(task, jobs, None, failing)
    assert pool.starts == starts + 1 and pool.active  # the workers ended (they may be mid-frame), new ones started
    assert pool._wait_ready(fp.START_TIMEOUT)
    assert [d[0].id for d in pool.run(task, jobs)[0]] == [1, 2, 3, 4]


def test_a_worker_dying_in_a_run_called_off_is_replaced(workers_only):
    pool = workers_only
    task, jobs = fruit_task(four(), die={1, 2, 3, 4})
    starts, (worker,) = pool.starts, pool._state.workers

    def after_it_died():  # the worker takes a fruit (it has the task) and dies on it; then the run is called off
        worker.process.join(fp.STALL_TIMEOUT)
        return False

    assert pool.run_guessed(task, jobs, None, after_it_died) is None
    assert pool.starts == starts + 1 and pool.active and "ended within a frame" in pool.last_loss
    task.die = set()
    assert pool._wait_ready(fp.START_TIMEOUT)
    before = pool.fruit_elsewhere
    assert [d[0].id for d in pool.run(task, jobs)[0]] == [1, 2, 3, 4] and pool.fruit_elsewhere == before + 4


# --- stop 55: frames in a stream (FruitPool.start, detect.DetectStream; docs/pipe55.md) ---------------------------


def streamed(stream, frames):
    """Each of ``frames`` through ``stream`` as a recording goes (the next prepared, the last finished, the next
    started): the detections in the frames' order."""
    out = []
    for frame in frames:
        ready = stream.prepare(frame)
        out.append(stream.finish())
        stream.start(ready)
    out.append(stream.finish())
    assert out[0] is None and not stream.in_flight
    return out[1:]


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_a_stream_gives_each_frames_detections_as_detect(pool, monkeypatch, shares):
    """The frames of frames() twice, in one stream: each frame's detections are detect's without a pool, bit for
    bit, whichever process did which fruit."""
    monkeypatch.setattr(pool, "_caller_shares", shares)
    for method in ("raw", "evidence"):
        given_frames = [frame for _, frame, _ in frames()] * 2
        before, starts = pool.fruit_elsewhere, pool.starts
        got = streamed(DetectStream(pool, method=method), given_frames)
        for frame, found in zip(given_frames, got, strict=True):
            assert_same(detect(frame, method=method), found)
        assert pool.starts == starts, pool.last_loss
        if not shares:  # the workers did every fruit of every frame of two fruit or more
            assert pool.fruit_elsewhere - before == sum(len(f.detections) for f in got if len(f.detections) >= 2)


class FailsOnSmall(Warns):
    """A fruit task that warns for fruit 1 and raises for fruit 2 of a 160x120 frame (four()), not of others."""

    def __call__(self, k, sl):
        small_frame = self.depth.shape == (120, 160)
        self.warn, self.fail = ({1} if small_frame else set()), ({2: "fruit 2 failed"} if small_frame else {})
        return super().__call__(k, sl)


@pytest.mark.parametrize("shares", [True, False], ids=["shared", "workers only"])
def test_a_streamed_frames_errors_and_warnings_come_with_it(pool, monkeypatch, shares):
    """A frame's fruit's error is raised when it is finished (after the next frame was prepared), its workers'
    warnings given then; a frame refused when prepared raises there and leaves the frame in flight as it was."""
    monkeypatch.setattr(pool, "_caller_shares", shares)
    monkeypatch.setattr("symfruit.detect._Fruit", FailsOnSmall)
    whole = small([(40, 60)], np.ones((120, 160), np.int32))  # one mask over the whole image: refused
    stream = DetectStream(pool, method="raw")
    stream.start(stream.prepare(bench(0)))
    ready = stream.prepare(four())
    first = stream.finish()
    with warnings.catch_warnings(record=True) as started:
        warnings.simplefilter("always")
        stream.start(ready)
    with pytest.raises(InputError, match="covers the whole image"):
        stream.prepare(whole)
    assert stream.in_flight  # four() still
    with warnings.catch_warnings(record=True) as finished:
        warnings.simplefilter("always")
        with pytest.raises(ValueError, match="fruit 2 failed"):
            stream.finish()
    # fruit 1's warning, once: given when the frame is finished if a worker did it, at once if this process did
    assert [str(w.message) for w in started + finished] == ["a fruit warns"]
    assert shares or not started
    assert not stream.in_flight
    last = streamed(stream, [bench(1)])
    monkeypatch.undo()
    assert_same(detect(bench(0), method="raw"), first)
    assert_same(detect(bench(1), method="raw"), last[0])


def test_a_frame_in_flight_dropped_ends_the_workers_and_the_next_is_right():
    before = ours()
    with FruitPool(1, method=None) as pool:
        stream = DetectStream(pool, method="raw")
        stream.start(stream.prepare(four()))
        first = pool._state.workers[0].process
        stream.abandon()
        stream.abandon()  # twice: harmless
        assert not stream.in_flight and not first.is_alive() and pool.starts == 2
        assert pool.last_loss == "a frame was dropped before its workers' fruit came"
        assert pool._wait_ready(fp.START_TIMEOUT)
        assert_same(detect(four(), method="raw"), streamed(stream, [four()])[0])
        processes = [w.process for w in pool._state.workers]
    assert not any(p.is_alive() for p in processes) and ours() - before == set()


class DiesOnSmall(_Fruit):
    """A fruit task whose worker dies on fruit 3 of a 160x120 frame (four())."""

    def __call__(self, k, sl):
        if k == 3 and self.depth.shape == (120, 160) and fp._IN_WORKER:
            os.kill(os.getpid(), signal.SIGKILL)
        return super().__call__(k, sl)


def test_a_worker_dying_with_a_frame_in_flight_leaves_its_fruit_to_this_process(workers_only, monkeypatch):
    pool = workers_only
    one = [detect(frame, method="raw") for frame in (four(), bench(0))]
    monkeypatch.setattr("symfruit.detect._Fruit", DiesOnSmall)
    starts = pool.starts
    got = streamed(DetectStream(pool, method="raw"), [four(), bench(0)])
    assert pool.starts == starts + 1 and "ended within a frame" in pool.last_loss
    for a, b in zip(one, got, strict=True):
        assert_same(a, b)


def test_a_run_while_a_frame_is_in_flight_runs_in_this_process_alone(pool):
    """The frame in flight keeps the pool busy: another frame meanwhile (another thread's, or this one's by
    mistake) runs here alone and is right; the one in flight is right too."""
    task, jobs = fruit_task(four())
    alone = [record(d[0]) for d in (task(k, sl) for k, sl in jobs)]
    assert pool._wait_ready(fp.START_TIMEOUT)  # warm (after another test's lost worker): the pool shares
    running = pool.start(task, jobs)
    assert running.pending
    before = pool.fruit_elsewhere
    assert [record(d[0]) for d in pool.run(task, jobs)[0]] == alone and pool.fruit_elsewhere == before
    done, _ = running.result()
    assert [record(d[0]) for d in done] == alone and not running.pending
    assert running.result() is None  # had once: nothing more


class Counted(_Fruit):
    """A fruit task that notes, in the calling process, the fruit done there."""

    def __call__(self, k, sl):
        if not fp._IN_WORKER:
            self.here.append(k)
        return super().__call__(k, sl)


def test_the_calling_process_leaves_the_workers_the_fruit_left_when_told_it_has_other_work(pool):
    """``leave``: the calling process stops taking fruit once those left would keep the workers about that long
    (here, after its first: more seconds than any fruit takes); the rest are done when the result is asked for (by
    the workers, or here if they left some). The answers are the same."""
    task, jobs = fruit_task(four(), Counted)
    task.here = []
    alone = [record(d[0]) for d in (task(k, sl) for k, sl in jobs)]
    assert pool._wait_ready(fp.START_TIMEOUT)
    for leave in (1e9, None):
        task.here = []
        running = pool.start(task, jobs, leave=leave)
        took = list(task.here)
        done, _ = running.result()
        assert [record(d[0]) for d in done] == alone
        if leave:
            assert len(took) <= 1  # its first fruit (none if the worker took them all first)


@pytest.mark.parametrize("leave", ["1", -1.0, float("nan"), True, [1.0]])
def test_a_start_told_to_leave_what_is_no_seconds_is_refused_before_the_task_is_sent(pool, leave):
    """Stop 56 (robust56): FruitPool.start(..., leave="1") sent the task, took a fruit, then failed comparing
    seconds with text (a TypeError, the workers ended and new ones started); -1 and NaN were taken in silence as
    "take every fruit". Now refused by name before anything is sent; the pool is not busy after it."""
    task, jobs = fruit_task(four())
    with pytest.raises(InputError, match=r"^FruitPool\.start: leave must be None or seconds >= 0, got "):
        pool.start(task, jobs, leave=leave)
    running = pool.start(task, jobs, leave=0.0)  # the pool goes on
    assert len(running.result()[0]) == len(jobs)
