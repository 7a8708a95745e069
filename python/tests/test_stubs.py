# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""The type stubs (lumx/_lumx.pyi) name every public class, function, method and property of the
extension, and the extension every one the stubs name, so editors complete what exists. Every public
function, method and property has a docstring."""
import ast
from pathlib import Path

import lumx
from lumx import _lumx

STUBS = Path(__file__).resolve().parents[1] / "lumx" / "_lumx.pyi"


def stub_names():
    tree = ast.parse(STUBS.read_text(encoding="utf-8"))
    top, members = set(), {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            top.add(node.name)
            names = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
            names |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
            members[node.name] = {m for m in names if not m.startswith("_")}
        elif isinstance(node, ast.FunctionDef):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            top.add(node.target.id)
    return top, members


def runtime_members(cls):
    return {n for n in vars(cls) if not n.startswith("_")}


def test_stubs_match_the_extension():
    top, members = stub_names()
    public = {n for n in vars(_lumx) if not n.startswith("_")} | {"__version__"}
    assert public - top - {"__version__"} == set(), "missing from the stubs"
    assert {n for n in top if not n.startswith("_")} - public - {"ArrayLike", "PathLike", "FloatArray", "Vec3",
                                                                  "ChunkLike", "RaysArgument"} == set()
    for name, names in members.items():
        cls = getattr(_lumx, name)
        if issubclass(cls, BaseException):
            continue  # attributes set on instances
        assert runtime_members(cls) == names, name
    assert set(lumx.__all__) <= public


def test_every_public_call_is_documented():
    for name in dir(_lumx):
        obj = getattr(_lumx, name)
        if name.startswith("_") or not callable(obj):
            continue
        assert obj.__doc__, name
        if isinstance(obj, type) and not issubclass(obj, BaseException):
            for m, member in vars(obj).items():
                if m.startswith("_"):
                    continue
                doc = member.__doc__ if not isinstance(member, property) else member.fget.__doc__ or member.__doc__
                assert doc, f"{name}.{m}"
