"""Synthetic data: fruit shapes (:mod:`.shapes`), a depth renderer with sensor models (:mod:`.render`),
models of real RGB-D cameras (:mod:`.sensors`: Azure Kinect, L515, D435, D405) and whole RGB-D scenes
(:mod:`.scenes`), for the evaluation, the benchmark, the demo frame and the tests."""
