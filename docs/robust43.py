"""Stop 43: adversarial arrays at the library API (``symfruit.complete``, ``Camera``, ``Frame`` + ``detect``,
``segment``, ``occlusion``, ``extract``, ``FrameProcessor``).

Each case runs in this process under a 300 s alarm (the first run compiles the numba kernels, a minute or more)
and is classified:

- ``error``: a :class:`symfruit.SymfruitError` (its message is printed, cut to 150 characters);
- ``result``: it returned (a summary is printed); a case that expects an error and gets a result is a defect
  (``wrong silent result``);
- ``DEFECT``: any other exception (the library and the line it was raised from are printed), or a hang.

Run it under both kernel settings::

    PYTHONPATH=src python docs/robust43.py
    SYMFRUIT_KERNELS=numpy PYTHONPATH=src python docs/robust43.py

``--only SUBSTRING`` runs the cases whose name holds it.
"""

from __future__ import annotations

import argparse
import signal
import sys
import traceback
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

import numpy as np

import symfruit
from symfruit.core.frame import Frame
from symfruit.core.occlusion import occlusion
from symfruit.detect import detect
from symfruit.extract import extract
from symfruit.segment.colour import segment

CAM = symfruit.Camera(fx=615.0, fy=615.0, cx=320.0, cy=240.0, width=640, height=480)


def fruit(n: int = 600, r: float = 0.015, z: float = 0.3, seed: int = 0) -> np.ndarray:
    """The camera-facing half of a sphere: a fruit's visible points."""
    d = np.random.default_rng(seed).normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return r * d[d[:, 2] < 0] + [0.0, 0.0, z]


def example() -> tuple[np.ndarray, np.ndarray, symfruit.Camera]:
    from symfruit.ros.bench import example_images

    rgb, raw, cam = example_images()
    return rgb, raw.astype(np.float32) * np.float32(0.001), cam


def labels_of() -> np.ndarray:
    """The example frame's own instance labels (the colour segmenter's)."""
    return segment(RGB, DEPTH, ECAM)


P = fruit()


class Hang(Exception):
    pass


def _alarm(signum: int, frame: Any) -> None:
    raise Hang


CASES: list[tuple[str, str, Callable[[], Any]]] = []  # name, expected ("error", "result", "any"), call


def case(name: str, expect: str = "any") -> Callable[[Callable[[], Any]], Callable[[], Any]]:
    def add(fn: Callable[[], Any]) -> Callable[[], Any]:
        CASES.append((name, expect, fn))
        return fn

    return add


def add(name: str, expect: str, fn: Callable[[], Any]) -> None:
    CASES.append((name, expect, fn))


# --- complete: points ------------------------------------------------------------------------------------------
def _with(rows: np.ndarray, values: Any) -> np.ndarray:
    q = P.copy()
    q[: len(rows)] = values
    return q


for method in ("evidence", "paper", "sphere", "superellipsoid"):
    m = method
    add(f"complete/{m}/good", "result", lambda m=m: symfruit.complete(P, method=m))
    add(f"complete/{m}/nan-rows", "result", lambda m=m: symfruit.complete(_with(P[:20], np.nan), method=m))
    add(f"complete/{m}/inf-rows", "result", lambda m=m: symfruit.complete(_with(P[:20], np.inf), method=m))
    add(f"complete/{m}/-inf-z", "result", lambda m=m: symfruit.complete(_with(P[:5], [0, 0, -np.inf]), method=m))
    add(f"complete/{m}/all-nan", "error", lambda m=m: symfruit.complete(np.full((100, 3), np.nan), method=m))
    add(f"complete/{m}/float16", "any", lambda m=m: symfruit.complete(P.astype(np.float16), method=m))
    add(f"complete/{m}/float32", "result", lambda m=m: symfruit.complete(P.astype(np.float32), method=m))
    add(f"complete/{m}/longdouble", "any", lambda m=m: symfruit.complete(P.astype(np.longdouble), method=m))
    add(f"complete/{m}/int-mm", "error", lambda m=m: symfruit.complete((P * 1000).astype(np.int32), method=m))
    add(f"complete/{m}/int64-m", "error", lambda m=m: symfruit.complete(P.astype(np.int64), method=m))
    add(f"complete/{m}/uint8", "error", lambda m=m: symfruit.complete(np.ones((50, 3), np.uint8), method=m))
    add(f"complete/{m}/bool", "error", lambda m=m: symfruit.complete(P > 0, method=m))
    add(f"complete/{m}/object", "any", lambda m=m: symfruit.complete(P.astype(object), method=m))
    add(f"complete/{m}/object-str", "error", lambda m=m: symfruit.complete(np.full((50, 3), "a", object), method=m))
    add(f"complete/{m}/complex", "error", lambda m=m: symfruit.complete(P.astype(complex), method=m))
    add(f"complete/{m}/strings", "error", lambda m=m: symfruit.complete(P.astype(str), method=m))
    add(f"complete/{m}/bytes", "error", lambda m=m: symfruit.complete(P.astype("S8"), method=m))
    add(f"complete/{m}/datetime", "error", lambda m=m: symfruit.complete(np.zeros((50, 3), "M8[s]"), method=m))
    add(f"complete/{m}/structured", "error",
        lambda m=m: symfruit.complete(np.zeros(50, [("x", "f8"), ("y", "f8"), ("z", "f8")]), method=m))  # fmt: skip
    add(f"complete/{m}/masked", "any", lambda m=m: symfruit.complete(np.ma.masked_invalid(P), method=m))
    add(f"complete/{m}/noncontig", "result",
        lambda m=m: symfruit.complete(np.repeat(P, 2, axis=1)[:, ::2], method=m))  # fmt: skip
    add(f"complete/{m}/rows-strided", "result", lambda m=m: symfruit.complete(np.repeat(P, 2, 0)[::2], method=m))
    add(f"complete/{m}/fortran", "result", lambda m=m: symfruit.complete(np.asfortranarray(P), method=m))

    def _ro(m: str = m) -> Any:
        q = P.copy()
        q.flags.writeable = False
        return symfruit.complete(q, method=m)

    add(f"complete/{m}/readonly", "result", _ro)
    add(f"complete/{m}/bigendian", "result", lambda m=m: symfruit.complete(P.astype(">f8"), method=m))
    add(f"complete/{m}/list", "result", lambda m=m: symfruit.complete(P.tolist(), method=m))
    add(f"complete/{m}/zero-size", "error", lambda m=m: symfruit.complete(np.zeros((0, 3)), method=m))
    add(f"complete/{m}/empty-list", "error", lambda m=m: symfruit.complete([], method=m))
    add(f"complete/{m}/one-point", "error", lambda m=m: symfruit.complete(P[:1], method=m))
    add(f"complete/{m}/1d", "error", lambda m=m: symfruit.complete(P[0], method=m))
    add(f"complete/{m}/scalar", "error", lambda m=m: symfruit.complete(0.3, method=m))
    add(f"complete/{m}/none", "error", lambda m=m: symfruit.complete(None, method=m))
    add(f"complete/{m}/n-by-2", "error", lambda m=m: symfruit.complete(P[:, :2], method=m))
    add(f"complete/{m}/n-by-4", "any", lambda m=m: symfruit.complete(np.c_[P, P[:, :1]], method=m))
    add(f"complete/{m}/3x-n", "error", lambda m=m: symfruit.complete(P.T, method=m))
    add(f"complete/{m}/3d", "error", lambda m=m: symfruit.complete(P[None], method=m))
    add(f"complete/{m}/ragged", "error", lambda m=m: symfruit.complete([[0, 0, 0.3], [0, 0.3]], method=m))
    add(f"complete/{m}/identical", "error", lambda m=m: symfruit.complete(np.tile([0.0, 0, 0.3], (100, 1)), method=m))
    add(f"complete/{m}/collinear", "error",
        lambda m=m: symfruit.complete(np.c_[np.linspace(-0.02, 0.02, 100), np.zeros(100), np.full(100, 0.3)],
                                      method=m))  # fmt: skip

    def _coplanar(m: str = m, tilt: float = 0.0) -> Any:
        g = np.random.default_rng(1).uniform(-0.02, 0.02, (300, 2))
        return symfruit.complete(np.c_[g, 0.3 + tilt * g[:, 0]], method=m)

    add(f"complete/{m}/coplanar", "error", _coplanar)
    add(f"complete/{m}/coplanar-tilted", "error", lambda m=m: _coplanar(m, 0.5))
    add(f"complete/{m}/near-coplanar", "any", lambda m=m: symfruit.complete(P * [1, 1, 1e-3] + [0, 0, 0.3], method=m))
    add(f"complete/{m}/mm", "error", lambda m=m: symfruit.complete(P * 1000, method=m))
    add(f"complete/{m}/huge-1e6", "error", lambda m=m: symfruit.complete(P + [0, 0, 1e6], method=m))
    add(f"complete/{m}/huge-xy-1e6", "error", lambda m=m: symfruit.complete(P + [1e6, 1e6, 0], method=m))
    add(f"complete/{m}/1e300", "error", lambda m=m: symfruit.complete(P * 1e300, method=m))
    add(f"complete/{m}/tiny", "error", lambda m=m: symfruit.complete(P * 1e-6, method=m))
    add(f"complete/{m}/behind", "error", lambda m=m: symfruit.complete(P * [1, 1, -1], method=m))
    add(f"complete/{m}/out-of-view", "any", lambda m=m: symfruit.complete(P + [2.0, 0, 0], method=m))
    add(f"complete/{m}/huge-n", "result", lambda m=m: symfruit.complete(fruit(2_000_000), method=m))
    add(f"complete/{m}/denormals", "error", lambda m=m: symfruit.complete(P * 1e-310, method=m))

add("complete/settings-max-points-4", "error",
    lambda: symfruit.complete(P, settings={"input": {"max_points": 4, "min_points": 4}}))  # fmt: skip
add(
    "complete/camera-dict-width0",
    "error",
    lambda: symfruit.complete(P, camera={"fx": 615, "fy": 615, "cx": 320, "cy": 240, "width": 0, "height": 480}),
)
add(
    "complete/camera-dict-nan",
    "error",
    lambda: symfruit.complete(P, camera={"fx": np.nan, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}),
)
add("complete/camera-tiny-image", "error", lambda: symfruit.complete(P, camera=cam(width=1, height=1, cx=0, cy=0)))
add("complete/method-unknown", "error", lambda: symfruit.complete(P, method="nope"))
add("complete/method-int", "error", lambda: symfruit.complete(P, method=3))  # type: ignore[arg-type]
add("complete/settings-bad", "error", lambda: symfruit.complete(P, settings={"input": {"min_points": -1}}))
add("complete/settings-str", "error", lambda: symfruit.complete(P, settings="x.yaml"))  # type: ignore[arg-type]
add("complete/camera-str", "error", lambda: symfruit.complete(P, camera="d435"))  # type: ignore[arg-type]
add(
    "complete/camera-dict-fx0",
    "error",
    lambda: symfruit.complete(P, camera={"fx": 0, "fy": 615, "cx": 320, "cy": 240, "width": 640, "height": 480}),
)
add("complete/camera-dict-empty", "error", lambda: symfruit.complete(P, camera={}))
add("complete/occlusion-array", "error", lambda: symfruit.complete(P, occlusion=np.zeros((480, 640))))  # type: ignore


# --- Camera ----------------------------------------------------------------------------------------------------
def cam(**kw: Any) -> symfruit.Camera:
    base = {"fx": 615.0, "fy": 615.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480}
    base.update(kw)
    return symfruit.Camera(**base)


for key, value in [("fx", 0.0), ("fx", -615.0), ("fx", np.nan), ("fy", np.inf), ("cx", np.nan), ("cy", -np.inf),
                   ("width", 0), ("height", -1), ("width", 640.5), ("width", np.nan), ("width", 10**12),
                   ("width", True), ("fx", "615"), ("fx", None), ("fx", np.array([615.0, 1.0])), ("fx", 0.615),
                   ("fx", complex(615, 0)), ("cx", 1e12), ("fx", 10**400)]:  # fmt: skip
    add(f"camera/{key}={value!r:.20}", "error", lambda key=key, value=value: cam(**{key: value}))
for key, value in [("fx", np.float32(615)), ("width", np.int16(640)), ("width", 640.0), ("fx", np.array(615.0)),
                   ("cx", -5.0), ("width", np.uint64(640))]:  # fmt: skip
    add(f"camera/{key}={value!r:.20}", "result", lambda key=key, value=value: cam(**{key: value}))
add("camera/project-n2", "error", lambda: CAM.project(np.zeros((4, 2))))
add("camera/deproject-mismatch", "error", lambda: CAM.deproject(np.zeros((4, 2)), np.ones(3)))
add("camera/deproject-nan", "any", lambda: CAM.deproject(np.full((4, 2), np.nan), np.ones(4)))
add("camera/rays-str", "error", lambda: CAM.rays("a", "b"))  # type: ignore[arg-type]
add("camera/shifted-nan", "error", lambda: CAM.shifted(np.nan, 0))


# --- Frame and detect ------------------------------------------------------------------------------------------
def frame(color: Any = None, depth: Any = None, camera: Any = None, **kw: Any) -> Frame:
    return Frame("adv", RGB if color is None else color, DEPTH if depth is None else depth,
                 ECAM if camera is None else camera, **kw)  # fmt: skip


def det(masks: Any = None, **kw: Any) -> Any:
    found = detect(frame(**kw), masks=LABELS if masks is None else masks)
    return found


def _depth_with(value: float, share: slice = slice(0, 240)) -> np.ndarray:
    d = DEPTH.copy()
    d[share] = value
    return d


add("detect/good", "result", lambda: det())
add("detect/masks-auto", "result", lambda: detect(frame()))
add("detect/depth-nan-half", "result", lambda: det(depth=_depth_with(np.nan)))
add("detect/depth-inf-half", "result", lambda: det(depth=_depth_with(np.inf)))
add("detect/depth-neg-half", "any", lambda: det(depth=_depth_with(-1.0)))
add("detect/depth-all-nan", "error", lambda: det(depth=np.full_like(DEPTH, np.nan)))
add("detect/depth-all-zero", "error", lambda: det(depth=np.zeros_like(DEPTH)))
add("detect/depth-mm-float", "error", lambda: det(depth=DEPTH * 1000))
add("detect/depth-mm-uint16", "error", lambda: det(depth=(DEPTH * 1000).astype(np.uint16)))
add("detect/depth-float16", "any", lambda: det(depth=DEPTH.astype(np.float16)))
add("detect/depth-float64", "result", lambda: det(depth=DEPTH.astype(np.float64)))
add("detect/depth-int32", "any", lambda: det(depth=DEPTH.astype(np.int32)))
add("detect/depth-bool", "error", lambda: det(depth=DEPTH > 0))
add("detect/depth-object", "any", lambda: det(depth=DEPTH.astype(object)))
add("detect/depth-complex", "error", lambda: det(depth=DEPTH.astype(complex)))
add("detect/depth-str", "error", lambda: det(depth=DEPTH.astype(str)))
add("detect/depth-fortran", "result", lambda: det(depth=np.asfortranarray(DEPTH)))
add("detect/depth-noncontig", "result", lambda: det(depth=np.repeat(DEPTH, 2, axis=1)[:, ::2]))
add("detect/depth-bigendian", "result", lambda: det(depth=DEPTH.astype(">f4")))


def _ro_frame() -> Any:
    c, d, m = RGB.copy(), DEPTH.copy(), LABELS.copy()
    for a in (c, d, m):
        a.flags.writeable = False
    return detect(frame(color=c, depth=d), masks=m)


add("detect/all-readonly", "result", _ro_frame)
add("detect/depth-3d", "error", lambda: det(depth=DEPTH[..., None]))
add("detect/depth-hw-swapped", "error", lambda: det(depth=DEPTH.T))
add("detect/depth-smaller", "error", lambda: det(depth=DEPTH[:240]))
add("detect/depth-1e6", "error", lambda: det(depth=DEPTH + 1e6))
add("detect/color-float", "error", lambda: det(color=RGB / 255.0))
add("detect/color-gray", "error", lambda: det(color=RGB[..., 0]))
add("detect/color-rgba", "error", lambda: det(color=np.dstack([RGB, RGB[..., :1]])))
add("detect/color-bgr-view", "result", lambda: det(color=RGB[..., ::-1]))
add("detect/color-fortran", "result", lambda: det(color=np.asfortranarray(RGB)))
add("detect/color-uint16", "error", lambda: det(color=RGB.astype(np.uint16)))
add("detect/color-bool", "error", lambda: det(color=RGB > 0))
add("detect/color-object", "error", lambda: det(color=RGB.astype(object)))
add("detect/color-smaller", "error", lambda: det(color=RGB[:240]))
add("detect/zero-size", "error", lambda: Frame("z", np.zeros((0, 0, 3), np.uint8), np.zeros((0, 0), np.float32), ECAM))
add("detect/camera-mapping", "error", lambda: det(camera=ECAM.to_dict()))
add("detect/camera-other-size", "error", lambda: det(camera=cam(width=320, height=240)))
add("detect/masks-float-whole", "any", lambda: det(masks=LABELS.astype(float)))
add("detect/masks-float-frac", "error", lambda: det(masks=LABELS + 0.5))
add("detect/masks-float-nan", "error", lambda: det(masks=np.where(LABELS > 0, np.nan, 0.0)))
add("detect/masks-negative", "error", lambda: det(masks=-LABELS))
add("detect/masks-above-2^31", "error", lambda: det(masks=LABELS.astype(np.int64) * 2**32))
add("detect/masks-2^31-1", "result", lambda: det(masks=np.where(LABELS == 1, 2**31 - 1, LABELS)))
add("detect/masks-uint64-huge", "error", lambda: det(masks=LABELS.astype(np.uint64) + np.uint64(2**63)))
add("detect/masks-bool", "any", lambda: det(masks=LABELS > 0))
add("detect/masks-int8", "result", lambda: det(masks=LABELS.astype(np.int8)))
add("detect/masks-uint16", "result", lambda: det(masks=LABELS.astype(np.uint16)))
add("detect/masks-object", "any", lambda: det(masks=LABELS.astype(object)))
add("detect/masks-str", "error", lambda: det(masks=LABELS.astype(str)))
add("detect/masks-complex", "error", lambda: det(masks=LABELS.astype(complex)))
add("detect/masks-fortran", "result", lambda: det(masks=np.asfortranarray(LABELS)))
add("detect/masks-noncontig", "result", lambda: det(masks=np.repeat(LABELS, 2, axis=1)[:, ::2]))
add("detect/masks-bigendian", "result", lambda: det(masks=LABELS.astype(">i4")))
add("detect/masks-zero", "result", lambda: det(masks=np.zeros_like(LABELS)))
add("detect/masks-whole", "error", lambda: det(masks=np.ones_like(LABELS)))
add("detect/masks-whole-but-one", "any", lambda: det(masks=np.where(np.arange(H * W).reshape(H, W) == 0, 0, 1)))


def _one_px(value: float | None = None) -> Any:
    m = np.zeros_like(LABELS)
    ys, xs = np.nonzero(LABELS == 1)
    m[ys[len(ys) // 2], xs[len(xs) // 2]] = 1
    return det(masks=m)


add("detect/masks-one-pixel", "result", _one_px)
add("detect/masks-whole-float", "error", lambda: det(masks=np.ones(LABELS.shape)))
add("detect/masks-uint64", "result", lambda: det(masks=LABELS.astype(np.uint64)))
add("detect/masks-sparse-ids", "result", lambda: det(masks=LABELS.astype(np.int64) * 100_000_000))
add("detect/masks-int-2^31", "error", lambda: det(masks=np.where(LABELS == 1, 2**31, LABELS)))
add("detect/masks-float-2^40", "error", lambda: det(masks=np.where(LABELS == 1, 2.0**40, LABELS)))
add("detect/masks-float-inf", "error", lambda: det(masks=np.where(LABELS == 1, np.inf, LABELS)))
add("detect/masks-1d", "error", lambda: det(masks=LABELS.ravel()))
add("detect/masks-list", "error", lambda: det(masks=LABELS.tolist()))
add("detect/masks-smaller", "error", lambda: det(masks=LABELS[:240]))
add("detect/masks-callable-bad", "error", lambda: det(masks=lambda f, s: "nope"))
add("detect/masks-callable-none", "error", lambda: det(masks=lambda f, s: None))
add("detect/masks-callable-float", "error", lambda: det(masks=lambda f, s: LABELS + 0.5))
add("detect/masks-callable-raises", "theirs", lambda: det(masks=lambda f, s: 1 / 0))
add("detect/masks-many", "error", lambda: det(masks=np.arange(H * W).reshape(H, W) + 1))
add("detect/method-bad", "error", lambda: detect(frame(), masks=LABELS, method="nope"))
add("detect/frame-mapping", "error", lambda: detect({"color": RGB}))  # type: ignore[arg-type]
add("detect/name-int", "error", lambda: Frame(5, RGB, DEPTH, ECAM))  # type: ignore[arg-type]


# --- segment ---------------------------------------------------------------------------------------------------
add("segment/good", "result", lambda: segment(RGB, DEPTH, ECAM))
add("segment/colour-only", "result", lambda: segment(RGB))
add("segment/depth-no-camera", "error", lambda: segment(RGB, DEPTH))
add("segment/depth-mismatch", "error", lambda: segment(RGB, DEPTH[:240], ECAM))
add("segment/depth-mm", "error", lambda: segment(RGB, DEPTH * 1000, ECAM))
add("segment/depth-uint16", "error", lambda: segment(RGB, (DEPTH * 1000).astype(np.uint16), ECAM))
add("segment/depth-nan", "result", lambda: segment(RGB, _depth_with(np.nan), ECAM))
add("segment/depth-all-nan", "result", lambda: segment(RGB, np.full_like(DEPTH, np.nan), ECAM))
add("segment/depth-inf", "result", lambda: segment(RGB, _depth_with(np.inf), ECAM))
add("segment/depth-neg", "any", lambda: segment(RGB, _depth_with(-1.0), ECAM))
add("segment/depth-float16", "any", lambda: segment(RGB, DEPTH.astype(np.float16), ECAM))
add("segment/depth-object", "any", lambda: segment(RGB, DEPTH.astype(object), ECAM))
add("segment/depth-bool", "error", lambda: segment(RGB, DEPTH > 0, ECAM))
add("segment/depth-fortran", "result", lambda: segment(RGB, np.asfortranarray(DEPTH), ECAM))
add("segment/depth-bigendian", "result", lambda: segment(RGB, DEPTH.astype(">f4"), ECAM))
add("segment/color-float", "error", lambda: segment(RGB / 255.0))
add("segment/color-float-0-255", "any", lambda: segment(RGB.astype(np.float32)))
add("segment/color-int64", "any", lambda: segment(RGB.astype(np.int64)))
add("segment/color-uint16", "any", lambda: segment(RGB.astype(np.uint16)))
add("segment/color-bool", "error", lambda: segment(RGB > 0))
add("segment/color-object", "error", lambda: segment(RGB.astype(object)))
add("segment/color-gray", "error", lambda: segment(RGB[..., 0]))
add("segment/color-rgba", "any", lambda: segment(np.dstack([RGB, RGB[..., :1]])))
add("segment/color-zero", "error", lambda: segment(np.zeros((0, 0, 3), np.uint8)))
add("segment/color-1px", "result", lambda: segment(np.full((1, 1, 3), [200, 20, 20], np.uint8)))
add("segment/color-1row", "result", lambda: segment(np.full((1, 640, 3), [200, 20, 20], np.uint8)))
add("segment/color-all-red", "result", lambda: segment(np.full((480, 640, 3), [200, 20, 20], np.uint8)))
add("segment/color-huge", "error", lambda: segment(np.broadcast_to(np.uint8(0), (100_000, 100_000, 3))))
add("segment/color-bgr-view", "result", lambda: segment(RGB[..., ::-1]))
add("segment/color-fortran", "result", lambda: segment(np.asfortranarray(RGB)))
add("segment/color-noncontig", "result", lambda: segment(np.repeat(RGB, 2, axis=1)[:, ::2]))
add("segment/color-readonly", "result", lambda: segment(np.broadcast_to(RGB, RGB.shape)))
add("segment/color-list", "any", lambda: segment(RGB[:8, :8].tolist()))
add("segment/camera-fx0", "error", lambda: segment(RGB, DEPTH, SimpleNamespace(fx=0.0, fy=615.0)))
add("segment/camera-nan", "error", lambda: segment(RGB, DEPTH, SimpleNamespace(fx=np.nan, fy=np.nan)))
add("segment/camera-no-fx", "error", lambda: segment(RGB, DEPTH, SimpleNamespace(f=615.0)))
add("segment/camera-str", "error", lambda: segment(RGB, DEPTH, SimpleNamespace(fx="615", fy="615")))
add("segment/settings-dict", "error", lambda: segment(RGB, settings={"min_area_share": 0.1}))  # type: ignore


# --- occlusion and extract -------------------------------------------------------------------------------------
add("occlusion/good", "result", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM))
add("occlusion/mask-int", "any", lambda: occlusion(DEPTH, MASK1.astype(int), PTS1, ECAM))
add("occlusion/mask-labels", "any", lambda: occlusion(DEPTH, LABELS, PTS1, ECAM))
add("occlusion/mask-float", "any", lambda: occlusion(DEPTH, MASK1.astype(float), PTS1, ECAM))
add("occlusion/mask-smaller", "error", lambda: occlusion(DEPTH, MASK1[:240], PTS1, ECAM))
add("occlusion/mask-empty", "any", lambda: occlusion(DEPTH, np.zeros_like(MASK1), PTS1, ECAM))
add("occlusion/mask-whole", "any", lambda: occlusion(DEPTH, np.ones_like(MASK1), PTS1, ECAM))
add("occlusion/depth-mm", "error", lambda: occlusion(DEPTH * 1000, MASK1, PTS1, ECAM))
add("occlusion/depth-nan", "result", lambda: occlusion(_depth_with(np.nan), MASK1, PTS1, ECAM))
add("occlusion/depth-float64", "result", lambda: occlusion(DEPTH.astype(float), MASK1, PTS1, ECAM))
add("occlusion/depth-float16", "any", lambda: occlusion(DEPTH.astype(np.float16), MASK1, PTS1, ECAM))
add("occlusion/depth-fortran", "result", lambda: occlusion(np.asfortranarray(DEPTH), MASK1, PTS1, ECAM))
add("occlusion/depth-bigendian", "result", lambda: occlusion(DEPTH.astype(">f4"), MASK1, PTS1, ECAM))
add("occlusion/points-empty", "error", lambda: occlusion(DEPTH, MASK1, np.zeros((0, 3)), ECAM))
add("occlusion/points-nan", "any", lambda: occlusion(DEPTH, MASK1, np.full((10, 3), np.nan), ECAM))
add("occlusion/points-float32", "result", lambda: occlusion(DEPTH, MASK1, PTS1.astype(np.float32), ECAM))
add("occlusion/points-fortran", "result", lambda: occlusion(DEPTH, MASK1, np.asfortranarray(PTS1), ECAM))
add("occlusion/points-int", "any", lambda: occlusion(DEPTH, MASK1, (PTS1 * 1000).astype(int), ECAM))
add("occlusion/points-n2", "error", lambda: occlusion(DEPTH, MASK1, PTS1[:, :2], ECAM))
add("occlusion/points-behind", "any", lambda: occlusion(DEPTH, MASK1, PTS1 * [1, 1, -1], ECAM))
add("occlusion/others-smaller", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, others=MASK1[:240]))
add("occlusion/others-labels", "any", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, others=LABELS))
add("occlusion/others-float", "any", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, others=LABELS.astype(float)))
add("occlusion/others-object", "any", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, others=LABELS.astype(object)))
add("occlusion/mask-bigendian", "any", lambda: occlusion(DEPTH, LABELS.astype(">i4") == 1, PTS1, ECAM))
add("occlusion/points-bigendian", "result", lambda: occlusion(DEPTH, MASK1, PTS1.astype(">f8"), ECAM))
add("occlusion/tolerance-str", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, tolerance="0.005"))  # type: ignore
add("occlusion/pad-float", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, pad=16.0))  # type: ignore
add("occlusion/reach-numpy-int", "result", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, reach=np.int64(3)))
add("occlusion/camera-other", "error", lambda: occlusion(DEPTH, MASK1, PTS1, cam(width=320, height=240)))
add("occlusion/camera-dict", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM.to_dict()))  # type: ignore
add("occlusion/tolerance-nan", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, tolerance=np.nan))
add("occlusion/reach-neg", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, reach=-1))
add("occlusion/reach-huge", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, reach=10**9))
add("occlusion/pad-huge", "any", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, pad=10**9))
add("occlusion/band-float", "error", lambda: occlusion(DEPTH, MASK1, PTS1, ECAM, band=2.5))  # type: ignore
add("extract/good", "result", lambda: extract(MASK1, DEPTH, ECAM))
add("extract/mask-labels", "any", lambda: extract(LABELS, DEPTH, ECAM))
add("extract/mask-float", "any", lambda: extract(MASK1.astype(float), DEPTH, ECAM))
add("extract/mask-smaller", "error", lambda: extract(MASK1[:240], DEPTH, ECAM))
add("extract/mask-one-pixel", "result", lambda: extract(np.eye(1, H * W, 200 * W + 300, bool).reshape(H, W), DEPTH,
                                                        ECAM))  # fmt: skip
add("extract/mask-whole", "any", lambda: extract(np.ones_like(MASK1), DEPTH, ECAM))
add("extract/mask-empty", "any", lambda: extract(np.zeros_like(MASK1), DEPTH, ECAM))
add("extract/depth-mm", "error", lambda: extract(MASK1, DEPTH * 1000, ECAM))
add("extract/depth-uint16", "error", lambda: extract(MASK1, (DEPTH * 1000).astype(np.uint16), ECAM))
add("extract/depth-nan", "result", lambda: extract(MASK1, np.full_like(DEPTH, np.nan), ECAM))
add("extract/depth-float16", "any", lambda: extract(MASK1, DEPTH.astype(np.float16), ECAM))
add("extract/depth-object", "any", lambda: extract(MASK1, DEPTH.astype(object), ECAM))
add("extract/depth-bigendian", "result", lambda: extract(MASK1, DEPTH.astype(">f4"), ECAM))
add("extract/depth-fortran", "result", lambda: extract(MASK1, np.asfortranarray(DEPTH), ECAM))
add("extract/camera-other", "error", lambda: extract(MASK1, DEPTH, cam(width=320, height=240)))


# --- FrameProcessor --------------------------------------------------------------------------------------------
def _hdr() -> SimpleNamespace:
    return SimpleNamespace(stamp=SimpleNamespace(secs=7, nsecs=5), frame_id="cam")


def _img(a: np.ndarray, encoding: str) -> SimpleNamespace:
    a = np.ascontiguousarray(a)
    h, w = a.shape[:2]
    rows = a.reshape(h, -1).view(np.uint8)
    return SimpleNamespace(height=h, width=w, encoding=encoding, is_bigendian=0, step=rows.shape[1],
                           data=rows.tobytes(), header=_hdr())  # fmt: skip


def _info(fx: float | None = None, width: int | None = None, height: int | None = None,
          cx: float | None = None) -> SimpleNamespace:  # fmt: skip
    fx, cx = ECAM.fx if fx is None else fx, ECAM.cx if cx is None else cx
    width, height = W if width is None else width, H if height is None else height
    return SimpleNamespace(width=width, height=height, header=_hdr(),
                           K=[fx, 0.0, cx, 0.0, ECAM.fy, ECAM.cy, 0.0, 0.0, 1.0])  # fmt: skip


_PROC: list[Any] = []


def proc() -> Any:
    if not _PROC:
        from symfruit.ros.core import FrameProcessor

        _PROC.append(FrameProcessor(masks="color"))
    return _PROC[0]


add("proc/good", "result", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info()))
add("proc/depth-32FC1", "result",
    lambda: proc().process(_img(RGB, "rgb8"), _img(DEPTH, "32FC1"), _info()))  # fmt: skip
add("proc/depth-32FC1-mm", "error",
    lambda: proc().process(_img(RGB, "rgb8"), _img(DEPTH * 1000, "32FC1"), _info()))  # fmt: skip
add("proc/depth-32FC1-nan", "result",
    lambda: proc().process(_img(RGB, "rgb8"), _img(_depth_with(np.nan), "32FC1"), _info()))  # fmt: skip
add("proc/fx0", "error", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(fx=0.0)))
add("proc/fx-neg", "error", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(fx=-615.0)))
add("proc/fx-nan", "error", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(fx=np.nan)))
add("proc/cx-inf", "error", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(cx=np.inf)))
add("proc/width0", "result", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(width=0)))
add("proc/width-other", "error",
    lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(width=320, height=240)))  # fmt: skip
add("proc/info-width-huge", "error",
    lambda: proc().process(_img(RGB, "rgb8"), _img(RAW, "16UC1"), _info(width=10**12, height=10**12)))  # fmt: skip
add("proc/depth-16UC1-in-metres", "error",
    lambda: proc().process(_img(RGB, "rgb8"), _img((DEPTH).astype(np.uint16), "16UC1"), _info()))  # fmt: skip
add("proc/depth-smaller", "error", lambda: proc().process(_img(RGB, "rgb8"), _img(RAW[:240], "16UC1"), _info()))
add("proc/color-mono8", "any", lambda: proc().process(_img(RGB[..., 0], "mono8"), _img(RAW, "16UC1"), _info()))
add("proc/depth-scale-nan", "error", lambda: __import__("symfruit.ros.core").ros.core.FrameProcessor(
    depth_scale=float("nan")))  # fmt: skip
add("proc/depth-scale-0", "error", lambda: __import__("symfruit.ros.core").ros.core.FrameProcessor(depth_scale=0))
add("proc/method-bad", "error", lambda: __import__("symfruit.ros.core").ros.core.FrameProcessor(method="x"))
add("proc/overrides-bad", "error", lambda: __import__("symfruit.ros.core").ros.core.FrameProcessor(
    overrides={"input": {"min_points": "ten"}}))  # fmt: skip


def summary(value: Any) -> str:
    if isinstance(value, symfruit.Result):
        return f"box size {np.round(value.box.size * 1000, 1).tolist()} mm, centre {np.round(value.centre, 4).tolist()}"
    if hasattr(value, "detections"):
        ok = sum(d.result is not None for d in value.detections)
        return f"{len(value.detections)} detections, {ok} completed"
    if hasattr(value, "fruits"):
        return f"{len(value.fruits)} fruit"
    if isinstance(value, np.ndarray):
        return f"{value.dtype} {value.shape}, max {value.max() if value.size else '-'}"
    if hasattr(value, "points"):
        return f"{len(value.points)} points"
    return type(value).__name__


def origin(exc: BaseException) -> str:
    frames = traceback.extract_tb(exc.__traceback__)
    last = frames[-1] if frames else None
    where = f"{last.filename.split('site-packages/')[-1]}:{last.lineno}" if last else "?"
    return f"{type(exc).__module__}.{type(exc).__name__} at {where}: {str(exc)[:120]!r}"


def load() -> None:
    """The example frame, its labels and one fruit's points and mask, which the cases read (made after the command
    line is read: ``--help`` does no work)."""
    global RGB, DEPTH, ECAM, H, W, LABELS, MASK1, PTS1, RAW
    RGB, DEPTH, ECAM = example()
    H, W = DEPTH.shape
    LABELS = labels_of()
    MASK1 = LABELS == 1
    PTS1 = extract(MASK1, DEPTH, ECAM).points
    RAW = (DEPTH * 1000).astype(np.uint16)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="")
    parser.add_argument("--defects", action="store_true", help="print the defects alone")
    args = parser.parse_args()
    load()
    signal.signal(signal.SIGALRM, _alarm)
    counts = {"error": 0, "result": 0, "DEFECT": 0}
    for name, expect, fn in CASES:
        if args.only not in name:
            continue
        signal.alarm(300)
        try:
            value = fn()
            signal.alarm(0)
            if expect == "error":
                kind, text = "DEFECT", f"wrong silent result: {summary(value)}"
            else:
                kind, text = "result", summary(value)
        except symfruit.SymfruitError as exc:
            signal.alarm(0)
            msg = str(exc)
            if expect == "result":
                kind, text = "DEFECT", f"refused what it should take: {msg[:150]}"
            elif len(msg) > 300:
                kind, text = "DEFECT", f"message of {len(msg)} characters: {msg[:150]}"
            else:
                kind, text = "error", msg[:150]
        except Hang:
            kind, text = "DEFECT", "hang (over 300 s)"
        except Exception as exc:  # the point of the sweep
            signal.alarm(0)
            if expect == "theirs" and traceback.extract_tb(exc.__traceback__)[-1].filename == __file__:
                kind, text = "result", f"the caller's own {type(exc).__name__} passed on"
            else:
                kind, text = "DEFECT", origin(exc)
        counts[kind] += 1
        if kind == "DEFECT" or not args.defects:
            sys.stdout.write(f"{kind:6} {name:42} {text}\n")
            sys.stdout.flush()
    sys.stdout.write(f"# {sum(counts.values())} cases: {counts['error']} clear errors, {counts['result']} results, "
                     f"{counts['DEFECT']} defects\n")  # fmt: skip
    return 1 if counts["DEFECT"] else 0


if __name__ == "__main__":
    sys.exit(main())
