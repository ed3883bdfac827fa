"""The checkpoint folder of a run: what is done, kept so that a killed run loses (almost) nothing.

Layout of ``DIR/checkpoint/`` (plain numeric files and JSON; no pickle)::

    run.json                 what identifies the run: the configuration (without
                             its execution table), the resolved seed, the
                             number of realizations, the slidernet version
    block-<first>-<k>.npz    finished realizations, written together: their
                             indices, then every record stacked (ragged records,
                             the event catalogue, concatenated with offsets);
                             block-<first>-<k>-<j>.npz where that name is taken
                             (j = 1, 2, ...; a realization in two blocks is read
                             from the one written last)
    partial-<r>.npz          a realization in progress (slidernet.io.checkpoint)

Every file is written to a temporary name and renamed, so a kill at any time
leaves either the old file or the new one. The set of finished realizations is
read from the blocks themselves (not from a list that could disagree with
them). Once ``result.nc`` is written the folder is removed.
"""

from __future__ import annotations

import json
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from slidernet.errors import CheckpointError, OutputError
from slidernet.io import atomic_output

Record = dict[str, Any]

# A block's name; the suffix -<j> tells apart blocks whose first realization and size agree.
_BLOCK = re.compile(r"block-(\d+)-(\d+)(?:-(\d+))?\.npz")


def _block_order(path: Path) -> tuple[int, int]:
    """(first realization, suffix j; 0 without one): the order in which blocks were written, per first index."""
    m = _BLOCK.fullmatch(path.name)
    return int(m.group(1)), int(m.group(3) or 0)


def _flat_diff(a: Any, b: Any, prefix: str = "") -> list[str]:
    """Dotted keys where two JSON-like trees differ."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            out += _flat_diff(a.get(key), b.get(key), f"{prefix}{key}.")
        return out
    return [] if a == b else [f"{prefix[:-1]} ({json.dumps(a)} in the checkpoint, {json.dumps(b)} now)"]


class RunStore:
    """The checkpoint folder ``out_dir / "checkpoint"`` of one run.

    Parameters
    ----------
    out_dir : path
        The run's output directory.
    identity : dict
        ``config`` (the configuration as JSON-ready dict, without ``execution``;
        its ``seed`` as the user gave it), ``seed`` (resolved), ``realizations``
        and ``slidernet_version``.
    resume : bool
        Continue the run found there. Without it, a folder that holds an
        interrupted run is refused rather than overwritten.
    """

    def __init__(self, out_dir: str | Path, identity: dict[str, Any], resume: bool,
                 overwrite: bool = False) -> None:
        self.dir = Path(out_dir) / "checkpoint"
        self.identity = dict(identity)
        self.resume = resume
        self.overwrite = overwrite
        self._buffer: dict[int, Record] = {}
        self._created: list[Path] = []  # folders this run made, outermost first (undone by abandon)

    # -- opening ---------------------------------------------------------
    def open(self) -> int:
        """Create or check the folder; return the seed to use (the stored one on resume).

        Raises
        ------
        OutputError
            If the output directory is a file or cannot be created, or it
            holds a finished ``result.nc`` and neither ``overwrite`` nor a
            run to resume is there.
        CheckpointError
            If it holds an interrupted run and ``resume`` is not set, or
            another run's checkpoint, or nothing to resume.
        """
        out = self.dir.parent
        check_output_dir(out)
        run_json = self.dir / "run.json"
        result = out / "result.nc"
        if result.exists() and not run_json.exists() and not (self.overwrite or self.resume):
            raise OutputError(
                f"{str(out)!r} holds a finished result ({str(result)!r}); it is not replaced silently. "
                "Use --overwrite to replace it, or another output directory."
            )
        if run_json.exists() and self.overwrite and not self.resume:
            shutil.rmtree(self.dir)  # asked for: the interrupted run there is replaced
        if run_json.exists():
            try:
                stored = json.loads(run_json.read_text())
            except (OSError, ValueError) as exc:
                raise CheckpointError(f"The checkpoint {str(run_json)!r} cannot be read: {exc}") from None
            done = len(self.done())
            if not self.resume:
                raise CheckpointError(
                    f"{str(self.dir.parent)!r} holds an interrupted run ({done} of {stored.get('realizations')} "
                    f"realizations done). Continue it with --resume, or start again with --overwrite."
                )
            diff = _flat_diff(stored["config"], self.identity["config"])
            if stored.get("realizations") != self.identity["realizations"]:
                diff.append(f"realizations ({stored.get('realizations')} in the checkpoint, "
                            f"{self.identity['realizations']} now)")
            if diff:
                raise CheckpointError(
                    "Cannot resume: the configuration differs from the checkpointed run's in "
                    + "; ".join(diff) + ". Resume with the same configuration, or use another output directory."
                )
            if stored.get("slidernet_version") != self.identity["slidernet_version"]:
                raise CheckpointError(
                    f"Cannot resume: the checkpoint was written by slidernet {stored.get('slidernet_version')}, "
                    f"this is {self.identity['slidernet_version']}; results would not be bit-identical."
                )
            self.identity["seed"] = stored["seed"]
            return int(stored["seed"])
        if self.resume:
            finished = " (its run is finished: result.nc is there)" if result.exists() else ""
            raise CheckpointError(
                f"Nothing to resume in {str(self.dir.parent)!r}: it has no checkpoint folder{finished}.")
        self._make_dirs()
        try:
            with atomic_output(run_json) as tmp:
                tmp.write_text(json.dumps(self.identity, indent=1, sort_keys=True))
        except OSError as exc:
            self.abandon()
            raise OutputError(f"Cannot write in the output directory {str(out)!r}: {reason(exc)}.") from None
        return int(self.identity["seed"])

    def _make_dirs(self) -> None:
        """Create the checkpoint folder and its missing parents, remembering which were made here."""
        missing = [p for p in (self.dir, *self.dir.parents) if not p.exists()][::-1]
        for path in missing:
            try:
                path.mkdir()
            except FileExistsError:
                if not path.is_dir():
                    self.abandon()
                    raise OutputError(f"The output path {str(path)!r} is a file; name a folder.") from None
            except OSError as exc:
                self.abandon()
                raise OutputError(
                    f"Cannot create the output directory {str(self.dir.parent)!r}: {reason(exc)}.") from None
            else:
                self._created.append(path)

    def abandon(self) -> None:
        """Undo :meth:`open` after a failure, if nothing worth keeping was saved.

        A run that failed before any realization finished or saved its state
        leaves the output directory as it found it: the folders it created
        are removed. Saved work (a block or a partial realization) is kept,
        so that a fixed run can resume it.
        """
        if self._buffer or (self.dir.exists() and any(
                _BLOCK.fullmatch(p.name) or p.name.startswith("partial-") for p in self.dir.iterdir())):
            return
        for path in reversed(self._created):
            shutil.rmtree(path, ignore_errors=True)
        self._created.clear()

    def partials(self) -> int:
        """The number of realizations saved in progress."""
        return sum(1 for _ in self.dir.glob("partial-*.npz")) if self.dir.exists() else 0

    # -- finished realizations -------------------------------------------
    def _blocks(self) -> list[Path]:
        if not self.dir.exists():
            return []
        return sorted((p for p in self.dir.iterdir() if _BLOCK.fullmatch(p.name)), key=_block_order)

    def done(self) -> dict[int, tuple[Path, int]]:
        """Finished realization -> (its block, its row in the block)."""
        out: dict[int, tuple[Path, int]] = {}
        for path in self._blocks():
            try:
                with np.load(path, allow_pickle=False) as z:
                    idx = z["realization"]
            except (OSError, ValueError, KeyError) as exc:
                raise CheckpointError(f"The checkpoint block {str(path)!r} is damaged: {exc}") from None
            for row, r in enumerate(idx.tolist()):
                out[r] = (path, row)
        return out

    def add(self, r: int, record: Record) -> None:
        """Hold a finished realization until the next :meth:`flush`."""
        self._buffer[r] = record

    @property
    def held(self) -> int:
        """Finished realizations held in memory, not yet written."""
        return len(self._buffer)

    def flush(self) -> None:
        """Write the held realizations as one block, then drop their partial files."""
        if not self._buffer:
            return
        rs = sorted(self._buffer)
        arrays = _pack([self._buffer[r] for r in rs])
        arrays["realization"] = np.array(rs, np.int64)
        path = self.dir / f"block-{rs[0]:09d}-{len(rs)}.npz"
        k = 0
        while path.exists():  # the same first realization can recur after a resume
            k += 1
            path = self.dir / f"block-{rs[0]:09d}-{len(rs)}-{k}.npz"
        with atomic_output(path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
        for r in rs:
            self.partial(r).unlink(missing_ok=True)
        self._buffer.clear()

    def partial(self, r: int) -> Path:
        """Where realization ``r`` in progress is saved."""
        return self.dir / f"partial-{r:09d}.npz"

    def records(self, R: int) -> Iterator[Record]:
        """Every realization's records, in realization order, reading one block at a time (or two)."""
        where = self.done()
        missing = [r for r in range(R) if r not in where]
        if missing:
            raise CheckpointError(f"{len(missing)} realizations are missing from {str(self.dir)!r}, "
                                  f"e.g. {missing[:5]}")
        cache: dict[Path, list[Record]] = {}
        for r in range(R):
            path, row = where[r]
            if path not in cache:
                if len(cache) >= 2:
                    cache.pop(next(iter(cache)))
                with np.load(path, allow_pickle=False) as z:
                    cache[path] = _unpack({k: z[k] for k in z.files})
            yield cache[path][row]

    def remove(self) -> None:
        """Delete the folder (the run's result is safely written)."""
        shutil.rmtree(self.dir, ignore_errors=True)


def check_output_dir(out: Path) -> None:
    """Refuse an output directory that is an existing file (the one check every output folder shares)."""
    if out.exists() and not out.is_dir():
        raise OutputError(f"The output directory {str(out)!r} is a file; name a folder.")


def reason(exc: OSError) -> str:
    """The OS's words for an error, without the traceback's chain."""
    return exc.strerror or str(exc)


# -- records <-> flat arrays ---------------------------------------------------
def _pack(records: list[Record]) -> dict[str, np.ndarray]:
    """Stack records into named arrays; dict-valued entries (ragged) are concatenated with offsets."""
    out: dict[str, np.ndarray] = {}
    for key, value in records[0].items():
        if isinstance(value, dict):
            sizes = [len(next(iter(rec[key].values()))) for rec in records]
            out[f"{key}/offsets"] = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            for sub in value:
                out[f"{key}/{sub}"] = np.concatenate([np.asarray(rec[key][sub]) for rec in records])
        else:
            out[key] = np.stack([np.asarray(rec[key]) for rec in records])
    return out


def _unpack(arrays: dict[str, np.ndarray]) -> list[Record]:
    """Inverse of :func:`_pack`."""
    B = arrays["realization"].size
    records: list[Record] = [{} for _ in range(B)]
    ragged = {k.split("/")[0] for k in arrays if "/" in k}
    for key, value in arrays.items():
        if key == "realization" or "/" in key:
            continue
        for b in range(B):
            item = value[b]
            records[b][key] = item.item() if item.ndim == 0 and value.dtype == bool else item
    for key in ragged:
        off = arrays[f"{key}/offsets"]
        subs = [k.split("/", 1)[1] for k in arrays if k.startswith(f"{key}/") and not k.endswith("/offsets")]
        for b in range(B):
            records[b][key] = {s: arrays[f"{key}/{s}"][off[b]:off[b + 1]] for s in subs}
    return records
