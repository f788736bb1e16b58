"""The package's shape, checked on its source (DESIGN.md, "Contributions"; docs/theory.md, "Architecture").

* no import cycle among the package's modules (imports inside functions count);
* contact, output and the scene never name a concrete part class, and nothing outside
  ``parts/`` asks ``isinstance`` of one: they use the part protocol and ``Surface``;
* PETSc objects are made in ``assembly/petsc.py`` only (through ``_dolfinx.py`` where
  DOLFINx's C++ layer makes them), and DOLFINx's private API is used in ``_dolfinx.py`` only;
* no module reads another module's private attributes.
"""
import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "dolfinx_corot"
MODULES = {".".join(p.relative_to(ROOT.parent).with_suffix("").parts).removesuffix(".__init__"): p
           for p in ROOT.rglob("*.py")}
PART_CLASSES = {"Part", "LineFrame", "Frame2D", "Frame3D", "Surface3D", "Shell3D", "MembraneQuad", "Solid",
                "Coupled", "Rotations3D"}


def _source(name: str) -> str:
    return MODULES[name].read_text()


def _imports(name: str) -> set[str]:
    """Package modules that module ``name`` imports (anywhere in it), with the packages on the way
    (importing a.b.c runs a.b's __init__), the root package's __init__ excepted."""
    path = MODULES[name]
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        targets = []
        if isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else [])) if node.level else node.module
            targets = [f"{module}.{a.name}" for a in node.names] + [module]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        for t in targets:
            if t in MODULES:
                parts = t.split(".")
                found |= {".".join(parts[:k]) for k in range(2, len(parts) + 1)}
    ancestors = {".".join(name.split(".")[:k]) for k in range(1, len(name.split(".")))}
    return {m for m in found if m in MODULES and m != name and m not in ancestors}


def _find_cycle(graph: dict[str, set[str]]) -> list[str]:
    """A cycle of the directed graph (a list of nodes, first = last), or []."""
    state: dict[str, int] = {}

    def visit(m, path):
        state[m] = 1
        for d in sorted(graph.get(m, ())):
            if state.get(d) == 1:
                return path[path.index(d):] + [d] if d in path else [m, d]
            if state.get(d) is None:
                found = visit(d, path + [d])
                if found:
                    return found
        state[m] = 2
        return []

    for m in sorted(graph):
        if state.get(m) is None:
            found = visit(m, [m])
            if found:
                return found
    return []


def test_no_import_cycle():
    cycle = _find_cycle({m: _imports(m) for m in MODULES})
    assert not cycle, "import cycle: " + " -> ".join(cycle)


def test_the_checker_sees_imports_and_cycles():
    """The cycle test is not vacuous: the graph has the edges a reader sees (lazy imports too),
    and a cycle is found."""
    assert "dolfinx_corot.assembly" in _imports("dolfinx_corot.solvers.run")
    assert "dolfinx_corot.parts.surface" in _imports("dolfinx_corot.contact.laws")
    assert _find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert _find_cycle({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("name", sorted(m for m in MODULES if not m.startswith("dolfinx_corot.parts")))
def test_no_concrete_part_class_outside_parts(name):
    tree = ast.parse(_source(name))
    named = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} | \
            {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
    bad = sorted(named & (PART_CLASSES - {"Part", "Coupled"}))
    if name.startswith("dolfinx_corot.contact") or name.startswith("dolfinx_corot.io"):
        bad += sorted(named & {"Part", "Coupled"})
    assert not bad, f"{name} names part classes {bad}: use the part protocol (parts/base.py) and Surface"
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance":
            classes = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
            assert not classes & PART_CLASSES, f"{name}: isinstance on a part class"


CREATION = re.compile(r"PETSc\.(Mat|Vec|KSP|NullSpace|LGMap)\(\)|create_(matrix|vector|petsc_vector)\(|"
                      r"(?<!petsc)\.duplicate\(|\.convert\(")
PRIVATE_DOLFINX = re.compile(r"dolfinx\.cpp|_cpp_object|petsc\._[a-z]")


@pytest.mark.parametrize("name", sorted(MODULES))
def test_petsc_objects_are_made_in_one_module(name):
    allowed = {"dolfinx_corot.assembly.petsc", "dolfinx_corot._dolfinx"}
    code = "\n".join(line.split("#")[0] for line in _source(name).splitlines())
    if name not in allowed:
        assert not CREATION.search(code), f"{name} makes PETSc objects: {CREATION.search(code).group(0)}"
    if name != "dolfinx_corot._dolfinx":
        assert not PRIVATE_DOLFINX.search(code), f"{name} uses DOLFINx's private API"


def _private_reads(name: str) -> list[str]:
    """``obj._field`` for obj other than self/cls/super() whose field the module does not define."""
    tree = ast.parse(_source(name))
    own = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name)
           and n.value.id in ("self", "cls")} | \
          {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    out = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Attribute) and n.attr.startswith("_") and not n.attr.startswith("__"):
            base = n.value
            if isinstance(base, ast.Name) and base.id in ("self", "cls"):
                continue
            if isinstance(base, ast.Call) and getattr(base.func, "id", None) == "super":
                continue
            if n.attr not in own:
                out.append(f"{ast.unparse(n)} (line {n.lineno})")
    return out


@pytest.mark.parametrize("name", sorted(set(MODULES) - {"dolfinx_corot._dolfinx"}))
def test_no_reads_of_other_modules_private_fields(name):
    assert not _private_reads(name), f"{name} reads private fields of other modules: {_private_reads(name)}"
