"""The C&C driver in the three Annex G scenarios, evaluated exactly for arrays of scenarios.

Each ``evaluate_*`` function takes arrays (or scalars, broadcast together) of concrete
scenarios in SI units and returns a :class:`CCResult` of per-scenario arrays: collision
yes/no, minimum gap, time of collision and impact speed. The kinematics are closed-form
(:mod:`hiyari.risk.cc.kinematics`); there is no time stepping.

Scenarios (t = 0 when the other vehicle starts its manoeuvre; geometry in
:mod:`hiyari.risk.cc.model`):

- cut-in: the other vehicle, in the adjacent lane dx0 ahead (ego front to its rear) at Vo0 <=
  Ve0, moves laterally at Vy into the ego lane. The C&C driver judges danger as
  ``params.judgement`` says (default: ``perception_time_s`` after its displacement reaches
  ``wander_m``). If the other car is then beside the ego (gap <= 0) it does not brake for it;
  if TTC = gap / (Ve0 - Vo0) is still >= ``ttc_brake_s`` the cut-in is not critical and the
  scenario ends there (default; with ``above_ttc="wait"`` it reacts when TTC falls to it).
  Braking starts
  ``reaction_delay_s`` after the reaction, ramps to ``max_decel_g`` and holds until the ego
  is down to Vo0. The driver judges on the lane-aligned gap (Annex G's point mass); contact
  is judged on the rectangles (:mod:`hiyari.risk.cc.contact`).
- cut-out: the ego follows the lead (same speed) at ``thw_s``; a stopped vehicle stands
  dx0_f ahead of the lead's front. The lead moves laterally at Vy into the adjacent lane;
  the C&C driver judges the cut-out at ``wander_m``, danger ``perception_time_s`` later
  (``cut_out_perception``), and brakes to a stop ``reaction_delay_s`` after that (no TTC
  condition: the revealed vehicle is stopped).
- deceleration: the ego follows the lead at ``thw_s``; the lead brakes at Gx_max as a step
  (infinite jerk) to a stop; danger judgement ``perception_time_s`` after its brake onset
  (``decel_perception``), braking ``reaction_delay_s`` later, held to a stop.

With ``params.aeb`` the ego's deceleration is the larger of the driver's and the AEB's.
A collision needs the obstacle's rectangle, clipped to the ego's lateral band, to overlap the
ego longitudinally by more than ``contact_tol_m``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields

import numpy as np
from numpy.typing import ArrayLike

from hiyari.errors import HiyariError
from hiyari.risk.cc.contact import CutInContact, cut_in_contact
from hiyari.risk.cc.kinematics import Motion, PiecewiseCubic, max_of_profiles, ramp_knots
from hiyari.risk.cc.model import CCParams

_DEFAULT = CCParams()
CHUNK = 16384  # scenarios per vectorised pass: keeps the (N, K) temporaries in cache


@dataclass(frozen=True)
class CCResult:
    """Per-scenario outcome of the C&C driver, arrays of shape (N,).

    ``collision``: the rectangles overlapped. ``min_gap_m``: the smallest longitudinal gap
    from the ego's front to the nearest point of the obstacle inside the ego's width while
    they overlap laterally (the gap when the scenario ends if they never do); after a contact
    the motions are continued as if the vehicles passed through each other, so for a
    collision it is minus the extra gap the C&C driver would have needed (negative with no
    collision only in a cut-in the ego had fully passed before the other entered its lane).
    ``t_collision_s``: first contact, s after the manoeuvre start (nan if none).
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

    ``obstacle``: the motion of the obstacle's rear as the driver judges it (lane-aligned),
    with ``offset`` its initial distance ahead of the ego's front (m); ``contact_rear`` /
    ``contact_front``: the nearest / farthest x of the obstacle inside the ego's lateral band
    (m, absolute, valid from ``t_overlap``); ``v0``/``v_end``: ego speed at t = 0 and the
    speed its braking stops at (m/s); ``t_brake``: driver's braking onset (s); ``t_overlap``:
    when the two start to overlap laterally (s); ``t_end``: when the scenario ends (s, inf =
    never); ``t_enable_aeb``: from when the AEB may trigger (s); ``valid``: inside Annex G;
    ``front_monotone``: ``contact_rear`` is never faster than the ego's slowest speed, except
    for a jump forward at ``t_jump`` (s), so the front gap can only shrink between jumps.
    """

    obstacle: Motion
    offset: np.ndarray
    contact_rear: Motion
    contact_front: Motion
    v0: np.ndarray
    v_end: np.ndarray
    t_brake: np.ndarray
    t_overlap: np.ndarray
    t_end: np.ndarray
    t_enable_aeb: np.ndarray
    valid: np.ndarray
    front_monotone: np.ndarray
    t_jump: np.ndarray

    def gap(self, ego: Motion, rows: np.ndarray | None = None) -> PiecewiseCubic:
        """Ego front to obstacle rear (m, lane-aligned) under the ego motion ``ego`` (of the
        given rows only)."""
        if rows is None:
            return PiecewiseCubic.gap(self.offset, self.obstacle, ego)
        return PiecewiseCubic.gap(self.offset[rows], self.obstacle.rows(rows), ego.rows(rows))


def _lane_aligned_setup(
    obstacle: Motion, offset: np.ndarray, p: CCParams, **rest: np.ndarray
) -> ScenarioSetup:
    """A setup whose obstacle is a lane-aligned rectangle in the ego's lane."""
    rear = obstacle.shifted(offset)
    return ScenarioSetup(
        obstacle=obstacle,
        offset=offset,
        contact_rear=rear,
        contact_front=rear.shifted(np.full(offset.shape, p.other_length_m)),
        front_monotone=np.zeros(offset.shape, bool),
        t_jump=np.full(offset.shape, np.inf),
        **rest,
    )


def _driver_motion(v0: np.ndarray, v_end: np.ndarray, t_brake: np.ndarray, p: CCParams) -> Motion:
    t, d = ramp_knots(t_brake, p.ramp_time_s, p.max_decel_mps2)
    return Motion.braking(v0, t, d, v_end)


def ego_response(setup: ScenarioSetup, p: CCParams) -> tuple[Motion, np.ndarray]:
    """The C&C ego's motion and the onset of its braking force (s, inf if never).

    Without AEB the ego brakes as the driver does from ``setup.t_brake``. With AEB, the
    trigger is the first time at or after ``t_enable_aeb`` that gap < ``aeb_ttc_s`` x closing
    speed under the driver's motion, for an obstacle still ahead of the ego's front then (an
    AEB does not brake for a car beside the ego); from then the ego decelerates at the
    larger of the two.
    """
    ego = _driver_motion(setup.v0, setup.v_end, setup.t_brake, p)
    if not p.aeb:
        return ego, setup.t_brake
    gap = setup.gap(ego)
    trigger = gap.plus_derivative(p.aeb_ttc_s).first_negative(setup.t_enable_aeb)
    ahead = (gap.value(setup.t_enable_aeb) >= 0) & (trigger <= setup.t_end)
    onset = np.where(ahead, trigger + p.aeb_delay_s, np.inf)
    t_drv, d_drv = ramp_knots(setup.t_brake, p.ramp_time_s, p.max_decel_mps2)
    t_aeb, d_aeb = ramp_knots(onset, p.aeb_ramp_time_s, p.aeb_decel_mps2)
    knots_t, knots_d = max_of_profiles(t_drv, d_drv, t_aeb, d_aeb)
    return Motion.braking(setup.v0, knots_t, knots_d, setup.v_end), np.minimum(setup.t_brake, onset)


def outcome(setup: ScenarioSetup, p: CCParams) -> CCResult:
    """Contact between the C&C ego and the obstacle within [t_overlap, t_end].

    With ``front`` = obstacle's nearest point in the ego's band - ego front and ``back`` =
    ego rear - its farthest point, contact at t means both are below ``-contact_tol_m``; as
    front + back <= -ego length, one of them is. So an ego not yet past the nearest point at
    ``t_overlap`` collides iff ``front`` falls below the tolerance later; an ego already past
    the farthest one (it passed before the other entered its band) collides iff ``back``
    does (the other's corner sweeping into the ego's side); one that is neither is hit at once.
    """
    ego, t_brake = ego_response(setup, p)
    tol = p.contact_tol_m
    t0, t1 = setup.t_overlap, setup.t_end
    n = t0.size
    in_time = t0 <= t1
    t0q = np.where(in_time, t0, 0.0)
    min_gap = np.empty(n)
    never = ~in_time
    if never.any():
        min_gap[never] = setup.gap(ego, never).value(t1[never])
    fast = in_time & setup.front_monotone
    if fast.any():
        min_gap[fast] = _monotone_front_minimum(setup, ego, fast)
    slow = np.flatnonzero(in_time & ~fast)
    if slow.size:
        front = _front_gap(setup, ego, slow)
        min_gap[slow] = front.minimum_between(t0[slow], t1[slow])
    front0 = setup.contact_rear.state_at(t0q)[0] - ego.state_at(t0q)[0]
    beside = in_time & (front0 < -tol)
    collision = ~beside & in_time & (min_gap < -tol)
    t_hit = np.full(n, np.nan)
    if collision.any():
        rows = np.flatnonzero(collision)
        t_hit[rows] = _front_gap(setup, ego, rows).shifted(tol).first_negative(t0[rows])
    if beside.any():
        rows = np.flatnonzero(beside)
        back = PiecewiseCubic.gap(
            np.full(rows.size, -p.ego_length_m), ego.rows(rows), setup.contact_front.rows(rows)
        )
        at_once = back.value(t0[rows]) < -tol
        later = ~at_once & (back.minimum_between(t0[rows], t1[rows]) < -tol)
        collision[rows] = at_once | later
        t_hit[rows[at_once]] = t0[rows[at_once]]
        if later.any():
            sub = back.rows(np.flatnonzero(later)).shifted(tol)
            t_hit[rows[later]] = sub.first_negative(t0[rows[later]])
    impact = np.full(n, np.nan)
    if collision.any():
        rows = np.flatnonzero(collision)
        impact[rows] = -setup.gap(ego, rows).derivative_value(t_hit[rows])
    return CCResult(collision, min_gap, t_hit, impact, t_brake, setup.valid)


def _front_gap(setup: ScenarioSetup, ego: Motion, rows: np.ndarray) -> PiecewiseCubic:
    """Obstacle's nearest point in the ego's band - ego front (m), of the given rows."""
    return PiecewiseCubic.gap(np.zeros(rows.size), setup.contact_rear.rows(rows), ego.rows(rows))


def _monotone_front_minimum(setup: ScenarioSetup, ego: Motion, rows: np.ndarray) -> np.ndarray:
    """min over [t_overlap, t_end] of the front gap where it only shrinks between its jumps
    (``front_monotone``): the left limit before the jump, or the end of the scenario, or
    -inf when the ego stays faster than the obstacle for ever."""
    rear, mine = setup.contact_rear.rows(rows), ego.rows(rows)
    t_jump, t_end = setup.t_jump[rows], setup.t_end[rows]
    t_a = np.minimum(t_jump, t_end)
    before = np.maximum(np.sum(rear.t < t_a[:, None], axis=1) - 1, 0)
    x_rear_a = rear.state_in_segment(before[:, None], t_a[:, None])[0][:, 0]
    first = x_rear_a - mine.state_at(t_a)[0]
    # after the jump: to the end, or to when neither changes speed any more
    last_knot = np.max(np.where(np.isfinite(mine.t), mine.t, 0.0), axis=1)
    t_b = np.where(np.isfinite(t_end), t_end, np.maximum(t_jump, last_knot))
    t_bq = np.where(np.isfinite(t_b), t_b, 0.0)
    second = rear.state_at(t_bq)[0] - mine.state_at(t_bq)[0]
    running_away = np.isinf(t_end) & (mine.v[:, -1] > rear.v[:, -1])
    second = np.where(running_away, -np.inf, second)
    return np.where(t_jump <= t_end, np.minimum(first, second), first)


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


def cut_in_reaction(
    ve0: np.ndarray,
    vo0: np.ndarray,
    dx0: np.ndarray,
    vy: np.ndarray,
    t_overlap: np.ndarray,
    p: CCParams,
) -> tuple[np.ndarray, np.ndarray]:
    """When the C&C driver's reaction delay starts in a cut-in and when the scenario ends (s,
    inf = never), before any braking (the ego still at Ve0).

    At danger judgement the gap is dx0 - (Ve0 - Vo0) t: at or below 0 the other car is beside
    the ego and the driver does not brake for it. Else TTC below ``ttc_brake_s`` means react
    now; above it, react when TTC falls to it (``above_ttc="wait"``) or end the scenario
    (``"end"``).
    """
    dv = ve0 - vo0
    t_danger = p.danger_judgement_time(vy, t_overlap)
    ahead = dx0 - dv * t_danger > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ttc = np.where(dv > 0, dx0 / dv - p.ttc_brake_s, np.inf)
    above = t_ttc > t_danger
    never = np.full(ve0.shape, np.inf)
    if p.above_ttc == "end":
        t_react = np.where(ahead & ~above, t_danger, np.inf)
        return t_react, np.where(ahead & above, t_danger, never)
    return np.where(ahead, np.maximum(t_danger, t_ttc), np.inf), never


def cut_in_setup(
    ve0: np.ndarray,
    vo0: np.ndarray,
    dx0: np.ndarray,
    vy: np.ndarray,
    p: CCParams,
    reaction: tuple[np.ndarray, np.ndarray] | None = None,
    contact: CutInContact | None = None,
) -> ScenarioSetup:
    """Cut-in scenarios (no input checks); ``reaction`` = (reaction start, scenario end)
    overrides :func:`cut_in_reaction`, ``contact`` (of these scenarios, at this dx0) saves
    computing it."""
    if contact is None:
        contact = cut_in_contact(vo0, dx0, vy, p)
    t_react, t_end = reaction or cut_in_reaction(ve0, vo0, dx0, vy, contact.t_overlap, p)
    return ScenarioSetup(
        obstacle=Motion.constant_speed(vo0),
        offset=dx0,
        contact_rear=contact.rear,
        contact_front=contact.front,
        v0=ve0,
        v_end=vo0,
        t_brake=t_react + p.reaction_delay_s,
        t_overlap=contact.t_overlap,
        t_end=t_end,
        t_enable_aeb=contact.t_overlap,
        valid=np.ones(ve0.shape, bool),
        # the ego never brakes below Vo0 and the rear only recedes while entering the band
        front_monotone=contact.rear_receding,
        t_jump=contact.t_settle,
    )


def evaluate_cut_in(
    ve0_mps: ArrayLike,
    vo0_mps: ArrayLike,
    dx0_m: ArrayLike,
    vy_mps: ArrayLike,
    params: CCParams = _DEFAULT,
) -> CCResult:
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
    return _lane_aligned_setup(
        Motion.constant_speed(zeros),
        p.thw_s * ve0 + p.other_length_m + dx0_f,
        p,
        v0=ve0,
        v_end=zeros,
        t_brake=p.cut_out_danger_time(vy) + p.reaction_delay_s,
        t_overlap=zeros,
        t_end=np.full(ve0.shape, np.inf),
        t_enable_aeb=0.5 * (p.ego_width_m + p.other_width_m) / vy,
        valid=dx0_f >= cut_out_lead_clear_gap(ve0, vy, p) - 1e-9,
    )


def evaluate_cut_out(
    ve0_mps: ArrayLike, vy_mps: ArrayLike, dx0_f_m: ArrayLike, params: CCParams = _DEFAULT
) -> CCResult:
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
    decel = gx * p.g_mps2
    return _lane_aligned_setup(
        Motion.step_deceleration(ve0, decel),
        dx0,
        p,
        v0=ve0,
        v_end=zeros,
        t_brake=p.decel_danger_time(decel) + p.reaction_delay_s,
        t_overlap=zeros,
        t_end=np.full(ve0.shape, np.inf),
        t_enable_aeb=zeros,
        valid=np.ones(ve0.shape, bool),
    )


def evaluate_decel(
    ve0_mps: ArrayLike,
    gx_max_g: ArrayLike,
    params: CCParams = _DEFAULT,
    dx0_m: ArrayLike | None = None,
) -> CCResult:
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
