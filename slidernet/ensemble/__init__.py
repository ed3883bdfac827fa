"""Ensembles: ``slidernet.run``, where realizations run (processes, Dask), sweeps, the streamed result file."""
