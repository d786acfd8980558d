"""A season of recordings: ``detect`` on a Dask cluster (:mod:`.cluster`), the fruit tables every run writes
(:mod:`.table`: ``detections.parquet``, ``frames.parquet``) and the report made from them (:mod:`.report`)."""
