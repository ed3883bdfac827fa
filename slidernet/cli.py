"""Command-line interface: a thin layer over the library.

``slidernet run CONFIG.toml --out DIR``   writes DIR/result.nc
``slidernet paper [--quick] --out DIR``   reproduces the paper's four figures
``slidernet plugins``                     lists the registered plugins
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from slidernet.errors import SlidernetError


def _parser() -> argparse.ArgumentParser:
    import slidernet

    p = argparse.ArgumentParser(
        prog="slidernet",
        description="Frictional sliders joined by springs, driven by thermal dilation.",
    )
    p.add_argument("--version", action="version", version=f"slidernet {slidernet.__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run a configuration and write DIR/result.nc")
    r.add_argument("config", type=Path, help="TOML configuration (see MODEL.md section 5)")
    r.add_argument("--out", type=Path, required=True, help="output directory")
    r.add_argument("--no-progress", action="store_true", help="hide the progress bar")

    pp = sub.add_parser("paper", help="reproduce the four figures of Geminard & Bertin (2010)")
    pp.add_argument("--out", type=Path, required=True, help="output directory")
    pp.add_argument("--quick", action="store_true", help="small preset (under 2 minutes)")

    sub.add_parser("plugins", help="list the registered distributions and drivers")
    return p


def _cmd_run(args: argparse.Namespace) -> int:
    from slidernet.config import load_config
    from slidernet.io import write_netcdf
    from slidernet.runner import run

    cfg = load_config(args.config)  # validate before any work or any file
    ds = run(cfg, progress=not args.no_progress)
    path = write_netcdf(ds, args.out / "result.nc")
    print(f"wrote {path} (seed {ds.attrs['seed']}, kernel {ds.attrs['kernel']})")
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    from slidernet.paper import reproduce

    files = reproduce(args.out, quick=args.quick, progress=True)
    for name, path in files.items():
        print(f"{name}: {path}")
    return 0


def _cmd_plugins(args: argparse.Namespace) -> int:
    from slidernet import registry

    for reg in (registry.distributions, registry.drivers):
        print(f"{reg.kind}s ({reg.group}):")
        for name in reg.names():
            print(f"  {name}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``slidernet`` command; returns the exit status."""
    args = _parser().parse_args(argv)
    commands = {"run": _cmd_run, "paper": _cmd_paper, "plugins": _cmd_plugins}
    try:
        return commands[args.command](args)
    except SlidernetError as exc:
        print(f"slidernet: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("slidernet: interrupted; no partial result was written.", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
