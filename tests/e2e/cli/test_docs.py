"""The README and the documentation site: the site builds, links resolve, commands parse."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys

import pytest
from paths import REPO_ROOT

from hiyari.bridge.cli.main import build_parser

ROOT = REPO_ROOT
README = (ROOT / "README.md").read_text()


def test_the_site_builds_strict(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    for page in ("index.html", "guide/openscenario/index.html", "determinism/index.html"):
        assert (tmp_path / page).stat().st_size > 1000, page


def test_readme_is_short_and_its_links_resolve():
    assert len(README.splitlines()) < 400
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if not link.startswith("http")]
    assert len(local) > 10
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing


def _readme_commands() -> list[list[str]]:
    blocks = re.findall(r"```sh\n(.*?)```", README, flags=re.S)
    lines = [ln.split("  #")[0].strip() for b in blocks for ln in b.splitlines()]
    return [shlex.split(ln)[1:] for ln in lines if ln.startswith("hiyari ")]


@pytest.mark.parametrize("argv", _readme_commands(), ids=" ".join)
def test_readme_commands_parse(argv, capsys):
    """Each `hiyari ...` line of the README names a real command with real options."""
    args = build_parser().parse_args(argv)
    assert callable(args.func)


def test_readme_files_exist():
    """Files the README's commands read from the repository are there."""
    for argv in _readme_commands():
        for arg in argv:
            if arg.startswith(("bridge/", "examples/")):
                assert (ROOT / arg).is_file(), arg
