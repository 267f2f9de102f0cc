"""The package layers of docs/architecture.md, checked on the source: a package imports only
packages below it, only traffic/ imports libsumo, only the CLI picks matplotlib's backend."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

from paths import REPO_ROOT

ROOT = REPO_ROOT
LAYER = {"hiyari": 0, "net": 1, "traffic": 2, "sensors": 3, "risk": 3, "bridge": 4}
#: bridge's wings, bottom to top (equal numbers: side by side, neither imports the other)
BRIDGE_LAYER = {"openscenario": 0, "record": 0, "loop": 1, "replay": 1, "studies": 2, "cli": 3}


@functools.cache  # parsed once for the tests of this file (they only read the trees)
def _modules() -> list[tuple[str, Path, ast.Module]]:
    out = []
    for pkg in LAYER:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            out.append((pkg, path, ast.parse(path.read_text(encoding="utf-8"))))
    return out


def _imported(tree: ast.Module) -> list[str]:
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
    return names


def _package_of(module: str) -> str | None:
    parts = module.split(".")
    if parts[0] != "hiyari":
        return None
    return parts[1] if len(parts) > 1 and parts[1] in LAYER else "hiyari"


def test_packages_import_only_layers_below():
    bad = []
    for pkg, path, tree in _modules():
        if path.name == "__main__.py":  # `python -m hiyari` is the CLI's entry, above everything
            continue
        for name in _imported(tree):
            other = _package_of(name)
            if other is None or other == pkg:
                continue
            if LAYER[other] >= LAYER[pkg]:
                bad.append(f"{path.relative_to(ROOT)} imports {name}")
    assert not bad, "\n".join(bad)


def _wing_of(module: str) -> str | None:
    parts = module.split(".")
    if parts[:2] != ["hiyari", "bridge"] or len(parts) < 3:
        return None
    return parts[2]


def test_bridge_wings_import_only_wings_below():
    """Inside bridge/: openscenario and record at the bottom, then loop and replay, then
    studies, then cli; a wing imports only wings below it (or itself)."""
    wings = set(BRIDGE_LAYER)
    found = {p.name for p in (ROOT / "bridge").iterdir() if (p / "__init__.py").is_file()}
    assert found == wings, f"bridge wings {sorted(found)} are not the layered ones {sorted(wings)}"
    bad = []
    for pkg, path, tree in _modules():
        if pkg != "bridge" or path.parent == ROOT / "bridge":
            continue
        wing = path.relative_to(ROOT / "bridge").parts[0]
        for name in _imported(tree):
            other = _wing_of(name)
            if other is None or other == wing:
                continue
            if BRIDGE_LAYER[other] >= BRIDGE_LAYER[wing]:
                bad.append(f"{path.relative_to(ROOT)} imports {name}")
    assert not bad, "\n".join(bad)


def test_only_traffic_imports_libsumo():
    bad = [
        str(path.relative_to(ROOT))
        for pkg, path, tree in _modules()
        if pkg != "traffic"
        and any(n.split(".")[0] in ("libsumo", "_libsumo", "traci") for n in _imported(tree))
    ]
    assert not bad, bad


def test_only_the_cli_picks_the_matplotlib_backend():
    bad = []
    for _, path, tree in _modules():
        rel = path.relative_to(ROOT)
        for node in ast.walk(tree):
            is_use = (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr == "use"
                and isinstance(node.func.value, ast.Name)
                and node.func.value.id == "matplotlib"
            )
            if is_use and rel.parts[:2] != ("bridge", "cli"):
                bad.append(str(rel))
    assert not bad, bad


def test_only_the_report_and_the_cli_import_matplotlib():
    """Plots and pages are drawn in bridge/studies/report (and the CLI's demo); every other
    module computes and writes data."""
    bad = []
    for _, path, tree in _modules():
        rel = path.relative_to(ROOT)
        if rel.parts[:3] == ("bridge", "studies", "report") or rel.parts[:2] == ("bridge", "cli"):
            continue
        for node in ast.walk(tree):
            names = (
                [a.name for a in node.names] if isinstance(node, ast.Import)
                else [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            )  # fmt: skip
            if any(n == "matplotlib" or n.startswith("matplotlib.") for n in names):
                bad.append(str(rel))
    assert not bad, sorted(set(bad))


def _package_folders() -> list[Path]:
    return sorted(
        init.parent
        for pkg in LAYER
        for init in (ROOT / pkg).rglob("__init__.py")
        if "__pycache__" not in init.parts
    )


def test_every_package_folder_is_installed_and_none_is_crowded():
    """pyproject's package list is the tree (a missing entry installs editable but not from a
    wheel) and its data folders (listed with their files, so setuptools does not warn), and no
    folder holds more than a dozen modules (split it into wings)."""
    import tomllib

    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setuptools["packages"])
    folders = {
        "hiyari" if f.name == "hiyari" else "hiyari." + ".".join(f.relative_to(ROOT).parts)
        for f in _package_folders()
    }
    data = set(setuptools["package-data"])
    assert folders == listed - data and not data - listed
    crowded = {
        str(f.relative_to(ROOT)): n
        for f in _package_folders()
        if (n := len([p for p in f.glob("*.py") if p.name != "__init__.py"])) > 12
    }
    assert not crowded


def test_readme_layout_names_every_wing():
    """The README's layout block names every sub-package down to two levels."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## Layout", 1)[1].split("```")[1]
    missing = [
        str(f.relative_to(ROOT))
        for f in _package_folders()
        if len(f.relative_to(ROOT).parts) <= 2 and f"{f.name}/" not in block
    ]
    assert not missing
