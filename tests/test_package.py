"""The package as a whole: its public API, a core that imports only numpy, scipy and the standard library,
and no code path that evaluates or unpickles what it reads."""

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

import symfruit
import symfruit.core
import symfruit.io
import symfruit.methods

PACKAGE = Path(symfruit.__file__).resolve().parent

PUBLIC = {
    "DEFAULT_CAMERA", "Box", "Camera", "ConfigError", "FileFormatError", "InputError", "OutputError", "Plane", "Result",
    "Settings", "SymfruitError", "SymfruitWarning", "__version__", "available_methods", "box_iou", "centre_deviation",
    "complete",
    "load_settings",
    "resolve_settings",
}  # fmt: skip


def test_the_public_api():
    assert set(symfruit.__all__) == PUBLIC and len(symfruit.__all__) == len(PUBLIC)
    namespace: dict = {}
    exec("from symfruit import *", namespace)
    assert PUBLIC - {"__version__"} <= set(namespace)
    assert isinstance(symfruit.__version__, str) and symfruit.__version__
    assert callable(symfruit.complete) and isinstance(symfruit.DEFAULT_CAMERA, symfruit.Camera)
    assert {"fused", "paper", "sphere", "ellipsoid", "raw"} <= set(symfruit.available_methods())


@pytest.mark.parametrize("module", [symfruit.core, symfruit.io, symfruit.methods])
def test_every_listed_name_exists(module):
    missing = [name for name in module.__all__ if not hasattr(module, name)]
    assert not missing and len(set(module.__all__)) == len(module.__all__)


def test_every_error_is_a_symfruit_error_and_a_value_error():
    for cls in (symfruit.InputError, symfruit.FileFormatError, symfruit.ConfigError, symfruit.OutputError):
        assert issubclass(cls, symfruit.SymfruitError) and issubclass(cls, ValueError)
    from symfruit.settings import SettingError

    assert issubclass(SettingError, symfruit.ConfigError)


#: What a module of symfruit.core may import.
CORE_ALLOWED = {"numpy", "scipy"} | set(sys.stdlib_module_names)
#: The one core module that imports an optional extra: the compiled kernels (numba, the extra ``fast``), which
#: ``symfruit.core.kernels`` imports only when a fit first asks for a kernel (importing the core loads no numba:
#: the test below).
CORE_EXTRAS = {"_jit.py": {"numba"}}


def core_imports() -> dict[str, list[str]]:
    """Per core module, every module it imports (absolute names; ``..errors`` as ``symfruit.errors``)."""
    out = {}
    for path in sorted((PACKAGE / "core").glob("*.py")):
        names = []
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names += [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level == 0:
                    names.append(node.module)
                elif node.level == 1:
                    names.append(f"symfruit.core.{node.module}" if node.module else "symfruit.core")
                else:
                    names.append(f"symfruit.{node.module}" if node.module else "symfruit")
        out[path.name] = names
    return out


def test_the_core_imports_only_numpy_scipy_the_standard_library_and_the_errors():
    imports = core_imports()
    assert {"box.py", "camera.py", "fits.py", "planes.py", "points.py", "raster.py", "rating.py",
            "symmetry.py"} <= set(imports)  # fmt: skip
    for module, names in imports.items():
        for name in names:
            top = name.split(".")[0]
            ok = top in CORE_ALLOWED | CORE_EXTRAS.get(module, set()) or name == "symfruit.errors"
            ok = ok or name.startswith("symfruit.core")
            assert ok, f"symfruit/core/{module} imports {name}"


#: Imports ``symfruit.core`` without running ``symfruit/__init__.py`` (which loads the whole package) and
#: prints every module that importing it loaded, with its file (None for modules made at run time).
_LOAD_CORE = """
import json, sys, types
before = set(sys.modules)
package = types.ModuleType("symfruit")
package.__path__ = [sys.argv[1]]
sys.modules["symfruit"] = package
import symfruit.core
print(json.dumps({m: getattr(sys.modules[m], "__file__", None) for m in sorted(set(sys.modules) - before)}))
"""


def test_importing_the_core_loads_nothing_else_of_symfruit_and_no_other_library():
    import os

    import numpy
    import scipy

    done = subprocess.run([sys.executable, "-c", _LOAD_CORE, str(PACKAGE)], capture_output=True, text=True,
                          check=True, timeout=120)  # fmt: skip
    loaded = json.loads(done.stdout)
    ours = {m for m in loaded if m.split(".")[0] == "symfruit"}
    assert ours - {"symfruit", "symfruit.errors"} == {m for m in ours if m.startswith("symfruit.core")}
    assert {"symfruit.core.fits", "symfruit.core.rating", "symfruit.errors"} <= ours
    allowed = [Path(numpy.__file__).parent, Path(scipy.__file__).parent, PACKAGE / "core", PACKAGE / "errors.py"]
    stdlib = Path(os.__file__).resolve().parent

    def acceptable(file: str) -> bool:
        path = Path(file).resolve()
        if any(path.is_relative_to(root.resolve()) for root in allowed):
            return True
        installed = {"site-packages", "dist-packages"} & set(path.parts)  # another library, wherever it is
        return path.is_relative_to(stdlib) and not installed

    elsewhere = {m: f for m, f in loaded.items() if f is not None and not acceptable(f)}
    assert not elsewhere, f"importing symfruit.core loaded modules from elsewhere: {elsewhere}"
    assert {m.split(".")[0] for m in loaded} >= {"numpy", "scipy"}
    assert not {"yaml", "PIL", "plyfile", "symfruit.settings", "symfruit.io"} & set(loaded)


def test_no_eval_or_pickle_anywhere():
    import re

    src = Path(__file__).resolve().parents[1] / "src" / "symfruit"
    text = "\n".join(p.read_text() for p in src.rglob("*.py"))
    assert not re.search(r"(?<![.\w])(eval|exec)\(", text)
    assert not re.search(r"import pickle|pickle\.load|allow_pickle=True|yaml\.load\(|yaml\.unsafe_load", text)
    assert text.count("allow_pickle=False") >= 2 and "weights_only=True" in text


def test_no_module_is_shadowed_by_an_attribute_of_its_package():
    """``import symfruit.a.b as m`` gives the module: no function or class of ``symfruit.a`` is called ``b``."""
    import importlib
    import pkgutil

    shadowed = []
    for info in pkgutil.walk_packages(symfruit.__path__, "symfruit."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        parent, _, name = info.name.rpartition(".")
        if getattr(sys.modules[parent], name) is not module:
            shadowed.append(info.name)
    assert not shadowed
