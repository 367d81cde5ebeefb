"""The Python package's imports: no circle among its modules, counting the imports inside functions
(an import moved into a function hides a circle, it does not break it), and every import inside a
function says why it is there (a comment on its line or the line above).

Read from the sources (no module is imported): a module's imports are its ``import``/``from``
statements, at module level and inside functions; ``from sins_fw import x`` names the module
``sins_fw.x`` when there is one (the binding ``sins_fw._core`` is below every module). Importing a
module of a subpackage from outside it runs the subpackage's ``__init__`` first, so it imports that
too (``sins_fw.cli.common`` from ``sins_fw.broad_eval`` imports ``sins_fw.cli``, which imports every
command).
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "sins_fw"


def modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Module name → source file, for every module of the package."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def imported(node: ast.Import | ast.ImportFrom, module: str, path: Path, known: set[str]) -> list[str]:
    """The package's modules an import statement in ``module`` (file ``path``) names."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name in known]
    base = node.module or ""
    if node.level:
        here = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
        base = ".".join(here[: len(here) - node.level + 1] + ([node.module] if node.module else []))
    subs = [f"{base}.{a.name}" for a in node.names]
    names = [base] if base in known and any(s not in known and s != "sins_fw._core" for s in subs) else []
    return [s for s in subs if s in known] + names


def entered(target: str, module: str, known: set[str]) -> list[str]:
    """What importing ``target`` from ``module`` runs: ``target`` and the ``__init__`` of each package
    above it that ``module`` is not itself inside."""
    parts = target.split(".")
    packages = [".".join(parts[:n]) for n in range(2, len(parts))]
    return [target] + [p for p in packages if p in known and not module.startswith(p + ".") and module != p]


def graph(package: Path = PACKAGE) -> tuple[dict[str, set[str]], list[tuple[str, int, bool]]]:
    """Every module's imports of the package's modules, and each import inside a function as
    (module, line, whether a comment gives its reason)."""
    mods = modules(package)
    known = set(mods)
    edges: dict[str, set[str]] = {m: set() for m in mods}
    local = []
    for module, path in mods.items():
        source = path.read_text(encoding="utf-8")
        lines = source.splitlines()
        tree = ast.parse(source)
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in imported(node, module, path, known):
                    edges[module].update(t for t in entered(target, module, known) if t != module)
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(fn):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    own = lines[node.lineno - 1 : (node.end_lineno or node.lineno)]
                    above = lines[node.lineno - 2].strip() if node.lineno > 1 else ""
                    commented = any("#" in line for line in own) or above.startswith("#")
                    local.append((module, node.lineno, commented))
    return edges, local


def cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """A circle of imports, as the modules on it, or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        if state.get(node) == 2:
            return None
        if state.get(node) == 1:
            return [*path[path.index(node) :], node]
        state[node] = 1
        path.append(node)
        for nxt in sorted(edges.get(node, ())):
            found = visit(nxt)
            if found:
                return found
        path.pop()
        state[node] = 2
        return None

    for m in sorted(edges):
        found = visit(m)
        if found:
            return found
    return None


def test_no_import_circle() -> None:
    edges, _ = graph()
    assert cycle(edges) is None


def test_imports_inside_functions_say_why() -> None:
    _, local = graph()
    bare = [f"{m}:{line}" for m, line, commented in local if not commented]
    assert bare == [], "imports inside functions without a comment saying why"


def test_the_checks_catch_a_hidden_circle_and_a_bare_import(tmp_path: Path) -> None:
    """A circle closed by an import inside a function is found, and so is its missing comment; a
    commented one passes the comment rule."""
    pkg = tmp_path / "sins_fw"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from sins_fw import b\n")
    (pkg / "b.py").write_text("def f():\n    from sins_fw.a import x\n\n\ndef g():\n    import json  # why\n")
    edges, local = graph(pkg)
    assert cycle(edges) == ["sins_fw.a", "sins_fw.b", "sins_fw.a"]
    assert local == [("sins_fw.b", 2, False), ("sins_fw.b", 6, True)]
    (pkg / "b.py").write_text("import json\n")
    assert cycle(graph(pkg)[0]) is None


def test_a_subpackage_module_imports_the_subpackage(tmp_path: Path) -> None:
    """A module that imports ``pkg.sub.m`` runs ``pkg/sub/__init__.py``: when that imports the module
    back, it is a circle (the subpackage's own modules importing each other are not)."""
    pkg = tmp_path / "sins_fw"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("from sins_fw import a\n")
    (pkg / "sub" / "m.py").write_text("from sins_fw.sub import n\n")
    (pkg / "sub" / "n.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from sins_fw.sub.m import x  # why\n")
    assert cycle(graph(pkg)[0]) == ["sins_fw.a", "sins_fw.sub", "sins_fw.a"]
    (pkg / "sub" / "__init__.py").write_text("")
    assert cycle(graph(pkg)[0]) is None
