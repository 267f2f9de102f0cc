"""A SUMO configuration naming a file the file system cannot even look up is one line."""

from __future__ import annotations

import pytest

from hiyari.errors import HiyariError
from hiyari.traffic.sumocfg import read_sumocfg


def test_a_name_too_long_for_the_file_system_is_one_line(tmp_path):
    cfg = tmp_path / "run.sumocfg"
    name = "x" * 300  # longer than NAME_MAX (255) on Linux file systems
    cfg.write_text(f'<configuration><input><net-file value="{name}"/></input></configuration>')
    with pytest.raises(HiyariError) as exc:
        read_sumocfg(cfg)
    msg = str(exc.value)
    assert msg.startswith(f"{cfg}: net-file names xxx") and "\n" not in msg
    assert len(msg) < len(str(cfg)) + 140
