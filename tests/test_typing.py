"""The typed API: stubs of the native module and py.typed ship with the package, name every
public thing the module has, and every native class and property is documented."""

import ast
import inspect
from importlib import metadata, resources

import ssrlab
from ssrlab import _core


def _stub_tree() -> ast.Module:
    return ast.parse((resources.files("ssrlab") / "_core.pyi").read_text())


def test_stubs_and_py_typed_are_installed():
    assert (resources.files("ssrlab") / "py.typed").is_file()
    assert (resources.files("ssrlab") / "_core.pyi").is_file()
    files = {str(f) for f in metadata.files("ssrlab")}
    assert any(f.endswith("ssrlab/py.typed") for f in files) and any(f.endswith("ssrlab/_core.pyi") for f in files)


def test_stubs_name_every_public_class_function_method_and_property():
    tree = _stub_tree()
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    hint = "regenerate python/ssrlab/_core.pyi with cpp/bindings/make_stubs.py"
    for name, obj in vars(_core).items():
        if name.startswith("_") or inspect.ismodule(obj):
            continue
        if inspect.isclass(obj):
            assert name in classes, f"class {name} missing from the stubs; {hint}"
            stub_members = {n.name for n in classes[name].body if isinstance(n, ast.FunctionDef)} | {
                t.target.id for t in classes[name].body if isinstance(t, ast.AnnAssign)}
            members = [m for m in vars(obj) if not m.startswith("_")]
            init = vars(obj).get("__init__")
            # A bound constructor (classes built only by factories or the renderer have none).
            if init is not None and type(init).__name__ != "wrapper_descriptor" and not issubclass(obj, Exception):
                members.append("__init__")
            # RenderSettings' properties are made from cpp/render/settings_fields.def, one per
            # setting; its stub covers them with a typed __getattr__ (ssrlab.Settings is the typed face).
            schema = {e["name"] for e in _core.settings_schema()} if name == "RenderSettings" else set()
            for member in members:
                if member in schema and "__getattr__" in stub_members:
                    continue
                assert member in stub_members, f"{name}.{member} missing from the stubs; {hint}"
        elif callable(obj):
            assert name in functions, f"function {name} missing from the stubs; {hint}"


def test_every_native_class_and_property_has_a_docstring():
    undocumented = []
    for name, obj in vars(_core).items():
        if name.startswith("_") or not inspect.isclass(obj):
            continue
        doc = obj.__doc__ or ""
        if not doc.strip() or (issubclass(obj, Exception) and doc == Exception.__doc__):
            undocumented.append(name)
        for member, value in vars(obj).items():
            if isinstance(value, property) and not (value.__doc__ or "").strip():
                undocumented.append(f"{name}.{member}")
    assert not undocumented, f"no docstring: {undocumented}"


def test_render_settings_properties_document_units_from_settings():
    doc = _core.RenderSettings.width.__doc__
    assert "pixels" in doc and "image width" in doc


def test_version_comes_from_package_metadata():
    assert ssrlab.__version__ == metadata.version("ssrlab")
