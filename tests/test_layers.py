"""The package's layout is its data flow: each stage imports only the stages below it, and no cycle.

Stages, from the bottom up (ARCHITECTURE.md draws the same map):

0. ``errors``, ``_validation``, ``_version``, ``_paths``: exceptions, shared input checks, the version and
   the digest of the code, paths;
1. ``kernels``: the compiled loops (numba), which import nothing else;
2. ``model``: networks, their builders, physical units;
3. ``plugins``: distributions of mu_s, drivers, their registry and contract;
4. ``config``: the validated configuration;
5. ``solver``: scene, random streams, realizations;
6. ``io``: files, the checkpoint folder, checkpoints of a realization;
7. ``analysis``: the result dataset and its statistics, theory, pictures;
8. ``ensemble``: ``run``, execution, sweeps;
9. ``paper``, ``validation``: the reproduction, and tools that check the solver;
10. the package's front (``__init__``, ``cli``, ``testing``).

Every import counts, deferred ones inside functions included.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import slidernet

ROOT = Path(slidernet.__file__).parent
RANK = {"errors": 0, "_validation": 0, "_version": 0, "_paths": 0, "kernels": 1, "model": 2, "plugins": 3,
        "config": 4, "solver": 5, "io": 6, "analysis": 7, "ensemble": 8, "paper": 9, "validation": 9,
        "__init__": 10, "__main__": 10, "cli": 10, "testing": 10}


def _stage(module: str) -> str:
    """The stage of ``slidernet.a.b``: its first component (the package itself is its front)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] == "slidernet"]
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "slidernet":
            if node.module == "slidernet":  # from slidernet import x: x is a stage
                found += [f"slidernet.{a.name}" for a in node.names]
            else:
                found.append(node.module)
    return found


MODULES = sorted(p for p in ROOT.rglob("*.py"))


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    return ".".join(rel.parts)


@pytest.mark.parametrize("path", MODULES, ids=[_module_name(p) for p in MODULES])
def test_imports_point_down(path):
    me = _module_name(path)
    mine = RANK[_stage(me)]
    up = [m for m in _imports(path) if RANK.get(_stage(m), 10) > mine]
    assert not up, f"{me} (stage {mine}) imports up the layers: {up}"


def test_every_stage_is_ranked():
    stages = {_stage(_module_name(p)) for p in MODULES}
    assert stages <= set(RANK), stages - set(RANK)


# The values of ``solver.kernel``. The configuration checks and picks them (config/run.py: the key's checks;
# config/rules.py: choose_kernel, the one rule), the scene checks an explicit choice against its network, and
# solver/backends.py maps the choice to a backend (BACKENDS); no other module may branch on one.
KERNEL_NAMES = {"pair", "csr", "vec"}
ALLOWED = {"config/run.py", "solver/scene.py", "solver/backends.py"}


def _kernel_name_comparisons(path: Path) -> list[int]:
    """Lines of ``path`` that compare something with a kernel's name (==, !=, in, match cases)."""
    lines = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare):
            names = [c for c in [node.left, *node.comparators] if isinstance(c, ast.Constant)]
            names += [e for c in node.comparators if isinstance(c, (ast.Tuple, ast.List, ast.Set)) for e in c.elts
                      if isinstance(e, ast.Constant)]
            if any(c.value in KERNEL_NAMES for c in names):
                lines.append(node.lineno)
        elif isinstance(node, ast.MatchValue) and isinstance(node.value, ast.Constant):
            if node.value.value in KERNEL_NAMES:
                lines.append(node.lineno)
    return lines


def test_only_the_configuration_and_the_backend_table_branch_on_a_kernel_name():
    found = {str(p.relative_to(ROOT)): lines for p in sorted(ROOT.rglob("*.py"))
             if str(p.relative_to(ROOT)) not in ALLOWED and (lines := _kernel_name_comparisons(p))}
    assert found == {}, f"branches on a kernel's name outside {sorted(ALLOWED)}: {found}"


def test_the_kernel_name_scan_finds_a_branch(tmp_path):
    # The scan itself can fail: a planted branch is found.
    planted = tmp_path / "planted.py"
    planted.write_text('if scene.kernel == "vec":\n    pass\nok = kernel in ("csr", "other")\n')
    assert _kernel_name_comparisons(planted) == [1, 3]


def _graph() -> dict[str, set[str]]:
    """Module -> the slidernet modules it imports (every import: deferred, and for type hints only)."""
    names = {_module_name(p).removesuffix(".__init__"): p for p in MODULES}
    graph = {}
    for name, path in names.items():
        targets = set()
        for m in _imports(path):
            # "from slidernet.a import b" may name a module a.b or a name in a; either way a is imported.
            while m not in names and "." in m:
                m = m.rsplit(".", 1)[0]
            if m in names and m != name:
                targets.add(m)
        graph[name] = targets
    return graph


def test_no_import_cycle_between_modules():
    # Within a stage too, and even through an import for type hints only (ARCHITECTURE.md): a cycle
    # makes a module's meaning depend on which of the two is imported first.
    graph = _graph()
    cycles = []
    state: dict[str, int] = {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycles.append([*path[path.index(nxt):], nxt])
            elif nxt not in state:
                visit(nxt, [*path, nxt])
        state[node] = 2

    for start in sorted(graph):
        if start not in state:
            visit(start, [start])
    assert not cycles, cycles


# A module a reader can hold in mind: past this, split it by subject (ARCHITECTURE.md lists the modules).
MAX_LINES = 800


def test_no_module_is_over_800_lines():
    lines = {_module_name(p): len(p.read_text(encoding="utf-8").splitlines()) for p in MODULES}
    long = {name: n for name, n in lines.items() if n > MAX_LINES}
    assert long == {}, f"modules over {MAX_LINES} lines (split them by subject): {long}"
