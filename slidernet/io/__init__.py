"""Files: atomic writes, result files (netCDF), JSON summaries, the checkpoint folder of a run, checkpoints.

``slidernet.io`` itself holds the plain file helpers and the two writers of a
result file, which share one encoding (:mod:`slidernet.io.netcdf`);
:mod:`slidernet.io.store` and :mod:`slidernet.io.checkpoint` are imported
where they are used.
"""

from slidernet.io.netcdf import (
    atomic_output,
    read_result,
    result_config,
    result_writer,
    save_figure,
    write_netcdf,
)
from slidernet.io.summary import write_json

__all__ = ["atomic_output", "read_result", "result_config", "result_writer", "save_figure", "write_json",
           "write_netcdf"]
