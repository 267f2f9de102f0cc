"""Scenario files: expansion of logical ranges, and clear errors for bad files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from paths import REPO_ROOT

from hiyari.bridge.openscenario.presets.toml_file import load_scenario
from hiyari.errors import HiyariError

SCENARIOS = REPO_ROOT / "bridge" / "openscenario" / "presets" / "library"


def _write(tmp_path, text: str) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


def test_grid_expansion(tmp_path):
    p = _write(
        tmp_path,
        """
[scenario]
type = "cut-in"
seed = 10
[parameters]
ve0_kmh = 60
vo0_kmh = { range = [10, 50], step = 20 }
dx0_m = { values = [10, 25] }
vy_ms = 1.0
""",
    )
    runs = load_scenario(p).expand()
    assert len(runs) == 6
    assert [(r.params["vo0_kmh"], r.params["dx0_m"]) for r in runs] == [
        (10, 10),
        (10, 25),
        (30, 10),
        (30, 25),
        (50, 10),
        (50, 25),
    ]
    assert [r.seed for r in runs] == list(range(10, 16))
    assert all(r.params["ve0_kmh"] == 60 and r.params["vy_ms"] == 1.0 for r in runs)


def test_random_sampling_is_seeded(tmp_path):
    text = """
[scenario]
type = "decel"
[parameters]
ve0_kmh = { uniform = [40, 120] }
gx_max_g = { values = [0.5, 1.0] }
[sampling]
mode = "random"
n = 20
seed = %d
"""
    a = load_scenario(_write(tmp_path, text % 3)).expand()
    b = load_scenario(_write(tmp_path, text % 3)).expand()
    c = load_scenario(_write(tmp_path, text % 4)).expand()
    assert [r.params for r in a] == [r.params for r in b] != [r.params for r in c]
    assert all(40 <= r.params["ve0_kmh"] <= 120 for r in a) and len(a) == 20


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ('[scenario]\ntype = "cut-in"\ncolour = "red"', "scenario.colour: unknown key"),
        ('[scenario]\ntype = "warp"', "scenario.type: unknown type 'warp'"),
        ("[weather]\nrain = 1", "weather: unknown section"),
        (
            '[scenario]\ntype = "cut-in"\n[parameters]\nve0_kmh = 60\nvo0_kmh = 20\ndx0_m = 30',
            "parameters.vy_ms: missing",
        ),
        (
            '[scenario]\ntype = "cut-in"\n[parameters]\nve0_kmh = -60\nvo0_kmh = 20\ndx0_m = 30\nvy_ms = 1',
            "parameters.ve0_kmh: -60 is outside",
        ),
        (
            '[scenario]\ntype = "cut-in"\n[parameters]\nve0_kmh = 60\nvo0_kmh = 20\ndx0_m = 30\nvy_ms = 0',
            "parameters.vy_ms: 0 is outside",
        ),
        (
            '[scenario]\ntype = "decel"\nduration = -1\n[parameters]\nve0_kmh = 60\ngx_max_g = 0.5',
            "scenario.duration: must be positive",
        ),
        (
            '[scenario]\ntype = "decel"\n[parameters]\nve0_kmh = "fast"\ngx_max_g = 0.5',
            "parameters.ve0_kmh: expected a number",
        ),
        (
            '[scenario]\ntype = "decel"\n[ego]\nperception = "psychic"\n[parameters]\nve0_kmh = 60\ngx_max_g = 0.5',
            "ego.perception: unknown 'psychic'",
        ),
        ('[scenario\ntype = "decel"', "not valid TOML"),
    ],
)
def test_bad_files_name_file_and_key(tmp_path, text, needle):
    p = _write(tmp_path, text)
    with pytest.raises(HiyariError) as exc:
        load_scenario(p)
    assert str(p) in str(exc.value) and needle in str(exc.value)


def test_cli_reports_bad_scenario_in_one_line(tmp_path):
    p = _write(tmp_path, '[scenario]\ntype = "cut-in"\nspeed = 3')
    proc = subprocess.run(
        [sys.executable, "-m", "hiyari", "run", str(p)], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 1
    assert proc.stderr.strip().splitlines() == [
        f"hiyari: error: {p}: scenario.speed: unknown key (known: duration, name, seed, step_length, type)"
    ]


def test_shipped_scenarios_parse():
    files = sorted(SCENARIOS.glob("*.toml"))
    assert len(files) >= 3
    for f in files:
        assert load_scenario(f).expand()
