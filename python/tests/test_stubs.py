"""The native module's stubs (aemstep/_aemstep.pyi) name every function, argument and
default the extension has, and every exception class."""

import ast
import inspect
from pathlib import Path

import aemstep
from aemstep import _aemstep

STUB = Path(aemstep.__file__).with_name("_aemstep.pyi")


def stub_tree():
    return ast.parse(STUB.read_text())


def test_stub_functions_match_the_extension():
    functions = [n for n in stub_tree().body if isinstance(n, ast.FunctionDef)]
    native = sorted(n for n in dir(_aemstep) if callable(getattr(_aemstep, n))
                    and not isinstance(getattr(_aemstep, n), type))
    assert sorted(f.name for f in functions) == native
    for f in functions:
        sig = inspect.signature(getattr(_aemstep, f.name))
        names = [a.arg for a in f.args.args]
        assert names == list(sig.parameters), f.name
        defaults = [ast.literal_eval(d) for d in f.args.defaults]
        native_defaults = [p.default for p in sig.parameters.values()
                           if p.default is not inspect.Parameter.empty]
        assert defaults == native_defaults, f.name
        assert ast.get_docstring(f), f"{f.name}: no docstring in the stub"
        assert getattr(_aemstep, f.name).__doc__, f"{f.name}: no docstring in the extension"


def test_stub_classes_are_the_exceptions():
    classes = {n.name for n in stub_tree().body if isinstance(n, ast.ClassDef)}
    assert classes == set(aemstep.ERROR_VARIANTS) | {"AemstepError", "ShapeError", "UnsupportedSize", "InvalidArgument"}
