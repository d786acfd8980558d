"""Regenerate the embedded sample: a partial strawberry view and the camera it was "seen" with.

    python examples/make_sample.py

Writes ``strawberry_partial.ply`` (the visible points, metres, camera optical frame),
``strawberry_truth.json`` (the box of the whole berry) and ``camera.json`` (Intel D435 colour,
640x480) next to this file, and the demo frame (an RGB-D frame of hanging strawberries with
``truth.json``) into the package data, ``src/symfruit/data/example_frame``, where ``symfruit demo``
finds it however symfruit was installed. Seeded: the same files every time.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from symfruit import DEFAULT_CAMERA, Box
from symfruit.demo import FRAME_SEED
from symfruit.io import write_json, write_ply
from symfruit.io.frames import write_frame
from symfruit.synthetic.scenes import make_scene
from symfruit.synthetic.shapes import paper_visible, rotation_x, strawberry

HERE = Path(__file__).parent
FRAME = HERE.parent / "src" / "symfruit" / "data" / "example_frame"


def main() -> None:
    rng = np.random.default_rng(2024)
    fruit = strawberry(rng, shape="conic", length=0.038)
    dense = fruit.sample(3000, rng) @ rotation_x(-15.0).T + [0.012, -0.008, 0.32]
    visible = dense[paper_visible(dense)]
    visible = visible[np.sort(rng.choice(len(visible), size=600, replace=False))]
    visible = visible + rng.normal(scale=0.0003, size=visible.shape)  # 0.3 mm sensor noise
    write_ply(HERE / "strawberry_partial.ply", visible)
    truth = Box.from_points(fruit.vertices @ rotation_x(-15.0).T + [0.012, -0.008, 0.32])
    write_json(HERE / "strawberry_truth.json", {"centre": truth.centre.tolist(), **truth.to_dict()})
    write_json(HERE / "camera.json", DEFAULT_CAMERA.to_dict())
    # The example RGB-D frame: six ripe strawberries (two touching, some behind leaves), two unripe.
    scene = make_scene(FRAME_SEED)
    write_frame(FRAME, scene.color, scene.depth, scene.camera, truth=scene.truth())


if __name__ == "__main__":
    main()
