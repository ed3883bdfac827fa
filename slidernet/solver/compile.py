"""Compile a scene's kernels before its realizations run: once per machine, said on the terminal.

numba compiles a kernel the first time it is called with a new type
signature and keeps the machine code in its disk cache
(:mod:`slidernet.kernels.jit`). Left to itself, each worker process of a
run would compile the same kernels at the same time, and nothing would say
why a first run is slow. :func:`compile_kernels` instead runs a *probe*
before the realizations start: the same scene, shrunk to a few nodes and
two thermal steps (:func:`probe_config`). It calls exactly the compiled
functions the real scene calls, with the same type signatures (the types
of the arrays do not depend on their sizes), so the real run compiles
nothing more. It holds the cache's lock of its kernels while it runs: the
processes of one machine compile them once, and the others load them from
the cache. Forked workers inherit what the parent compiled.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.config import Config, load_config
from slidernet.errors import SlidernetError
from slidernet.kernels.jit import cache_dir, compile_lock, on_first_compile
from slidernet.plugins import registry
from slidernet.solver.backends import BACKENDS
from slidernet.solver.realization import Realization
from slidernet.solver.scene import Scene

# The largest probe: enough nodes that every code path of the kernels is typed, few enough to cost nothing.
_PROBE_CHAIN = 8
_PROBE_IRREGULAR = 32
_PROBE_SIDE = 4
_PROBE_SLIPS = 2000
# The largest theta / Ntilde a probe is driven with (see probe_config).
_PROBE_DRIVE = 100.0

# The wall seconds each family of kernels (a scene's kernel_parts, joined) took to compile the last time on
# this machine, recorded after each compile, beside the compiled kernels: the notice's estimate. A fixed table
# measured elsewhere (it said about 25 s) was 5 times short on a loaded machine.
_TIMES_FILE = "compile_seconds.json"
_clock = time.monotonic  # the clock of the measured time (a test's own where it checks what is recorded)


def compile_times() -> dict[str, float]:
    """The seconds each family of kernels took to compile the last time on this machine (``{}``: none known).

    Read from ``compile_seconds.json`` in :func:`~slidernet.kernels.jit.cache_dir`, keyed by the family's
    parts (``"1D network, network tilt test"``); a file that cannot be read counts as none.
    """
    try:
        times = json.loads((Path(cache_dir()) / _TIMES_FILE).read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(times, dict):
        return {}
    return {k: float(v) for k, v in times.items() if isinstance(v, (int, float)) and math.isfinite(v) and v >= 0}


def record_compile_time(family: str, seconds: float) -> None:
    """Record that ``family`` took ``seconds`` to compile (replacing the time before); a cache folder that
    cannot be written records nothing (the next notice then does not know)."""
    times = {**compile_times(), family: round(float(seconds), 1)}
    path = Path(cache_dir()) / _TIMES_FILE
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(times, indent=1, sort_keys=True))
        os.replace(tmp, path)  # whole or not at all: two processes that compile at once never mix their writes
    except OSError:
        pass


def probe_config(cfg: Config) -> Config | None:
    """The scene of ``cfg`` shrunk to a few nodes, one realization and two thermal steps.

    Only the size changes (a chain of at most 8 sliders, a lattice of at
    most 4 x 4, an irregular network of at most 32; a graph read from a file
    is kept whole), ``solver.max_avalanche`` (2000 slips), Ntilde (raised to
    the largest ``|theta|`` of two steps of the driver where that passes 100
    Ntilde: a drive of the study's strength, a few slips a step), and a plugin that
    is not a built-in, replaced by a built-in of its kind (a Gaussian law, a
    driver of Gaussian steps), so the probe runs the same compiled kernels as
    ``cfg``, stops soon, and never calls a user's plugin.
    None if the shrunk configuration is not valid (a rule that needs more
    steps): the real run then compiles what it needs as it goes.
    """
    data = cfg.model_dump(mode="json", exclude={"execution"})
    data.update(seed=0, realizations=1, steps=2, record="all")
    # A plugin of the user's runs only in the real run: its sample() or thetas() may count, log or read a
    # finite source. What the kernels compile does not depend on it (float64 arrays either way); a
    # built-in is kept, since some compile code of their own (compiled draws, the OU recursion).
    friction = data["friction"]
    if registry.distributions.origin(friction["static"]["name"]) != "built-in":
        friction["static"] = {"name": "gaussian", "mean": friction["mu_d"] + 0.1, "std": 0.01}
    if registry.drivers.origin(data["driver"]["name"]) != "built-in":
        data["driver"] = {"name": "gaussian_steps", "sigma_theta": 1e-7}
    # A bound on the work of one avalanche and of one tilt test: a probe that reaches it stops with an error
    # (which it drops) after its kernels have run, instead of following a long test (a square lattice's
    # floppy rows slide alone for 1e5 slips before the tilt test gives up, each an integration with the
    # exact 2D slip).
    data["solver"] = {**data.get("solver", {}), "max_avalanche": _PROBE_SLIPS}
    net = data["network"]
    if net["kind"] == "chain" and net["n"] > _PROBE_CHAIN:
        net["n"] = _PROBE_CHAIN
    elif net["kind"] == "irregular" and net["n"] > _PROBE_IRREGULAR:
        net["n"] = _PROBE_IRREGULAR
    elif net["kind"] in ("square", "triangular"):
        rows, cols = net["shape"]
        net["shape"] = [min(rows, _PROBE_SIDE), min(cols, _PROBE_SIDE)]
    try:
        probe = load_config(data)
        # A probe drives its network as the study's runs do, theta / Ntilde of order one: a few slips a step.
        # Far more (sigma_theta = 1 at Ntilde = 1e-7: the configuration fuzz) made two steps of a 4 x 4
        # lattice take ~1e8 slips in a kernel that holds the process, before the run's signal handling.
        # What numba compiles does not depend on Ntilde, so where the largest |theta| of the driver's two
        # steps passes 100 Ntilde, the probe's Ntilde is raised to it (the [units] table, which would set
        # it back, goes).
        largest = float(np.abs(probe.driver_plugin().thetas(np.random.default_rng(0), 2)).max())
        if largest > _PROBE_DRIVE * data["network"]["Ntilde"]:
            data.pop("units", None)
            data["network"]["Ntilde"] = largest
            probe = load_config(data)
        return probe
    except SlidernetError:
        return None


def kernel_parts(scene: Scene) -> list[str]:
    """What a scene compiles, in words: its kernel and the variants it needs (the notice's list)."""
    parts = BACKENDS[scene.kernel].parts(scene)
    if scene.tilt_at == "records":
        parts.append("network tilt test")
    if scene.shs_stiffness is not None:
        parts.append("slide-hold-slide")
    return parts


def compile_notice(scenes: Scene | Sequence[Scene]) -> str:
    """The line a first run prints before it compiles: what, that it happens once, about how long (the time
    it took the last time on this machine, :func:`compile_times`, or that it is not known yet)."""
    scenes = [scenes] if isinstance(scenes, Scene) else list(scenes)
    parts = list(dict.fromkeys(p for scene in scenes for p in kernel_parts(scene)))
    known = compile_times()
    families = [family(scene) for scene in scenes]
    if all(f in known for f in families):
        how_long = f"about {sum(known[f] for f in families):.0f} s the last time on this machine"
    else:
        how_long = "how long is not known yet on this machine (it is measured this time)"
    return (f"slidernet: compiling the kernels this run needs ({', '.join(parts)}) for this machine, once per "
            f"installation: {how_long}; later runs load them from {cache_dir()}.")


def family(scene: Scene) -> str:
    """The name of the kernels a scene compiles together (its :func:`kernel_parts`), the key of their time."""
    return ", ".join(kernel_parts(scene))


def _stderr(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def terminal_notice(progress: bool | float | None) -> Callable[[str], None] | None:
    """Where a caller with a progress argument says that it compiles: stderr wherever its progress shows, as
    a bar or as lines (:mod:`slidernet.ensemble.progress`); nowhere with ``progress=False``."""
    return None if progress is False else _stderr


def compile_kernels(configs: Config | Sequence[Config], notice: Callable[[str], Any] | None = _stderr) -> bool:
    """Compile (or load from the cache) every kernel the scene of each configuration runs; True if anything
    was compiled.

    Parameters
    ----------
    configs : Config or sequence of Config
        The run's configuration, or those of several runs (a study, the
        paper's figures): one probe per distinct set of kernels.
    notice : callable or None
        Called with :func:`compile_notice`'s line, for all the scenes
        together, once, when numba starts compiling (not when everything
        loads from the cache); None: silent. Default: print it on stderr.

    An error of a probe itself (a network the probe's size cannot hold,
    say) is not the run's: it is left for the real run to meet, and
    whatever the probe compiled before it stays compiled.
    """
    scenes: dict[tuple[str, ...], Scene] = {}
    for cfg in [configs] if isinstance(configs, Config) else configs:
        probe = probe_config(cfg)
        if probe is None:
            continue
        try:
            scene = Scene.from_config(probe)
        except SlidernetError:
            continue
        scenes.setdefault((*kernel_parts(scene), cfg.friction.static.name, cfg.driver.name), scene)
    if not scenes:
        return False
    line = compile_notice(list(scenes.values()))

    def said() -> None:
        if notice is not None:
            notice(line)

    with on_first_compile(said) as compiled:
        for scene in scenes.values():
            with compile_lock(family(scene)), on_first_compile(lambda: None) as this:
                start = _clock()  # after the lock: waiting for another process is not compiling
                try:
                    Realization(scene, np.random.SeedSequence(0)).advance()
                except SlidernetError:
                    pass
            if this.compiled:
                record_compile_time(family(scene), _clock() - start)
    return compiled.compiled
