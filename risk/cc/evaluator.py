"""The C&C driver in the three Annex G scenarios, evaluated exactly for arrays of scenarios.

Each ``evaluate_*`` function takes arrays (or scalars, broadcast together) of concrete
scenarios in SI units and returns a :class:`CCResult` of per-scenario arrays: collision
yes/no, minimum gap, time of collision and impact speed. The kinematics are closed-form
(:mod:`hiyari.risk.cc.kinematics`); there is no time stepping.

Scenarios (t = 0 when the other vehicle starts its manoeuvre; geometry in
:mod:`hiyari.risk.cc.model`):

- cut-in: the other vehicle, in the adjacent lane dx0 ahead (ego front to its rear) at Vo0 <=
  Ve0, moves laterally at Vy into the ego lane. The C&C driver judges the cut-in when its
  displacement reaches ``wander_m`` and danger ``perception_time_s`` later (or at
  ``wander_m + danger_lateral_m``); if TTC = gap / (Ve0 - Vo0) is still >= ``ttc_brake_s``
  then, it reacts when TTC falls to it. Braking starts ``reaction_delay_s`` after, ramps to
  ``max_decel_g`` and holds until the ego is down to Vo0.
- cut-out: the ego follows the lead (same speed) at ``thw_s``; a stopped vehicle stands
  dx0_f ahead of the lead's front. The lead moves laterally at Vy into the adjacent lane;
  the C&C driver judges the cut-out at ``wander_m``, danger ``perception_time_s`` later, and
  brakes to a stop ``reaction_delay_s`` after that (no TTC condition: the revealed vehicle is
  stopped).
- deceleration: the ego follows the lead at ``thw_s``; the lead brakes at Gx_max as a step
  (infinite jerk) to a stop; danger judgement ``perception_time_s`` after its brake onset,
  braking ``reaction_delay_s`` later, held to a stop.

With ``params.aeb`` the ego's deceleration is the larger of the driver's and the AEB's.
Contact is judged on lane-aligned rectangles: a collision needs lateral overlap and a
longitudinal overlap of more than ``contact_tol_m``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields

import numpy as np

from hiyari.errors import HiyariError
from hiyari.risk.cc.kinematics import Motion, PiecewiseCubic, max_of_profiles, ramp_knots
from hiyari.risk.cc.model import CCParams

_DEFAULT = CCParams()
CHUNK = 16384  # scenarios per vectorised pass: keeps the (N, K) temporaries in cache


@dataclass(frozen=True)
class CCResult:
    """Per-scenario outcome of the C&C driver, arrays of shape (N,).

    ``collision``: the rectangles overlapped. ``min_gap_m``: the smallest longitudinal gap
    from the ego's front to the obstacle's rear while they overlap laterally; after a
    contact the motions are continued as if the vehicles passed through each other, so for
    a collision it is minus the extra gap the C&C driver would have needed (negative with no
    collision only in a cut-in the ego had fully passed before the other entered its lane). ``t_collision_s``: first contact, s after the manoeuvre start (nan if none).
    ``impact_speed_mps``: the ego's longitudinal speed relative to the obstacle at first
    contact (nan if none). ``t_brake_s``: onset of the ego's braking force (inf if it never
    brakes). ``valid``: False where Annex G excludes the scenario (cut-out: the lead itself
    hits the stopped vehicle); other fields are still computed there.
    """

    collision: np.ndarray
    min_gap_m: np.ndarray
    t_collision_s: np.ndarray
    impact_speed_mps: np.ndarray
    t_brake_s: np.ndarray
    valid: np.ndarray


def _arrays(**named: object) -> list[np.ndarray]:
    """Broadcast the inputs to one 1-D float shape, refusing non-finite values."""
    try:
        arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in named.values()))
    except ValueError as exc:
        shapes = ", ".join(f"{k} {np.shape(v)}" for k, v in named.items())
        raise HiyariError(f"scenario arrays of incompatible shapes: {shapes}") from exc
    out = [np.ascontiguousarray(a, dtype=float).reshape(-1) for a in arrays]
    for name, arr in zip(named, out, strict=True):
        bad = ~np.isfinite(arr)
        if bad.any():
            raise HiyariError(f"{name}: {int(bad.sum())} value(s) not finite, e.g. {arr[bad][0]}")
    return out


def _refuse(mask: np.ndarray, name: str, values: np.ndarray, problem: str) -> None:
    if mask.any():
        raise HiyariError(
            f"{name}: {int(mask.sum())} scenario(s) {problem}, e.g. {values[mask][0]:g}"
        )


def _check_feasible_vy(vy: np.ndarray, vo: np.ndarray, params: CCParams) -> None:
    _refuse(vy <= 0, "vy_mps", vy, "with lateral velocity <= 0 (the manoeuvre never happens)")
    limit = vo * np.tan(np.radians(params.max_heading_deg))
    _refuse(
        vy > limit + 1e-12,
        "vy_mps",
        vy,
        f"with lateral velocity above Vo0 x tan({params.max_heading_deg:g}°): physically "
        "impossible at that speed (Annex G)",
    )


@dataclass(frozen=True)
class ScenarioSetup:
    """What the C&C response needs of N scenarios, before the ego's motion is known.

    ``obstacle``: the motion of the obstacle's rear, with ``offset`` its initial distance
    ahead of the ego's front (m); ``v0``/``v_end``: ego speed at t = 0 and the speed its
    braking stops at (m/s); ``t_brake``: driver's braking onset (s); ``t_overlap``: when the
    two start to overlap laterally (s); ``t_enable_aeb``: from when the AEB may trigger (s);
    ``valid``: inside Annex G.
    """

    obstacle: Motion
    offset: np.ndarray
    v0: np.ndarray
    v_end: np.ndarray
    t_brake: np.ndarray
    t_overlap: np.ndarray
    t_enable_aeb: np.ndarray
    valid: np.ndarray

    def gap(self, ego: Motion) -> PiecewiseCubic:
        """Ego front to obstacle rear (m) under the ego motion ``ego``."""
        return PiecewiseCubic.gap(self.offset, self.obstacle, ego)


def _driver_motion(v0: np.ndarray, v_end: np.ndarray, t_brake: np.ndarray, p: CCParams) -> Motion:
    t, d = ramp_knots(t_brake, p.ramp_time_s, p.max_decel_mps2)
    return Motion.braking(v0, t, d, v_end)


def ego_response(setup: ScenarioSetup, p: CCParams) -> tuple[Motion, np.ndarray]:
    """The C&C ego's motion and the onset of its braking force (s, inf if never).

    Without AEB the ego brakes as the driver does from ``setup.t_brake``. With AEB, the
    trigger is the first time at or after ``t_enable_aeb`` that gap < ``aeb_ttc_s`` x closing
    speed under the driver's motion (never for an obstacle the ego has already fully
    passed); from then the ego decelerates at the larger of the two.
    """
    ego = _driver_motion(setup.v0, setup.v_end, setup.t_brake, p)
    if not p.aeb:
        return ego, setup.t_brake
    gap = setup.gap(ego)
    trigger = gap.plus_derivative(p.aeb_ttc_s).first_negative(setup.t_enable_aeb)
    ahead = gap.value(setup.t_enable_aeb) > -_pass_length(p)
    onset = np.where(ahead, trigger + p.aeb_delay_s, np.inf)
    t_drv, d_drv = ramp_knots(setup.t_brake, p.ramp_time_s, p.max_decel_mps2)
    t_aeb, d_aeb = ramp_knots(onset, p.aeb_ramp_time_s, p.aeb_decel_mps2)
    knots_t, knots_d = max_of_profiles(t_drv, d_drv, t_aeb, d_aeb)
    return Motion.braking(setup.v0, knots_t, knots_d, setup.v_end), np.minimum(setup.t_brake, onset)


def _pass_length(p: CCParams) -> float:
    """Gap at or below which the ego front is past the obstacle's front: fully passed."""
    return p.ego_length_m + p.other_length_m


def outcome(setup: ScenarioSetup, p: CCParams) -> CCResult:
    """Contact between the C&C ego and the obstacle from the overlap time on.

    Contact happens iff the gap goes below ``-contact_tol_m`` after ``t_overlap``, unless the
    ego had already fully passed (gap <= -(ego length + other length)) when the overlap
    began. That is possible only in a cut-in, where the ego never gets slower than the other,
    so a passed ego stays past.
    """
    ego, t_brake = ego_response(setup, p)
    gap = setup.gap(ego)
    gap_in = gap.value(setup.t_overlap)
    min_gap = gap.minimum_after(setup.t_overlap)
    collision = (gap_in > -_pass_length(p)) & (min_gap < -p.contact_tol_m)
    t_hit = np.full(collision.shape, np.nan)
    impact = np.full(collision.shape, np.nan)
    if collision.any():
        rows = np.flatnonzero(collision)
        sub = gap.rows(rows).shifted(p.contact_tol_m)
        t_hit[rows] = sub.first_negative(setup.t_overlap[rows])
        impact[rows] = -sub.derivative_value(t_hit[rows])
    return CCResult(collision, min_gap, t_hit, impact, t_brake, setup.valid)


def run_chunked(
    setup_of: Callable[..., ScenarioSetup], arrays: list[np.ndarray], p: CCParams
) -> CCResult:
    """:func:`outcome` of ``setup_of(*arrays)`` in cache-sized chunks (same result, faster)."""
    n = arrays[0].size
    parts = [
        outcome(setup_of(*(a[i : i + CHUNK] for a in arrays)), p)
        for i in range(0, max(n, 1), CHUNK)
    ]
    if len(parts) == 1:
        return parts[0]
    return CCResult(
        *(np.concatenate([getattr(r, f.name) for r in parts]) for f in dataclass_fields(CCResult))
    )


def cut_in_reaction_time(
    ve0: np.ndarray, vo0: np.ndarray, dx0: np.ndarray, vy: np.ndarray, p: CCParams
) -> np.ndarray:
    """When the C&C driver's reaction delay starts in a cut-in (s), inf if never.

    Danger judgement, or later the instant TTC = dx0 / (Ve0 - Vo0) - t falls to
    ``ttc_brake_s`` (the ego has not braked before, so its speed is still Ve0).
    """
    dv = ve0 - vo0
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ttc = np.where(dv > 0, dx0 / dv - p.ttc_brake_s, np.inf)
    return np.maximum(p.danger_judgement_time(vy), t_ttc)


def cut_in_setup(
    ve0: np.ndarray,
    vo0: np.ndarray,
    dx0: np.ndarray,
    vy: np.ndarray,
    p: CCParams,
    t_react: np.ndarray | None = None,
) -> ScenarioSetup:
    """Cut-in scenarios (no input checks); ``t_react`` overrides the reaction start."""
    if t_react is None:
        t_react = cut_in_reaction_time(ve0, vo0, dx0, vy, p)
    t_overlap = p.cut_in_dy0_m / vy
    return ScenarioSetup(
        obstacle=Motion.constant_speed(vo0),
        offset=dx0,
        v0=ve0,
        v_end=vo0,
        t_brake=t_react + p.reaction_delay_s,
        t_overlap=t_overlap,
        t_enable_aeb=t_overlap,
        valid=np.ones(ve0.shape, bool),
    )


def evaluate_cut_in(ve0_mps, vo0_mps, dx0_m, vy_mps, params: CCParams = _DEFAULT) -> CCResult:
    """C&C driver in cut-in scenarios (arrays or scalars, broadcast).

    ``ve0_mps``: ego speed, ``vo0_mps``: cut-in vehicle's speed (<= ego's, Annex G),
    ``dx0_m``: ego front to its rear (>= 0), ``vy_mps``: its lateral speed (> 0, feasible).
    """
    ve0, vo0, dx0, vy = _arrays(ve0_mps=ve0_mps, vo0_mps=vo0_mps, dx0_m=dx0_m, vy_mps=vy_mps)
    _refuse(ve0 < 0, "ve0_mps", ve0, "with a negative ego speed")
    _refuse(vo0 < 0, "vo0_mps", vo0, "with a negative speed")
    _refuse(vo0 > ve0, "vo0_mps", vo0, "faster than the ego (Annex G excludes such cut-ins)")
    _refuse(dx0 < 0, "dx0_m", dx0, "with a negative initial gap (Annex G: 0 <= dx0)")
    _check_feasible_vy(vy, vo0, params)
    return run_chunked(lambda *a: cut_in_setup(*a, params), [ve0, vo0, dx0, vy], params)


def cut_out_lead_clear_gap(ve0: np.ndarray, vy: np.ndarray, p: CCParams) -> np.ndarray:
    """Smallest dx0_f (m) at which the cutting-out lead (at Ve0) clears the stopped vehicle:
    its side must pass the stopped vehicle's side before its front reaches that rear. Both are
    ``other_width_m`` wide and centred in the ego lane, so the lead must move laterally by
    one width."""
    return ve0 * p.other_width_m / vy


def cut_out_setup(ve0: np.ndarray, vy: np.ndarray, dx0_f: np.ndarray, p: CCParams) -> ScenarioSetup:
    """Cut-out scenarios (no input checks): the obstacle is the stopped vehicle."""
    zeros = np.zeros_like(ve0)
    return ScenarioSetup(
        obstacle=Motion.constant_speed(zeros),
        offset=p.thw_s * ve0 + p.other_length_m + dx0_f,
        v0=ve0,
        v_end=zeros,
        t_brake=p.danger_judgement_time(vy) + p.reaction_delay_s,
        t_overlap=zeros,
        t_enable_aeb=0.5 * (p.ego_width_m + p.other_width_m) / vy,
        valid=dx0_f >= cut_out_lead_clear_gap(ve0, vy, p) - 1e-9,
    )


def evaluate_cut_out(ve0_mps, vy_mps, dx0_f_m, params: CCParams = _DEFAULT) -> CCResult:
    """C&C driver in cut-out scenarios (arrays or scalars, broadcast).

    ``ve0_mps``: ego and lead speed (> 0), ``vy_mps``: the lead's lateral speed (> 0,
    feasible), ``dx0_f_m``: lead front to the stopped vehicle's rear (> 0). The ego follows
    at dx0 = ``thw_s`` x Ve0. ``valid`` is False where the lead itself would hit the stopped
    vehicle (Annex G excludes those gaps).
    """
    ve0, vy, dx0_f = _arrays(ve0_mps=ve0_mps, vy_mps=vy_mps, dx0_f_m=dx0_f_m)
    _refuse(ve0 <= 0, "ve0_mps", ve0, "with ego / lead speed <= 0")
    _refuse(dx0_f <= 0, "dx0_f_m", dx0_f, "with gap to the stopped vehicle <= 0 (Annex G)")
    _check_feasible_vy(vy, ve0, params)
    return run_chunked(lambda *a: cut_out_setup(*a, params), [ve0, vy, dx0_f], params)


def decel_setup(ve0: np.ndarray, gx: np.ndarray, dx0: np.ndarray, p: CCParams) -> ScenarioSetup:
    """Deceleration scenarios (no input checks): the obstacle is the braking lead."""
    zeros = np.zeros_like(ve0)
    return ScenarioSetup(
        obstacle=Motion.step_deceleration(ve0, gx * p.g_mps2),
        offset=dx0,
        v0=ve0,
        v_end=zeros,
        t_brake=np.full(ve0.shape, p.perception_time_s + p.reaction_delay_s),
        t_overlap=zeros,
        t_enable_aeb=zeros,
        valid=np.ones(ve0.shape, bool),
    )


def evaluate_decel(ve0_mps, gx_max_g, params: CCParams = _DEFAULT, dx0_m=None) -> CCResult:
    """C&C driver in deceleration scenarios (arrays or scalars, broadcast).

    ``ve0_mps``: ego and lead speed (> 0), ``gx_max_g``: the lead's deceleration in g
    (0 < Gx_max <= ``road_mu``), ``dx0_m``: ego front to lead rear, default ``thw_s`` x Ve0.
    """
    if dx0_m is None:
        ve0, gx = _arrays(ve0_mps=ve0_mps, gx_max_g=gx_max_g)
        dx0 = params.thw_s * ve0
    else:
        ve0, gx, dx0 = _arrays(ve0_mps=ve0_mps, gx_max_g=gx_max_g, dx0_m=dx0_m)
        _refuse(dx0 < 0, "dx0_m", dx0, "with a negative initial gap")
    _refuse(ve0 <= 0, "ve0_mps", ve0, "with ego / lead speed <= 0")
    _refuse(gx <= 0, "gx_max_g", gx, "with deceleration <= 0 g")
    _refuse(
        gx > params.road_mu,
        "gx_max_g",
        gx,
        f"above the road friction μ = {params.road_mu:g} (outside physics)",
    )
    return run_chunked(lambda *a: decel_setup(*a, params), [ve0, gx, dx0], params)
