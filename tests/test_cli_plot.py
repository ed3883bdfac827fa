"""``slidernet plot`` and ``python -m slidernet``: the standard panels of a result, their theory, bad input."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import xarray as xr

import slidernet
from slidernet.analysis import theory
from slidernet.analysis.plots import non_default_options, plot_result, theory_overlays
from slidernet.cli import main
from slidernet.config import load_config
from slidernet.errors import ResultError
from slidernet.io import read_result, result_config, write_netcdf

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _config(network: dict[str, Any], steps: int, realizations: int, observables: list[str]) -> dict[str, Any]:
    return {
        "seed": 4,
        "realizations": realizations,
        "steps": steps,
        "observables": observables,
        "network": {**network, "Ntilde": 1e-7},
        "friction": {"mu_d": 0.5, "static": {"name": "gaussian", "mean": 0.6, "std": 0.01}},
        "driver": {"name": "gaussian_steps", "sigma_theta": 1e-6},
    }


@pytest.fixture(scope="session")
def results(tmp_path_factory) -> dict[str, Path]:
    """Small result files: the paper's pair with the tilt test, a chain and a triangular lattice."""
    folder = tmp_path_factory.mktemp("plot")
    scenes = {
        "pair": _config({"kind": "two_slider"}, 300, 3, ["n", "mu_max", "x_G", "mu_eff"]),
        "chain": _config({"kind": "chain", "n": 6}, 20, 2, ["n", "mu_max", "x_G"]),
        "lattice": _config({"kind": "triangular", "shape": [5, 5]}, 10, 2, ["n", "mu_max", "x_G", "mu_eff"]),
    }
    return {name: write_netcdf(slidernet.run(cfg, progress=False), folder / f"{name}.nc")
            for name, cfg in scenes.items()}


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _line(ax, label_start: str):
    (line,) = [ln for ln in ax.get_lines() if ln.get_label().startswith(label_start)]
    return line


# --------------------------------------------------------------------------
# The command
# --------------------------------------------------------------------------


@pytest.mark.parametrize("scene", ["pair", "chain", "lattice"])
def test_plot_writes_a_png_beside_the_result(results, scene, capsys):
    png = results[scene].with_suffix(".png")
    png.unlink(missing_ok=True)
    assert main(["plot", str(results[scene])]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {png}"
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert not [p for p in png.parent.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize(("out", "written"),
                         [("picture.pdf", "picture.pdf"), ("sub/picture.svg", "sub/picture.svg"),
                          (".", "pair.png")],
                         ids=["pdf", "new-folder-svg", "folder"])
def test_plot_out_chooses_the_path_and_format(results, tmp_path, out, written, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["plot", str(results["pair"]), "--out", out]) == 0
    path = tmp_path / written
    assert capsys.readouterr().out.strip() == f"wrote {Path(out) / 'pair.png' if out == '.' else Path(out)}"
    head = path.read_bytes()[:5]
    assert head == {"pdf": b"%PDF-", "svg": b"<?xml", "png": PNG_MAGIC[:5]}[path.suffix[1:]]


def test_python_dash_m_slidernet_is_the_command(capsys):
    with pytest.raises(SystemExit):
        main(["--version"])
    expected = capsys.readouterr().out
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(Path(slidernet.__file__).parent.parent), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "slidernet", "--version"], env=env, capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout == expected == f"slidernet {slidernet.__version__}\n"


def test_paper_help_states_the_time_and_memory_of_a_full_run(capsys):
    """Where the command is, its cost: the measured wall time and memory of the full preset."""
    import slidernet.cli

    with pytest.raises(SystemExit):
        slidernet.cli.main(["paper", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "102 s of wall time (183 s of CPU)" in help_text and "0.90 GB" in help_text


# --------------------------------------------------------------------------
# The figure: panels, theory
# --------------------------------------------------------------------------


def test_pair_panels_carry_the_measured_means_and_the_theory(results):
    ds = read_result(results["pair"])
    fig = plot_result(ds)
    assert len(fig.axes) == 4
    n_ax, mu_ax, msd_ax, eff_ax = fig.axes
    assert [ax.get_ylabel().split(" (")[0] for ax in fig.axes] == [
        "$n$", r"$\mu_\mathrm{max}$", r"$\langle x_G^2\rangle$", r"$\mu_\mathrm{eff}$"]
    assert all(ax.get_xscale() == "log" for ax in fig.axes)
    t = ds["t"].values
    pos = t > 0
    np.testing.assert_array_equal(_line(mu_ax, "mean").get_ydata(), ds["mu_max_mean"].values[pos])
    np.testing.assert_array_equal(_line(msd_ax, "mean").get_ydata(), ds["x_G2_mean"].values[pos])
    np.testing.assert_array_equal(_line(eff_ax, "pooled").get_ydata(), ds["mu_eff"].values[pos])
    # The exact mean of the max of n + 2 draws at the measured mean n(t), from the result's own law.
    dist = load_config(result_config(ds)).distribution()
    exact = theory.mu_max_moments(dist, ds["n_mean"].values)[0][pos]
    np.testing.assert_allclose(_line(mu_ax, "exact").get_ydata(), exact, rtol=1e-12)
    leading = theory.mu_max_leading(0.6, 0.01, float(ds["r_mean"]) * t[pos])
    np.testing.assert_allclose(_line(mu_ax, "eq. (mumaxth)").get_ydata(), leading, rtol=1e-12)
    r_slope = float(theory.mean_rearrangements(1e-6, 1e-7, 0.5, 0.6))
    np.testing.assert_allclose(_line(n_ax, "eq. (slope)").get_ydata(), r_slope * t[pos], rtol=1e-9)
    np.testing.assert_allclose(_line(msd_ax, "law").get_ydata(),
                               theory.msd(1e-6, float(ds["r_mean"]) * t[pos]), rtol=1e-12)


@pytest.mark.parametrize(("scene", "n_axes"), [("chain", 6), ("lattice", 8)], ids=["chain", "lattice"])
def test_network_panels_add_the_slip_map_and_mu_s_field_without_pair_theory(results, scene, n_axes):
    ds = read_result(results[scene])
    fig = plot_result(ds)
    # 4 time panels, the slip map and the mu_s field (in 2D each with its colorbar).
    assert len(fig.axes) == n_axes
    assert fig.axes[4].get_title().startswith("slips per node")
    assert fig.axes[5 if scene == "chain" else 6].get_title().startswith(r"static threshold $\mu_s$")
    legend = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "eq. (mumaxth): not drawn (two sliders only)" in legend
    assert [ln.get_label() for ln in fig.axes[1].get_lines() if len(ln.get_xdata())] == [
        "mean over 2 realizations $\\pm$ s.e."]  # the data, no theory line


def test_a_missing_observable_gets_a_note_instead_of_a_panel(results):
    fig = plot_result(results["chain"])  # no mu_eff recorded
    eff = fig.axes[3]
    assert not eff.axison and not eff.get_lines()
    assert 'add "mu_eff"' in eff.texts[0].get_text()


def test_theory_overlays_say_why_a_law_is_not_drawn(results):
    ds = read_result(results["pair"])
    cfg = result_config(ds)
    cfg["friction"]["static"] = {"name": "uniform", "low": 0.55, "high": 0.65}
    cfg["driver"]["sigma_theta"] = 4e-8  # below mu_d Ntilde: eq. slope gives <r> < 0
    overlays = theory_overlays(ds, load_config(cfg))
    assert overlays["mu_max_leading"].values is None
    assert overlays["mu_max_leading"].legend == "eq. (mumaxth): not drawn (Gaussian p(mu_s) only)"
    assert overlays["n"].values is None and r"\leq 0" in overlays["n"].reason
    assert overlays["mu_max_exact"].values is not None  # exact for any law
    uniform = load_config(cfg).distribution()
    np.testing.assert_allclose(overlays["mu_max_exact"].values,
                               theory.mu_max_moments(uniform, ds["n_mean"].values)[0], rtol=1e-12)


# --------------------------------------------------------------------------
# Bad input: exit 2, the file and what is wrong named, nothing written
# --------------------------------------------------------------------------


def test_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "nothing.nc")]) == 2
    assert "nothing.nc' does not exist" in capsys.readouterr().err
    assert _files(tmp_path) == []


def test_not_netcdf(tmp_path, capsys):
    (tmp_path / "notes.nc").write_text("not a result\n")
    assert main(["plot", str(tmp_path / "notes.nc")]) == 2
    assert "notes.nc' is not a readable netCDF file" in capsys.readouterr().err
    assert _files(tmp_path) == ["notes.nc"]


def test_not_a_slidernet_result(tmp_path, capsys):
    write_netcdf(xr.Dataset({"temperature": ("time", np.arange(3.0))}), tmp_path / "other.nc")
    assert main(["plot", str(tmp_path / "other.nc")]) == 2
    err = capsys.readouterr().err
    assert "other.nc' is not a result of slidernet run: it has no 't' and no 'n' and no 'n_mean'" in err
    assert "It holds: temperature." in err
    assert _files(tmp_path) == ["other.nc"]


def test_a_sweep_is_refused(results):
    ds = read_result(results["pair"])
    swept = xr.concat([ds, ds], dim="sigma_theta")
    with pytest.raises(ResultError, match=r"more than one run: its 'n' has dims .*\['sigma_theta'\].*isel"):
        plot_result(swept)


def test_unknown_format_writes_nothing(results, tmp_path, capsys):
    assert main(["plot", str(results["pair"]), "--out", str(tmp_path / "picture.bmp")]) == 2
    assert "suffix '.bmp', which matplotlib cannot write" in capsys.readouterr().err
    assert _files(tmp_path) == []


def test_the_picture_never_replaces_the_result(results, tmp_path, capsys):
    copy = tmp_path / "result.png"  # a result file with the picture's name
    copy.write_bytes(results["pair"].read_bytes())
    assert main(["plot", str(copy)]) == 2
    assert "would replace the result file" in capsys.readouterr().err
    assert copy.read_bytes() == results["pair"].read_bytes()


# --------------------------------------------------------------------------
# --show
# --------------------------------------------------------------------------


def test_show_without_a_window_is_refused(results, capsys):
    import matplotlib.pyplot as plt

    plt.switch_backend("agg")
    png = results["pair"].with_suffix(".png")
    png.unlink(missing_ok=True)
    assert main(["plot", str(results["pair"]), "--show"]) == 2
    assert "--show needs a window, and matplotlib's backend 'agg' cannot open one" in capsys.readouterr().err
    assert not png.exists()


def test_show_draws_in_a_pyplot_figure_and_writes_nothing(results, monkeypatch, capsys):
    import matplotlib.pyplot as plt

    import slidernet.cli

    plt.switch_backend("agg")
    shown = []
    monkeypatch.setattr(slidernet.cli, "_non_interactive_backends", list)  # pretend agg opens windows
    monkeypatch.setattr(plt, "show", lambda: shown.append(len(plt.gcf().axes)))
    png = results["pair"].with_suffix(".png")
    png.unlink(missing_ok=True)
    try:
        assert main(["plot", str(results["pair"]), "--show"]) == 0
    finally:
        plt.close("all")
    assert shown == [4]
    assert capsys.readouterr().out == ""
    assert not png.exists()


def test_the_laws_of_the_papers_slip_are_not_drawn_for_another_overshoot(results):
    ds = read_result(results["pair"])
    cfg = result_config(ds)
    cfg["friction"]["overshoot"] = 0.5
    overlays = theory_overlays(ds, load_config(cfg))
    for key in ("n", "x_G2"):
        assert overlays[key].values is None and "friction.overshoot = 1" in overlays[key].reason
    assert overlays["mu_max_exact"].values is not None  # the law of the max of n + 2 draws does not use the slip


# --------------------------------------------------------------------------
# The title: every option that is not the default; the contact-age panel
# --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def strengthened_pair() -> xr.Dataset:
    """A pair with a damped slip and ageing thresholds, recording the contact age."""
    cfg = _config({"kind": "two_slider"}, 30, 2, ["n", "mu_max", "x_G", "contact_age"])
    cfg["friction"].update(overshoot=0.5, strengthening={"beta": 0.02, "tau_c": 3.0})
    return slidernet.run(cfg, progress=False)


def test_the_title_names_every_option_that_is_not_the_default(strengthened_pair):
    title = plot_result(strengthened_pair)._suptitle.get_text()
    assert "overshoot 0.5" in title
    assert "strengthening beta=0.02, tau_c=3" in title


def test_a_default_run_has_no_line_of_options(results):
    title = plot_result(results["pair"])._suptitle.get_text()
    assert title.count("\n") == 1 and "options" not in title


def test_non_default_options_are_read_from_the_models(strengthened_pair):
    cfg = result_config(strengthened_pair)
    cfg["record"] = "all"
    assert dict(non_default_options(load_config(cfg))) == {
        "record": "record all", "friction.overshoot": "overshoot 0.5",
        "friction.strengthening": "strengthening beta=0.02, tau_c=3"}
    del cfg["friction"]["overshoot"], cfg["friction"]["strengthening"]
    cfg.update(dynamics={"tau_ratio": 1e-3}, observables=["n"])
    assert dict(non_default_options(load_config(cfg))) == {"record": "record all",
                                                           "dynamics": "dynamics tau_ratio=0.001"}


def test_a_result_with_contact_age_gets_its_panel(strengthened_pair, results):
    fig = plot_result(strengthened_pair)
    ax = fig.axes[4]
    assert ax.get_ylabel().startswith("contact age")
    mean = strengthened_pair["contact_age_mean"].values
    np.testing.assert_allclose(_line(ax, "mean over 2").get_ydata(), mean[strengthened_pair["t"].values > 0])
    assert len(plot_result(results["pair"]).axes) == 4  # no contact age recorded: no panel
