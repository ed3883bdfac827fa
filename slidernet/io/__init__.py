"""Files: atomic writes, result files (netCDF), the checkpoint folder of a run, checkpoints of a realization.

``slidernet.io`` itself holds the plain file helpers (:mod:`slidernet.io.netcdf`);
:mod:`slidernet.io.store` and :mod:`slidernet.io.checkpoint` are imported
where they are used.
"""

from slidernet.io.netcdf import atomic_output, read_result, result_config, save_figure, write_netcdf

__all__ = ["atomic_output", "read_result", "result_config", "save_figure", "write_netcdf"]
