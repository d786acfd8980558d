"""Synthetic data: fruit shapes (:mod:`.shapes`), a depth renderer with sensor models (:mod:`.render`) and
whole RGB-D scenes (:mod:`.scenes`), for the evaluation, the benchmark, the demo frame and the tests."""
