"""The package's modules import one another without cycles.

The graph is read from the source with :mod:`ast`, the imports inside functions counted
(a cycle through a function-level import still ties two modules together: neither can be
read, tested or replaced without the other). An edge goes from a module to each module it
imports: relative imports resolved against the importing module's package, and
``from X import name`` to ``X.name`` where that is a module of the package, else to ``X``.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = "parapend"


def modules(root: Path, package: str = PACKAGE) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of ``package`` under ``root``."""
    out = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def import_graph(mods: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (itself left out)."""
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for name, path in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        base = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    target = base
                    for _ in range(node.level - 1):
                        target = target.rpartition(".")[0]
                    if node.module:
                        target = f"{target}.{node.module}"
                else:
                    target = node.module or ""
                found = [f"{target}.{a.name}" if f"{target}.{a.name}" in mods else target
                         for a in node.names]
            elif isinstance(node, ast.Import):
                found = [a.name for a in node.names]
            else:
                continue
            edges[name].update(m for m in found if m in mods and m != name)
    return edges


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_the_graph_resolves_relative_imports_names_and_function_level_imports(tmp_path):
    """The reader itself, on a small package with one cycle through a function-level import:
    ``from . import b`` goes to the module ``pkg.b``, ``from .c import f`` to ``pkg.c``
    (``f`` is no module), ``from ..pkg import sub`` to the subpackage."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    files = {"__init__.py": "", "a.py": "from . import b\n",
             "b.py": "def g():\n    from .c import f\n",
             "c.py": "import os\nfrom .a import x\nf = 1\n",
             "d.py": "from .sub import e\nimport pkg.c\n",
             "sub/__init__.py": "from ..c import f\n", "sub/e.py": "from .. import d\n"}
    for rel, text in files.items():
        (pkg / rel).write_text(text)
    edges = import_graph(modules(tmp_path, "pkg"))
    assert edges["pkg.a"] == {"pkg.b"} and edges["pkg.b"] == {"pkg.c"}
    assert edges["pkg.c"] == {"pkg.a"}
    assert edges["pkg.d"] == {"pkg.sub.e", "pkg.c"} and edges["pkg.sub"] == {"pkg.c"}
    assert edges["pkg.sub.e"] == {"pkg.d"}
    assert cycles(edges) == [["pkg.a", "pkg.b", "pkg.c"], ["pkg.d", "pkg.sub.e"]]


def test_no_import_cycle():
    """No cycle in the import graph of parapend (imports inside functions counted)."""
    found = cycles(import_graph(modules(SRC)))
    assert not found, f"import cycles: {found}"
