"""Synthetic data: fruit shapes (:mod:`.shapes`), a depth renderer with sensor models (:mod:`.render`),
models of real RGB-D cameras (:mod:`.sensors`: Azure Kinect, L515, D435, D405), whole RGB-D scenes
(:mod:`.scenes`) and the benchmark's fixed views (:mod:`.views`), for the evaluation, the benchmark, the
demo frame and the tests."""
