"""Limit-cycle studies of nonlinear hinges: setup and sweeps (:mod:`.study`), their run on Dask
(:mod:`.run`), the result (:mod:`.result`) and its figures (:mod:`.plots`)."""
