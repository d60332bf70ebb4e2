"""The type stubs describe the module as it is, and everything has a docstring."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pmvc
import pmvc._native as native

STUBS = Path(pmvc.__file__).with_name("_native.pyi")


def stub_names():
    tree = ast.parse(STUBS.read_text())
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    classes = {
        node.name: {item.name for item in node.body if isinstance(item, ast.FunctionDef)}
        for node in tree.body
        if isinstance(node, ast.ClassDef)
    }
    return functions, classes


def test_stubs_name_every_function_class_and_attribute_of_the_module():
    functions, classes = stub_names()
    public = {name for name in dir(native) if not name.startswith("_")}
    assert functions | set(classes) == public
    for name, members in classes.items():
        runtime = {m for m in dir(getattr(native, name)) if not m.startswith("_")}
        assert members - {"__init__"} == runtime, name


def test_everything_public_has_a_docstring_and_a_signature():
    for name in pmvc.__all__:
        value = getattr(pmvc, name)
        if callable(value):
            assert inspect.getdoc(value), name
    for cls in (pmvc.Cage, pmvc.Weights):
        for member in dir(cls):
            if not member.startswith("_"):
                assert inspect.getdoc(getattr(cls, member)), f"{cls.__name__}.{member}"
    assert str(inspect.signature(pmvc.bind)) == (
        "(points, cage, method='pmvc', resolution=32, grid=None, poisson_ratio=0.0, backend='auto', progress=None, triangulate=None,"
        " pmvc_kernel='auto', strict=False, dtype='float32')"
    )
