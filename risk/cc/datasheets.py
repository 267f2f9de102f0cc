"""The three C&C datasheets (cut-in, cut-out, deceleration) as CSV and PNG in one call."""

from __future__ import annotations

from pathlib import Path

from hiyari.risk.cc.boundary import (
    Grid,
    SearchOptions,
    cut_in_datasheet,
    cut_out_datasheet,
    decel_datasheet,
)
from hiyari.risk.cc.datasheet_plot import plot_cut_in, plot_cut_out, plot_decel
from hiyari.risk.cc.model import CCParams

_DEFAULT = CCParams()
_VE0_KMH = Grid(10, 130, 1)
_SEARCH = SearchOptions()


def write_datasheets(
    out_dir: str | Path,
    params: CCParams = _DEFAULT,
    ve0_kmh: Grid = _VE0_KMH,
    search: SearchOptions = _SEARCH,
) -> list[Path]:
    """Compute the cut-in, cut-out and deceleration datasheets over ``ve0_kmh`` (default
    10–130 km/h at 1 km/h; cut-in relative speeds 0–60 km/h at 1 km/h, Vy 0.1–3.0 m/s at
    0.1 m/s, boundaries at 0.1 m; deceleration Gx_max 0.01–1.0 g) and write
    ``cut_in_boundary.csv/.png``, ``cut_out_boundary.csv/.png`` and ``decel_map.csv/.png``
    into ``out_dir``. Returns the paths written."""
    out = Path(out_dir)
    cut_in = cut_in_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    cut_out = cut_out_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    decel = decel_datasheet(ve0_kmh=ve0_kmh, params=params, search=search)
    return [
        cut_in.write_csv(out / "cut_in_boundary.csv"),
        plot_cut_in(cut_in, out / "cut_in_boundary.png"),
        cut_out.write_csv(out / "cut_out_boundary.csv"),
        plot_cut_out(cut_out, out / "cut_out_boundary.png"),
        decel.write_csv(out / "decel_map.csv"),
        plot_decel(decel, out / "decel_map.png"),
    ]
