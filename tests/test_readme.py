"""The README's API example must run as written (a new user copies it first)."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _api_example() -> str:
    text = README.read_text(encoding="utf-8")
    section = text.split("## The API in 20 lines", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_api_example_is_at_most_20_lines():
    assert len(_api_example().strip().splitlines()) <= 20


def test_api_example_runs_as_written(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # it writes result.nc in the working directory
    exec(compile(_api_example(), "README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    r_mean, mu_max, mu_eff = (float(x) for x in printed[:3])
    # Eq. `slope` gives 53.6 per tau_th; the simulation sits ~1 % below it.
    assert 50 < r_mean < 56
    assert 0.6 < mu_max < 0.7
    assert 0.5 < mu_eff < 0.7
    assert (tmp_path / "result.nc").exists()


def test_plugin_example_runs_as_written(clean_registries):
    text = README.read_text(encoding="utf-8").split("**Your own plugin.**", 1)[1]
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    from slidernet import registry

    assert registry.distributions.origin("my_uniform") == "run time"
