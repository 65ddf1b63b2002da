"""The module's surface: type stubs shipped beside it that match it, docstrings everywhere."""
import ast
import inspect
from pathlib import Path

import chaintube

STUB = Path(chaintube.__file__).with_name("chaintube.pyi")
ALIASES = {"PathLike", "Vector3", "Quaternion", "Points"}  # the stub's own type aliases


def stub_tree():
    assert STUB.is_file(), f"no type stubs beside the module: {STUB}"
    return ast.parse(STUB.read_text())


def test_the_stubs_name_every_public_name_of_the_module_and_nothing_else():
    names = set()
    for node in stub_tree().body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(target.id for target in node.targets)
    public = {name for name in dir(chaintube) if not name.startswith("_")}
    assert names - ALIASES == public


def test_the_stubs_list_every_method_and_property_of_each_class():
    classes = {node.name: node for node in stub_tree().body if isinstance(node, ast.ClassDef)}
    for name, node in classes.items():
        cls = getattr(chaintube, name)
        if issubclass(cls, BaseException) or name.endswith("List"):
            continue  # exceptions; the lists behave as Python lists (pybind11's bind_vector)
        stubbed = {item.name for item in node.body if isinstance(item, ast.FunctionDef)}
        stubbed |= {item.target.id for item in node.body if isinstance(item, ast.AnnAssign)}
        stubbed |= {t.id for item in node.body if isinstance(item, ast.Assign)
                    for t in item.targets}
        own = {member for member in vars(cls) if not member.startswith("_")}
        if name == "Status":
            own -= {"name", "value"}  # enum.Enum's, as the stub declares it
        assert own <= stubbed, f"{name}: not in the stubs: {sorted(own - stubbed)}"


def test_every_public_class_function_method_and_property_has_a_docstring():
    undocumented = []
    for name in dir(chaintube):
        if name.startswith("_"):
            continue
        item = getattr(chaintube, name)
        if not inspect.getdoc(item):
            undocumented.append(name)
        if inspect.isclass(item) and not issubclass(item, BaseException) and \
                not name.endswith("List"):
            for member, value in vars(item).items():
                if member.startswith("_") or (name == "Status" and member in ("name", "value")):
                    continue
                if isinstance(value, property) or callable(value):
                    if not (inspect.getdoc(value) or "").strip():
                        undocumented.append(f"{name}.{member}")
    assert not undocumented, f"without a docstring: {undocumented}"


def test_help_on_hose_reads_like_its_header():
    text = inspect.getdoc(chaintube.Hose)
    assert "axis points" in text and "stretch" in text and "UpdateResult" in text
    assert "world metres" in inspect.getdoc(chaintube.Hose.grab)
