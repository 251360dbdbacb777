"""The type stubs shipped in the package (weft/__init__.pyi) name what the module has, and the
module has nothing public they do not name (mypy is not a dependency, so this is the check)."""

import ast
import inspect
import os

import pytest

import weft

STUB = os.path.join(os.path.dirname(weft.__file__), "__init__.pyi")


def stub_tree():
    with open(STUB) as f:
        return ast.parse(f.read())


def stubbed_names(body):
    """Functions, classes and annotated attributes of a module or class body (type aliases aside)."""
    names = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node
    return names


def test_the_stubs_and_the_marker_ship_with_the_package():
    assert os.path.isfile(STUB)
    assert os.path.isfile(os.path.join(os.path.dirname(weft.__file__), "py.typed"))


def test_every_stubbed_name_exists(small_cloth):
    instances = {"Cloth": small_cloth}  # a pure-Python class: its attributes are set per instance
    for name, node in stubbed_names(stub_tree().body).items():
        assert hasattr(weft, name), "stubbed but missing from weft: %s" % name
        if isinstance(node, ast.ClassDef):
            cls = getattr(weft, name)
            assert inspect.isclass(cls), name
            for member in stubbed_names(node.body):
                assert hasattr(instances.get(name, cls), member), "stubbed but missing: weft.%s.%s" % (name, member)


def test_every_public_name_is_stubbed():
    stubs = stubbed_names(stub_tree().body)
    public = set(weft.__all__) | {"Warning", "__version__"}
    assert sorted(public - set(stubs)) == []
    for name in public:
        obj = getattr(weft, name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            members = {m for m in dir(obj) if not m.startswith("_")}
            assert sorted(members - set(stubbed_names(stubs[name].body))) == [], name


@pytest.mark.parametrize("name", ["gen", "render", "validate", "measure_beam", "window_stats", "local_fields",
                                  "render_study", "render_matrix", "fit_albedo"])
def test_long_calls_are_stubbed_with_threads_and_progress(name):
    node = stubbed_names(stub_tree().body)[name]
    args = {a.arg for a in node.args.args + node.args.kwonlyargs}
    assert {"threads", "progress"} <= args
