"""Where the sliders of a triangular lattice slip
==============================================

Runs the triangular lattice of ``examples/lattice.toml`` (20 x 20 sliders,
free boundaries, 4 realizations of 200 tau_th) and draws where its sliders
slipped.

Writes ``result.nc``, ``slip_map.png`` (slips per node, log scale) and
``mu_s_field.png`` (thresholds at the end) for realization 0::

    python examples/lattice_pictures.py --out out/lattice

Only the boundary feels the dilation directly (section 2 of :doc:`/model`), so
the boundary nodes slip most and the count falls towards the centre.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import slidernet
from slidernet.analysis.plots import save_network_pictures
from slidernet.config import load_config
from slidernet.io import write_netcdf

try:
    CONFIG = Path(__file__).with_name("lattice.toml")
except NameError:  # sphinx-gallery defines no __file__; it runs the script from examples/
    CONFIG = Path("lattice.toml").resolve()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("out/lattice"),
                        help="output folder (default out/lattice)")
    parser.add_argument("--config", type=Path, default=CONFIG, help=f"network config (default {CONFIG.name})")
    args = parser.parse_args(argv)

    start = time.perf_counter()
    ds = slidernet.run(load_config(args.config))
    print(f"ran {args.config} in {time.perf_counter() - start:.1f} s "
          f"({int(ds['n'].isel(t=-1).sum())} slips in {ds.sizes['realization']} realizations)")
    print(write_netcdf(ds, args.out / "result.nc"))
    for path in save_network_pictures(ds, args.out).values():
        print(path)
    return 0


# %%
# Running the example
# -------------------
#
# The command line: ``main`` parses the options above. The documentation's
# gallery runs this script with a temporary ``--out`` folder
# (``docs/_ext/slidernet_gallery.py``) and shows the PNG files it writes.

if __name__ == "__main__":
    status = main()
    if status:  # sphinx-gallery runs the script inside Sphinx: exit only on failure
        raise SystemExit(status)
