"""Command-line interface: a thin layer over the library.

``slidernet run CONFIG.toml --out DIR [--workers N | --scheduler tcp://...] [--resume]``
                                          writes DIR/result.nc, checkpointing under DIR/checkpoint
``slidernet sweep CONFIG.toml --set KEY=V1,V2 ... --out DIR``
                                          a grid of runs, one dataset with the swept dimensions
``slidernet plot RESULT.nc [--out PATH] [--show]``
                                          the standard panels of a result (RESULT.png beside it)
``slidernet paper [--quick] --out DIR``   reproduces the paper's four result figures (Figs. 2-5)
``slidernet bench speed-error [--quick] --out DIR``
                                          speed against error of the methods (DIR/speed_error.csv, .png)
``slidernet plugins [--plugin FILE.py]``  lists the registered plugins, where they come from
``slidernet units --material steel --size 10cm --delta-T 10mK``
                                          Ntilde, sigma_theta and tau_th of a physical setup
``slidernet cache [clear]``               where the compiled kernels are kept, their size; or removes them

``python -m slidernet ...`` runs the same command.

Exit status, one rule for every subcommand:

- 0: done;
- 2: refused or failed because of something the user can change: the
  configuration, an argument, a file or a folder (missing, a folder where a
  file is wanted, unreadable, not UTF-8, no permission, a full disk), the
  machine's memory, a scheduler that does not answer. One line on stderr,
  ``slidernet: error: ...``, says what and where, and nothing half-written
  is left behind;
- 1: a bug of slidernet's, an error nobody foresaw: Python's traceback, then
  one line asking to report it;
- 128 + the signal's number: stopped by a signal, as a shell reports it (130
  for Ctrl-C, 143 for SIGTERM, each also while the command starts, with one
  line; 141 for an output pipe closed early, SIGPIPE).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from slidernet.errors import (
    CheckpointWarning,
    RunInterrupted,
    SlidAwayWarning,
    SlidernetError,
    SlowRunWarning,
    UnknownPluginError,
)

if TYPE_CHECKING:
    from slidernet.plugins.registry import Registry


def _parser() -> argparse.ArgumentParser:
    import slidernet

    p = argparse.ArgumentParser(
        prog="slidernet",
        description="Frictional sliders joined by springs, driven by thermal dilation.",
    )
    p.add_argument("--version", action="version", version=f"slidernet {slidernet.__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="run a configuration and write DIR/result.nc")
    r.add_argument("config", type=Path, help="TOML configuration (see docs/model.md section 5)")
    r.add_argument("--out", type=Path, required=True, help="output directory")
    _progress_flag(r)
    _execution_flags(r)
    _plugin_flag(r)

    sw = sub.add_parser(
        "sweep", help="run a grid of parameters; write DIR/result.nc with the swept parameters as dimensions",
        description="Each --set KEY=V1,V2,... adds a dimension; the grid is their product. Every point uses "
                    "the configuration's seed, so a point equals the plain run of its configuration.",
    )
    sw.add_argument("config", type=Path, help="TOML configuration (see docs/model.md section 5)")
    sw.add_argument("--set", dest="sets", action="append", required=True, metavar="KEY=V1,V2,...",
                    help="a dotted configuration key and its values, e.g. driver.sigma_theta=1e-7,1e-6")
    sw.add_argument("--out", type=Path, required=True, help="output directory")
    _progress_flag(sw)
    _execution_flags(sw)
    _plugin_flag(sw)

    pl = sub.add_parser(
        "plot", help="draw the standard panels of a result: n, mu_max, <x_G^2>, mu_eff against t, with the "
                     "paper's laws; a network's slip map and mu_s field; a sweep's points against t and the "
                     "swept key",
        description="Reads a result of `slidernet run` and writes RESULT.png beside it (or --out PATH): "
                    "ensemble means +- one standard error against t, the closed forms of the two-slider "
                    "model where they apply, and for a network its slip map and mu_s field (realization 0). "
                    "A result of `slidernet sweep` gets one curve per point against t, and each observable's "
                    "value at the last recorded time against the swept key.",
    )
    pl.add_argument("result", type=Path, help="a result file (DIR/result.nc of slidernet run or sweep)")
    pl.add_argument("--out", type=Path, help="the picture's path; its suffix picks the format (.png, .pdf, "
                                             ".svg); a folder gets RESULT.png (default: RESULT.png beside RESULT)")
    pl.add_argument("--show", action="store_true",
                    help="show the figure in a window instead of writing it (with --out: both)")

    paper_help = ("reproduce the four result figures of Geminard & Bertin (2010), its Figs. 2-5, written as "
                  "fig1_* to fig4_*; a full run took 102 s of wall time (183 s of CPU) and 0.90 GB of memory "
                  "in all on an idle 2-core machine, kernels compiled (2026-11-27)")
    pp = sub.add_parser("paper", help=paper_help, description=paper_help[0].upper() + paper_help[1:] + ".")
    pp.add_argument("--out", type=Path, required=True, help="output directory")
    pp.add_argument("--quick", action="store_true",
                    help="small preset (10 s of wall time, 12.5 s of CPU on an idle 2-core machine)")
    _progress_flag(pp)
    pp.add_argument("--resume", action="store_true",
                    help="continue an interrupted reproduction in --out: finished runs are read back, the "
                         "interrupted one resumes to the same bits")
    pp.add_argument("--overwrite", action="store_true", help="replace a finished reproduction in --out")

    b = sub.add_parser("bench", help="measurements of slidernet itself")
    bsub = b.add_subparsers(dest="bench", required=True)
    se = bsub.add_parser(
        "speed-error", help="speed against error of the event-driven solver and its alternatives",
        description="Runs the event-driven solver, a fixed-step theta sweep, the full dynamics and the 2D "
                    "straight-line slip on the same realizations and writes DIR/speed_error.csv "
                    "(method,setting,seconds,error,...) and DIR/speed_error.png.",
    )
    se.add_argument("--out", type=Path, required=True, help="output directory")
    se.add_argument("--quick", action="store_true", help="small preset (under 3 minutes)")
    _progress_flag(se)

    pg = sub.add_parser("plugins", help="list the registered distributions and drivers, and where they come from")
    _plugin_flag(pg)

    c = sub.add_parser("cache", help="show where the compiled kernels are kept and their size; or clear them",
                       description="slidernet compiles its kernels once and keeps them in a cache folder. "
                                   "'slidernet cache' shows it; 'slidernet cache clear' removes slidernet's "
                                   "files from it (the next run compiles again) and nothing else.")
    c.add_argument("action", nargs="?", choices=("show", "clear"), default="show",
                   help="show (default) or clear the cache")

    from slidernet.model.units import MATERIALS

    u = sub.add_parser(
        "units", help="turn a material and a setup into Ntilde, sigma_theta and tau_th",
        description="Ntilde = rho g l0 / Y, sigma_theta = alpha delta_T and tau_th = l0^2 rho c / lambda "
                    "(Geminard & Bertin 2010, section V), with a TOML snippet for a configuration.",
    )
    u.add_argument("--material", help=f"a preset ({', '.join(sorted(MATERIALS))}); explicit values override it")
    # A quantity with its unit, read by pint in _cmd_units (slidernet.model.units.QUANTITIES): a bare number
    # is refused, since "--size 10" meant as cm gave l0 = 10 m.
    u.add_argument("--size", required=True, help="slider size l0 with its unit, e.g. 10cm")
    u.add_argument("--delta-T", dest="delta_T", help="standard deviation of the temperature, e.g. 0.01K or 10mK")
    u.add_argument("--rho", help="density, e.g. 7800kg/m^3 or 7.8g/cm^3")
    u.add_argument("--Y", help="Young's modulus, e.g. 200GPa")
    u.add_argument("--alpha", help="linear thermal expansion coefficient, e.g. 12e-6/K or 12ppm/K")
    u.add_argument("--conductivity", help="thermal conductivity, e.g. 50W/m/K")
    u.add_argument("--heat-capacity", dest="heat_capacity", help="specific heat capacity, e.g. 450J/kg/K")
    u.add_argument("--g", help="gravity, e.g. 9.81m/s^2 (default 9.81m/s^2)")
    return p


def _progress_flag(p: argparse.ArgumentParser) -> None:
    shown = p.add_mutually_exclusive_group()
    shown.add_argument("--no-progress", action="store_true",
                       help="show no progress (default: a bar when stderr is a terminal, else a plain line "
                            "every 30 s: done, slips per second, time left)")
    shown.add_argument("--progress-every", dest="progress_every", type=_seconds, metavar="SECONDS",
                       help="a plain progress line every SECONDS of wall time, on a terminal too")


def _seconds(text: str) -> float:
    value = float(text)
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0, not {text!r}")
    return value


def _progress(args: argparse.Namespace) -> bool | float | None:
    """False with --no-progress, the seconds of --progress-every; else None: a bar on a terminal, lines
    elsewhere (slidernet.ensemble.progress)."""
    return False if args.no_progress else args.progress_every


def _execution_flags(p: argparse.ArgumentParser) -> None:
    p.add_argument("--workers", type=int, help="local worker processes (default: execution.workers, "
                                               "else every core)")
    p.add_argument("--scheduler", help="a Dask scheduler address, e.g. tcp://host:8786 (default: "
                                       "execution.scheduler)")
    p.add_argument("--scheduler-timeout", dest="scheduler_timeout", type=float,
                   help="seconds to wait for the Dask scheduler (default: execution.scheduler_timeout, 10)")
    p.add_argument("--resume", action="store_true",
                   help="continue the interrupted run in --out (same configuration), to the same bits")
    p.add_argument("--overwrite", action="store_true", help="replace a finished result in --out")


def _plugin_flag(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plugin", dest="plugins", action="append", metavar="FILE.py|MODULE",
                   help="a Python file or a dotted module name that registers distributions or drivers when "
                        "imported; appended to the configuration's 'plugins' (repeatable; a path is relative "
                        "to the current directory)")


def _with_cli_plugins(config: Path, plugins: list[str] | None) -> Path | dict:
    """The configuration file, read, with the ``--plugin`` entries added to its ``plugins``; as is without any.

    The entries go into the configuration itself, not only into this
    process, so that the workers, which load the configuration again,
    import them too, and the result's ``config`` attribute lists them.
    """
    if not plugins:
        return config
    from slidernet.config import read_toml
    from slidernet.plugins.loader import absolute_entry

    source = read_toml(config)
    listed = source.get("plugins", [])
    if not isinstance(listed, list):  # refused, by name, when the configuration is validated
        return source
    cwd = Path.cwd()
    added = [absolute_entry(entry, cwd) for entry in plugins]
    source["plugins"] = listed + [entry for entry in dict.fromkeys(added) if entry not in listed]
    return source


def _cmd_run(args: argparse.Namespace) -> int:
    from slidernet.config import load_config

    # Validate before any work or any file, and before the solver's modules (numba, xarray, distributed) are
    # imported: an error in the configuration is reported at once.
    cfg = load_config(_with_cli_plugins(args.config, args.plugins))
    from slidernet.ensemble.runner import all_slid_away, run

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SlidAwayWarning)  # said below, once, as a line of its own
        ds = run(cfg, progress=_progress(args), out=args.out, resume=args.resume, workers=args.workers,
                 scheduler=args.scheduler, overwrite=args.overwrite, scheduler_timeout=args.scheduler_timeout)
    with ds:
        print(f"wrote {args.out / 'result.nc'} (seed {ds.attrs['seed']}, kernel {ds.attrs['kernel']})")
        if "mu_eff_estimator" in ds.attrs:
            print(f"mu_eff: {ds.attrs['mu_eff_estimator']} (mu_eff_at = {ds.attrs['mu_eff_at']!r})")
        slid = all_slid_away(ds)
        if slid is not None:
            print(f"slidernet: {slid}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from slidernet.config import read_toml
    from slidernet.config.loading import check_keys

    base = _with_cli_plugins(args.config, args.plugins)
    check_keys(read_toml(base) if isinstance(base, Path) else base)  # a typo, before xarray and numba load
    import xarray as xr

    from slidernet.ensemble.sweep import parse_grid, sweep

    result = sweep(base, parse_grid(args.sets),
                   progress=_progress(args), out=args.out,
                   resume=args.resume, workers=args.workers, scheduler=args.scheduler, overwrite=args.overwrite,
                   scheduler_timeout=args.scheduler_timeout)
    # The points differ in number of nodes: the stacked variables are at the tree's root.
    tree = isinstance(result, xr.DataTree)
    ds = result.to_dataset() if tree else result
    swept = [name for name in ds.dims if "sweep_key" in ds[name].attrs]
    groups = f"; per-node variables in groups point_0 to point_{len(result.children) - 1}" if tree else ""
    print(f"wrote {args.out / 'result.nc'} ({' x '.join(f'{ds.sizes[d]} {d}' for d in swept)} points{groups})")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from slidernet.analysis.sweep_plots import plot as plot_result  # a run's panels, or a sweep's
    from slidernet.errors import ConfigError

    out = args.out
    if out is None and not args.show:
        out = args.result.with_suffix(".png")
    elif out is not None and out.is_dir():
        out = out / args.result.with_suffix(".png").name
    if out is not None and out.resolve() == args.result.resolve():
        raise ConfigError(f"The picture would replace the result file {str(args.result)!r}; choose another --out.")
    figure = None
    if args.show:
        import matplotlib.pyplot as plt

        backend = plt.get_backend()
        if backend.lower() in _non_interactive_backends():
            raise ConfigError(f"--show needs a window, and matplotlib's backend {backend!r} cannot open one "
                              "(no display?); write a file instead (--out PATH), or set MPLBACKEND.")
        figure = plt.figure()
    if out is None:
        plot_result(args.result, None, figure=figure)
    else:
        # The one lock of the picture's folder while the picture is made: never beside a run or a sweep
        # still going there (a run's own folder is where RESULT.png goes by default).
        from slidernet.io.store import FolderLock

        out.parent.mkdir(parents=True, exist_ok=True)
        with FolderLock(out.parent, "plot"):
            plot_result(args.result, out, figure=figure)
        print(f"wrote {out}")
    if args.show:
        plt.show()
    return 0


def _non_interactive_backends() -> list[str]:
    try:
        from matplotlib.backends import BackendFilter, backend_registry
    except ImportError:  # matplotlib < 3.9
        from matplotlib.rcsetup import non_interactive_bk

        return [name.lower() for name in non_interactive_bk]
    return backend_registry.list_builtin(BackendFilter.NON_INTERACTIVE)


def _cmd_paper(args: argparse.Namespace) -> int:
    from slidernet.paper.reproduction import reproduce

    files = reproduce(args.out, quick=args.quick, progress=_progress(args), resume=args.resume,
                      overwrite=args.overwrite)
    for name, path in files.items():
        print(f"{name}: {path}")
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from slidernet.validation.speed_error import speed_error

    files = speed_error(args.out, quick=args.quick, progress=_progress(args))
    for name, path in files.items():
        print(f"{name}: {path}")
    return 0


def _cmd_plugins(args: argparse.Namespace) -> int:
    from slidernet.plugins import registry
    from slidernet.plugins.loader import absolute_entry, import_plugins

    # So that a physicist can see their file register its names before naming them in a configuration.
    import_plugins([absolute_entry(entry, Path.cwd()) for entry in args.plugins or ()], field="--plugin option")

    for reg in (registry.distributions, registry.drivers):
        print(f"{reg.kind}s ({reg.group}):")
        rows = [(name, *_plugin_origin(reg, name)) for name in reg.names()]
        width = max((len(r[0]) for r in rows), default=0)
        source_width = max((len(r[1]) for r in rows), default=0)
        for name, origin, summary in rows:
            print(f"  {name:<{width}}  {origin:<{source_width}}  {summary}".rstrip())
    return 0


def _plugin_origin(reg: Registry, name: str) -> tuple[str, str]:
    """Where ``name`` comes from (built-in, an entry point's package, run time) and its summary."""
    origin = reg.origin(name)
    try:
        factory = reg.get(name)
    except UnknownPluginError:  # a broken package is listed (get warned), not fatal
        return origin, f"FAILED TO LOAD {reg.load_error(name)}"
    return origin, _summary(factory)


def _summary(factory: object) -> str:
    doc = getattr(factory, "__doc__", None)
    lines = [line.strip() for line in (doc or "").strip().splitlines()]
    return lines[0] if lines and lines[0] else "(no docstring)"


def _cmd_units(args: argparse.Namespace) -> int:
    from slidernet.model.units import QUANTITIES, read_quantity, setup

    values = {name: read_quantity(getattr(args, name), name, "--" + name.replace("_", "-"))
              for name in QUANTITIES if getattr(args, name) is not None}
    result = setup(args.material, **values)
    print(result.summary())
    print("\n# In a configuration (exact values):")
    print(result.toml())
    print("\n# or let slidernet compute them:")
    print(result.units_toml())
    return 0


def _cmd_cache(args: argparse.Namespace) -> int:
    from slidernet.kernels import jit

    if args.action == "clear":
        count, size = jit.clear_cache()
        print(f"removed {count} files ({_mib(size)}) of compiled kernels from {jit.cache_root()}")
        return 0
    files = jit.cache_files()
    current = sum(1 for path in files if path.is_relative_to(jit.cache_dir()))
    print(f"kernel cache: {jit.cache_root()}")
    print(f"  {len(files)} files, {_mib(sum(path.stat().st_size for path in files))}; {current} of them for "
          f"these sources ({jit.cache_dir()})")
    print("  'slidernet cache clear' removes them; set NUMBA_CACHE_DIR to move the cache.")
    return 0


def _mib(size: int) -> str:
    return f"{size / 2**20:.1f} MiB"


#: The exit status of the command, one rule for every subcommand (docs/getting-started.md says it too).
EXIT_OK = 0
#: A bug of slidernet's: an error nobody foresaw. Python's traceback is shown, to be reported.
EXIT_BUG = 1
#: Refused or failed because of something the user can change: the configuration, a file or a folder (missing,
#: unreadable, not UTF-8, no permission, a full disk), an argument, the machine's memory, a scheduler that does
#: not answer. One line on stderr says what and where; nothing half-written is left behind.
EXIT_INPUT = 2
#: Stopped by a signal: 128 + its number, as a shell reports it (130 for Ctrl-C, 143 for SIGTERM, 141 for a
#: closed output pipe, SIGPIPE).
EXIT_SIGNAL = 128


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``slidernet`` command; returns the exit status (:data:`EXIT_INPUT` and the others).

    Everything runs inside the handlers below, the parser and the imports of
    numpy, numba and xarray included, so that Ctrl-C while the command
    starts is one line and exit 130, as it is later.
    """
    started = False
    # A batch system ends a job with one SIGTERM: before and after a run (whose StopSignal has handlers of its
    # own) it says so in one line, as Ctrl-C does, rather than ending the process without a word.
    in_main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminated) if in_main else None
    try:
        with _one_line_warnings():
            args = _parser().parse_args(argv)
            commands = {"run": _cmd_run, "plot": _cmd_plot, "paper": _cmd_paper, "bench": _cmd_bench,
                        "sweep": _cmd_sweep, "plugins": _cmd_plugins, "units": _cmd_units,
                        "cache": _cmd_cache}
            started = True
            status = commands[args.command](args)
            sys.stdout.flush()  # a closed pipe shows here, inside the handlers below, not at exit
            return status
    except SlidernetError as exc:
        print(f"slidernet: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except RunInterrupted as exc:
        print(f"slidernet: {exc}", file=sys.stderr)
        return EXIT_SIGNAL + exc.signum
    except KeyboardInterrupt as exc:
        what = "terminated by SIGTERM" if isinstance(exc, _Terminated) else "interrupted"
        if not started:
            print(f"slidernet: {what} while starting; nothing was done.", file=sys.stderr)
        else:
            print(f"slidernet: {what}; files already written are complete, nothing else was saved.",
                  file=sys.stderr)
        return EXIT_SIGNAL + (signal.SIGTERM if isinstance(exc, _Terminated) else signal.SIGINT)
    except BrokenPipeError:
        # The reader went away (`slidernet units ... | head`): say so once, on stderr, and make
        # the interpreter's own flush of stdout at exit write nowhere instead of raising again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        print("slidernet: error: the output pipe was closed before everything was written.", file=sys.stderr)
        return EXIT_SIGNAL + signal.SIGPIPE
    except OSError as exc:  # a file or a folder of the user's: the same status as any other input
        where = f" {exc.filename!r}:" if exc.filename else ""
        print(f"slidernet: error:{where} {exc.strerror or exc}", file=sys.stderr)
        return EXIT_INPUT
    except MemoryError as exc:  # the estimate (slidernet.solver.budget) passed, the machine had less free
        detail = f" ({exc})" if str(exc) else ""
        print(f"slidernet: error: out of memory{detail}: the run needs more memory than this machine had free; "
              "run fewer workers or a smaller configuration.", file=sys.stderr)
        return EXIT_INPUT
    except Exception:
        traceback.print_exc()
        print("slidernet: internal error: this is a bug of slidernet; please report it with the lines above.",
              file=sys.stderr)
        return EXIT_BUG
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


class _Terminated(KeyboardInterrupt):
    """SIGTERM outside a run: it stops the command as Ctrl-C does, with its own words and status (143)."""


def _terminated(signum: int, frame: object) -> None:
    raise _Terminated


@contextlib.contextmanager
def _one_line_warnings() -> Iterator[None]:
    """slidernet's warnings as one line on stderr (``slidernet: warning: ...``); others as Python shows them."""
    shown = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: TextIO | None = None, line: str | None = None) -> None:
        if issubclass(category, (SlowRunWarning, SlidAwayWarning, CheckpointWarning)):
            print(f"slidernet: warning: {message}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = shown


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
