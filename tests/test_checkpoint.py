"""Checkpoints of one realization: a resumed run gives the bits of an uninterrupted one."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from slidernet.config import load_config
from slidernet.errors import CheckpointError
from slidernet.io.checkpoint import checkpoint_info, load_realization, save_realization
from slidernet.plugins.distributions import stream as threshold_stream
from slidernet.solver import Realization, Scene, simulate
from slidernet.solver import backends as backends_module

from .conftest import make_config

BASE = ["n", "mu_max", "x_G"]
META = {"config_hash": "3f2a", "realization": 4, "slidernet_version": "0.1.0"}


def network_config(net: dict, steps: int, observables: list[str], **changes: Any) -> dict:
    # batch 16 (the smallest allowed) makes the draw buffers run out and be refilled many times.
    return make_config(**{"seed": 3, "realizations": 1, "steps": steps, "record": "all",
                          "observables": observables, "network": {**net, "Ntilde": 1e-7},
                          "driver.sigma_theta": 3e-7, "solver.batch": 16, **changes})


# Each scene is sized so that by step S/3 the threshold buffer has been refilled,
# the tilt stream has been read (mu_eff) and catalogue chunks have been flushed (events).
SCENES = {
    "pair_tilt": make_config(**{"steps": 120, "record": "all", "observables": [*BASE, "mu_eff"],
                                "solver.batch": 16}),
    "csr_tilt_events_fext": network_config({"kind": "chain", "n": 6, "f_ext": 0.02}, 60,
                                           [*BASE, "mu_eff", "events", "contact_age"],
                                           **{"solver.recompute_every": 50}),
    # max_events = 350 with 64-row chunks: at S/3 the kernel's buffer has been cut to the 30 rows
    # left, and the cap is reached after the checkpoint.
    "csr_events_capped": network_config({"kind": "two_slider"}, 60, [*BASE, "events"],
                                        **{"solver.max_events": 350}),
    "vec_straight_tilt_events_fext": network_config(
        {"kind": "triangular", "shape": [4, 5], "f_ext": [0.02, -0.01]}, 60,
        [*BASE, "mu_eff", "events", "contact_age"]),
    # The exact slip costs ~1 ms a slip with the tilt test: a small lattice, few steps.
    "vec_exact_tilt_events": network_config({"kind": "triangular", "shape": [3, 3]}, 12,
                                            [*BASE, "mu_eff", "events"],
                                            **{"solver.slip": "exact", "driver.sigma_theta": 5e-8}),
}

pytestmark = pytest.mark.filterwarnings("ignore:The event catalogue reached solver.max_events:RuntimeWarning")


@pytest.fixture(autouse=True)
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    # Catalogue chunks of 64 rows: several are handed to Python before the checkpoint.
    monkeypatch.setattr(backends_module, "EVENT_CHUNK", 64)
    # Raw threshold chunks of 64 draws: the streams' Generators have moved past
    # their first chunk, and hold a surplus, at the checkpoint.
    monkeypatch.setattr(threshold_stream, "RAW_CHUNK", 64)  # read where TruncatedStream is


def fresh_scene(name: str) -> Scene:
    return Scene.from_config(load_config(SCENES[name]))


def assert_same(a: Any, b: Any, where: str = "result") -> None:
    """Bitwise equality of two results (nested dicts of arrays and scalars)."""
    if isinstance(a, dict):
        assert set(a) == set(b), where
        for key in a:
            assert_same(a[key], b[key], f"{where}[{key!r}]")
    else:
        assert np.asarray(a).dtype == np.asarray(b).dtype, where
        np.testing.assert_array_equal(a, b, err_msg=where, strict=True)


def npz_arrays(path: Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as npz:
        return {name: npz[name] for name in npz.files}


def saved_at_third(name: str, path: Path, seed: int = 11) -> tuple[Realization, np.random.SeedSequence]:
    scene = fresh_scene(name)
    ss = np.random.SeedSequence(seed)
    real = Realization(scene, ss).advance(scene.steps // 3)
    save_realization(real, path, META)
    return real, ss


@pytest.mark.parametrize("name", list(SCENES), ids=list(SCENES))
def test_a_resumed_realization_gives_the_uninterrupted_bits(name: str, tmp_path: Path) -> None:
    path = tmp_path / "r4.npz"
    real, ss = saved_at_third(name, path)
    # The checkpoint is taken where it matters: buffers refilled, streams read, chunks flushed.
    fresh = Realization(real.scene, ss)
    assert real.n > 2 * real.scene.batch
    assert real.rngs["thresholds"].bit_generator.state != fresh.rngs["thresholds"].bit_generator.state
    if real.scene.tilt_at is not None:
        assert real.out["f_count"].sum() > 0
        assert real.rngs["tilt"].bit_generator.state != fresh.rngs["tilt"].bit_generator.state
    if real.scene.catalogue:
        assert len(real.backend.event_chunks) > 0 and real.state["ev_pos"][0] > 0

    # New Python objects throughout: another Scene from the same config, another SeedSequence.
    scene = fresh_scene(name)
    loaded = load_realization(scene, np.random.SeedSequence(11), path, expect_meta=META)
    assert loaded.step == real.step == scene.steps // 3
    assert loaded.n == real.n
    assert_same(loaded.result(), real.result(), "at the checkpoint")

    resumed = loaded.advance().result()
    uninterrupted = real.advance().result()
    assert_same(resumed, uninterrupted)
    assert_same(resumed, simulate(scene, np.random.SeedSequence(11)))
    if name == "csr_events_capped":
        assert resumed["events_complete"] is False and resumed["events"]["node"].size == 350


@pytest.mark.parametrize("name", ["pair_tilt", "vec_straight_tilt_events_fext"], ids=["pair", "vec"])
@pytest.mark.parametrize("at", ["start", "end"])
def test_checkpoints_before_the_first_step_and_after_the_last(name: str, at: str, tmp_path: Path) -> None:
    scene = fresh_scene(name)
    real = Realization(scene, np.random.SeedSequence(11)).advance(0 if at == "start" else None)
    save_realization(real, tmp_path / "r.npz", META)
    loaded = load_realization(fresh_scene(name), np.random.SeedSequence(11), tmp_path / "r.npz", META)
    assert loaded.step == real.step
    assert_same(loaded.advance().result(), simulate(scene, np.random.SeedSequence(11)))


@pytest.mark.parametrize("name", list(SCENES), ids=list(SCENES))
def test_save_load_save_writes_the_same_arrays(name: str, tmp_path: Path) -> None:
    first, second = tmp_path / "a.npz", tmp_path / "b.npz"
    _, ss = saved_at_third(name, first)
    save_realization(load_realization(fresh_scene(name), ss, first, META), second, META)
    a, b = npz_arrays(first), npz_arrays(second)
    assert_same(a, b, "file")
    # Numbers only: nothing in the file needs pickle.
    assert all(v.dtype.kind in "biuf" for v in a.values())


def test_the_header_holds_the_meta_and_the_step(tmp_path: Path) -> None:
    real, _ = saved_at_third("vec_straight_tilt_events_fext", tmp_path / "r.npz")
    info = checkpoint_info(tmp_path / "r.npz")
    assert info["meta"] == META
    assert (info["step"], info["n"]) == (real.step, real.n)


@pytest.mark.parametrize(
    ("expect", "match"),
    [
        ({**META, "config_hash": "9e1b"}, r"another run: its meta 'config_hash' is '3f2a', expected '9e1b'"),
        ({**META, "realization": 5}, r"its meta 'realization' is 4, expected 5"),
        ({"resume_token": 1}, r"has no meta entry 'resume_token'"),
    ],
    ids=["config_hash", "realization", "missing_key"],
)
def test_a_mismatching_meta_is_refused(expect: dict, match: str, tmp_path: Path) -> None:
    _, ss = saved_at_third("csr_tilt_events_fext", tmp_path / "r.npz")
    with pytest.raises(CheckpointError, match=match):
        load_realization(fresh_scene("csr_tilt_events_fext"), ss, tmp_path / "r.npz", expect)


def test_another_scene_or_seed_is_refused(tmp_path: Path) -> None:
    name = "csr_tilt_events_fext"
    path = tmp_path / "r.npz"
    _, ss = saved_at_third(name, path)
    cfg = SCENES[name]
    other_batch = Scene.from_config(load_config({**cfg, "solver": {**cfg["solver"], "batch": 32}}))
    with pytest.raises(CheckpointError, match=r"another scene: its 'batch' is 16 there and 32 here"):
        load_realization(other_batch, ss, path)
    other_net = Scene.from_config(load_config({**cfg, "network": {**cfg["network"], "f_ext": 0.03}}))
    with pytest.raises(CheckpointError, match=r"another scene: its 'loads' is"):
        load_realization(other_net, ss, path)
    with pytest.raises(CheckpointError, match=r"other theta\(t_q\) for this seed"):
        load_realization(fresh_scene(name), np.random.SeedSequence(12), path)


def _flip_middle(data: bytes) -> bytes:
    # 64 bytes inverted inside an array's data: the zip's CRC catches it.
    mid = len(data) // 2
    return data[:mid] + bytes(b ^ 0xFF for b in data[mid: mid + 64]) + data[mid + 64:]


def _shorten_npy_header(data: bytes) -> bytes:
    # The last member's .npy header length, 20 bytes short: numpy still parses the header (its padding
    # goes), reads the data 20 bytes early and stops short of the member's end, where zipfile checks the CRC.
    i = data.rfind(b"\x93NUMPY\x01\x00") + 8
    return data[:i] + bytes([data[i] - 20]) + data[i + 1:]


DAMAGE = {
    "truncated": lambda data: data[: len(data) // 2],
    "npy_header_length": _shorten_npy_header,
    "empty": lambda data: b"",
    "flipped": _flip_middle,
    "text": lambda data: b"not a checkpoint\n",
}


@pytest.mark.parametrize("damage", list(DAMAGE.values()), ids=list(DAMAGE))
def test_truncated_or_corrupt_files_raise_a_checkpoint_error(damage, tmp_path: Path) -> None:
    path = tmp_path / "r.npz"
    _, ss = saved_at_third("vec_straight_tilt_events_fext", path)
    path.write_bytes(damage(path.read_bytes()))
    with pytest.raises(CheckpointError, match=r"cannot be read: it is truncated or corrupt"):
        load_realization(fresh_scene("vec_straight_tilt_events_fext"), ss, path, META)


def test_files_that_are_not_checkpoints_are_refused(tmp_path: Path) -> None:
    ss = np.random.SeedSequence(11)
    scene = fresh_scene("pair_tilt")
    np.save(tmp_path / "one.npy", np.zeros(3))
    with pytest.raises(CheckpointError, match=r"single \.npy array, not a slidernet checkpoint"):
        load_realization(scene, ss, tmp_path / "one.npy")
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(CheckpointError, match=r"not a slidernet checkpoint \(no valid header\)"):
        load_realization(scene, ss, tmp_path / "other.npz")
    # A checkpoint with a missing array names it.
    saved_at_third("pair_tilt", tmp_path / "r.npz")
    arrays = npz_arrays(tmp_path / "r.npz")
    del arrays["buffers/mu"]
    np.savez(tmp_path / "partial.npz", **arrays)
    with pytest.raises(CheckpointError, match=r"inconsistent: it has no array 'buffers/mu'"):
        load_realization(scene, ss, tmp_path / "partial.npz")
    # The surplus of a threshold stream is state: missing, or below mu_d, it is refused.
    arrays = npz_arrays(tmp_path / "r.npz")
    del arrays["surplus/thresholds"]
    np.savez(tmp_path / "no_surplus.npz", **arrays)
    with pytest.raises(CheckpointError, match=r"inconsistent: its threshold streams are \['shs', 'tilt'\], "
                                              r"a realization's are \['shs', 'thresholds', 'tilt'\]"):
        load_realization(scene, ss, tmp_path / "no_surplus.npz")
    arrays = npz_arrays(tmp_path / "r.npz")
    arrays["surplus/tilt"] = np.array([0.6, 0.4])
    np.savez(tmp_path / "bad_surplus.npz", **arrays)
    with pytest.raises(CheckpointError, match=r"inconsistent: the surplus of a threshold stream holds values "
                                              r"that are not finite and > mu_d = 0\.5"):
        load_realization(scene, ss, tmp_path / "bad_surplus.npz")
    # A layout this version does not read.
    arrays = npz_arrays(tmp_path / "r.npz")
    header = json.loads(arrays["header"].tobytes())
    arrays["header"] = np.frombuffer(json.dumps({**header, "version": 99}).encode(), np.uint8)
    np.savez(tmp_path / "future.npz", **arrays)
    with pytest.raises(CheckpointError, match=r"layout version 99; this slidernet reads version 6"):
        load_realization(scene, ss, tmp_path / "future.npz")
    # Checkpoints of the layouts before the per-kernel backends (version 2), before the named
    # state (version 3: slot arrays ist and fst) and before the driving trees and K's block table
    # (version 4: three heap rows), and before sliding away (version 5: no count of the moving
    # nodes) are refused, not misread.
    for old in (2, 3, 4, 5):
        arrays["header"] = np.frombuffer(json.dumps({**header, "version": old}).encode(), np.uint8)
        np.savez(tmp_path / "old.npz", **arrays)
        with pytest.raises(CheckpointError, match=rf"layout version {old}; this slidernet reads version 6"):
            load_realization(scene, ss, tmp_path / "old.npz")
    with pytest.raises(FileNotFoundError):
        load_realization(scene, ss, tmp_path / "missing.npz")


def test_a_failed_save_leaves_the_previous_checkpoint_and_no_temporary_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # No ".npz" suffix: the file is written at exactly the path given.
    path = tmp_path / "r4.ckpt"
    real, _ = saved_at_third("csr_tilt_events_fext", path)
    before = path.read_bytes()
    real.advance(real.step + 5)

    def savez_fails_midway(fh, **arrays):
        fh.write(b"PK\x03\x04 half a zip")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np, "savez", savez_fails_midway)
    with pytest.raises(OSError, match="No space left on device"):
        save_realization(real, path, META)
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["r4.ckpt"]
    assert zipfile.is_zipfile(path)


def test_state_this_module_does_not_know_is_refused(tmp_path: Path) -> None:
    real = Realization(fresh_scene("pair_tilt"), np.random.SeedSequence(11))
    real.new_state = np.zeros(3)
    with pytest.raises(RuntimeError, match=r"\['new_state'\] that Realization.snapshot neither saves"):
        save_realization(real, tmp_path / "r.npz", META)
    assert not (tmp_path / "r.npz").exists()


def test_a_meta_that_is_not_json_is_refused(tmp_path: Path) -> None:
    real = Realization(fresh_scene("pair_tilt"), np.random.SeedSequence(11))
    with pytest.raises(CheckpointError, match=r"meta must be JSON-serializable"):
        save_realization(real, tmp_path / "r.npz", {"config": object()})
