"""The Python package's planners, checked from outside: every program is integrated here tick
by tick in Python's exact integers (seed 000's eqs 72-75: j += d, a += j, v += a, x += v, each
from the previous tick's values), independently of the Rust closed form the package uses, and
the trajectory, its end and its limits are compared with that integration."""

import math
import random

import numpy as np
import pytest

import snapgen


def integrate(traj):
    """Every tick's (x, v, a, j) from the start registers and the program, in Python ints."""
    x, v, a, j = traj.start_registers
    states = [(x, v, a, j)]
    for ticks, snap in traj.program:
        for _ in range(ticks):
            x, v, a, j = x + v, v + a, a + j, j + snap
            states.append((x, v, a, j))
    return states


def check_move(traj, distance, lsb, limits):
    states = integrate(traj)
    assert len(states) == traj.ticks + 1
    # The package's registers at every tick are the independent integration's.
    for k in range(0, traj.ticks + 1, max(1, traj.ticks // 200)):
        assert traj.registers_at(k) == states[k], k
    assert traj.registers_at(traj.ticks) == states[-1]
    # Ends at rest, exactly on the asked distance's LSB grid point.
    x0 = states[0][0]
    x, v, a, j = states[-1]
    assert (v, a, j) == (0, 0, 0)
    moved = (x - x0) / traj.scale("position")
    assert abs(moved - distance) <= lsb / 2 * (1 + 1e-9), (moved, distance)
    assert abs(traj.target_position - moved) <= lsb * 1e-6
    # Within every limit on every tick.
    names = ["velocity", "acceleration", "jerk"]
    for i, name in enumerate(names, start=1):
        if name in limits:
            peak = max(abs(s[i]) for s in states) / traj.scale(name)
            assert peak <= limits[name] * (1 + 1e-12), (name, peak, limits[name])
    if "snap" in limits:
        peak = max(abs(d) for _, d in traj.program) / traj.scale("snap")
        assert peak <= limits["snap"] * (1 + 1e-12)
    return states


def test_an_order_3_move_is_exact_and_within_its_limits():
    lim = {"velocity": 0.5, "acceleration": 2.0, "jerk": 50.0}
    t = snapgen.plan(0.1, max_velocity=0.5, max_acceleration=2.0, max_jerk=50.0, ts=1e-4)
    assert t.order == 3
    assert t.duration == pytest.approx(t.ticks * 1e-4)
    check_move(t, 0.1, snapgen.DEFAULT_LSB, lim)


def test_orders_4_and_2_and_negative_distances():
    t4 = snapgen.plan(-0.05, max_velocity=0.3, max_acceleration=3.0, max_jerk=100.0,
                      max_snap=5000.0, ts=2e-4)
    assert t4.order == 4
    check_move(t4, -0.05, snapgen.DEFAULT_LSB,
               {"velocity": 0.3, "acceleration": 3.0, "jerk": 100.0, "snap": 5000.0})
    t2 = snapgen.plan(0.2, max_velocity=0.4, max_acceleration=1.0, ts=1e-3, lsb=1e-5)
    assert t2.order == 2
    check_move(t2, 0.2, 1e-5, {"velocity": 0.4, "acceleration": 1.0})


def test_seed_001s_duration_method():
    # Seed 001's Table 1: 12*pi rad in 1.8 s, gamma = 0.3, phi = 0.3 (ts 1 ms here).
    d = 12 * math.pi
    t = snapgen.plan_duration(d, duration=1.8, gamma=0.3, phi=0.3, ts=1e-3, lsb=1e-4)
    assert t.order == 3
    check_move(t, d, 1e-4, {})
    # The duration asked, up to the tick grid and the quantizer's cruise ticks.
    assert 1.8 <= t.duration <= 1.8 + 0.01


def test_random_moves_over_wide_ranges():
    rng = random.Random(20261127)
    for _ in range(12):
        order = rng.choice([2, 3, 4])
        ts = rng.choice([1e-4, 2e-4, 5e-4, 1e-3])
        distance = rng.choice([-1, 1]) * 10 ** rng.uniform(-3, 0)
        vmax = 10 ** rng.uniform(-1.5, 0.5)
        amax = 10 ** rng.uniform(-0.5, 1.5)
        jmax = 10 ** rng.uniform(1, 3)
        smax = 10 ** rng.uniform(3, 5)
        lim = {"velocity": vmax, "acceleration": amax}
        kw = {}
        if order >= 3:
            kw["max_jerk"] = jmax
            lim["jerk"] = jmax
        if order == 4:
            kw["max_snap"] = smax
            lim["snap"] = smax
        t = snapgen.plan(distance, max_velocity=vmax, max_acceleration=amax, ts=ts, **kw)
        if t.ticks > 60000:
            continue  # a long move: the per-tick Python integration would be slow
        assert t.order == order
        check_move(t, distance, snapgen.DEFAULT_LSB, lim)


def test_at_time_and_at_times_sample_the_integrated_chain():
    t = snapgen.plan(0.02, max_velocity=0.2, max_acceleration=2.0, max_jerk=80.0, ts=1e-3)
    states = integrate(t)
    sx, sv, sa, sj = (t.scale(q) for q in ("position", "velocity", "acceleration", "jerk"))
    x0 = states[0][0]
    times = np.array([-1.0, 0.0, 0.0005, 0.0123, t.duration / 2, t.duration - 1e-9,
                      t.duration, t.duration + 5.0])
    p, v, a, j = t.at_times(times)
    assert p.shape == v.shape == a.shape == j.shape == times.shape
    for i, time in enumerate(times):
        x, vv, aa, jj = states[tick_at(t, time)]
        want = ((x - x0) / sx, vv / sv, aa / sa, jj / sj)
        assert t.at_time(float(time)) == pytest.approx(want, rel=1e-12, abs=1e-15)
        assert (p[i], v[i], a[i], j[i]) == pytest.approx(want, rel=1e-12, abs=1e-15)


def tick_at(t, time):
    """The documented rule, by search: the last tick k (clamped to the move) with k * ts <= t."""
    k = 0
    while k < t.ticks and (k + 1) * t.ts <= time:
        k += 1
    return k


def test_the_end_of_the_move_is_at_its_duration_whatever_the_tick_count():
    # t / ts rounds below a whole tick for some tick counts (49 ticks of 1e-4 s, ...): the
    # state at the move's duration is still its end, at rest, for every move here.
    rng = random.Random(7)
    ends = 0
    for _ in range(200):
        t = snapgen.plan(10 ** rng.uniform(-4, -2), max_velocity=1.0, max_acceleration=20.0,
                         max_jerk=2000.0, ts=rng.choice([1e-4, 1e-3, 3e-5]))
        states = integrate(t)
        sv = t.scale("velocity")
        assert t.at_time(t.duration)[1:] == (0.0, 0.0, 0.0)
        assert t.registers_at(t.ticks) == states[-1]
        # At each tick's own time, that tick's state (velocities compared exactly).
        for k in range(0, t.ticks + 1, max(1, t.ticks // 10)):
            assert t.at_time(k * t.ts)[1] == states[k][1] / sv, k
        ends += 1
    assert ends == 200
    with pytest.raises(ValueError, match="NaN"):
        t.at_time(float("nan"))


def test_peaks_are_the_integrations_peaks():
    t = snapgen.plan(0.1, max_velocity=0.5, max_acceleration=2.0, max_jerk=50.0, ts=1e-3)
    states = integrate(t)
    peaks = t.peaks()
    for i, name in enumerate(["velocity", "acceleration", "jerk"], start=1):
        want = max(abs(s[i]) for s in states) / t.scale(name)
        assert peaks[name] == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(max_velocity=-1.0, max_acceleration=1.0, max_jerk=10.0), "vmax"),
        (dict(max_velocity=1.0, max_acceleration=float("nan"), max_jerk=10.0), "amax"),
        (dict(max_velocity=1.0, max_acceleration=1.0, max_snap=10.0), "max_snap without max_jerk"),
        (dict(max_velocity=1.0, max_acceleration=1.0, ts=0.0), "ts = 0"),
    ],
)
def test_bad_input_raises_plan_error_with_what_to_change(kwargs, message):
    with pytest.raises(snapgen.PlanError, match=message) as e:
        snapgen.plan(0.1, **kwargs)
    assert isinstance(e.value, ValueError)


def test_a_bad_ratio_names_the_range():
    with pytest.raises(snapgen.PlanError, match="gamma"):
        snapgen.plan_duration(1.0, duration=1.0, gamma=0.7, phi=0.3)


def test_replanning_from_a_moving_state_ends_exactly_on_the_new_target():
    """Seed 002 / MC_MoveAbsolute aborting a move: from the exact registers halfway through a
    move, a new target behind it; the new program, integrated here from those registers,
    reverses within its limits and comes to rest in the target's cell."""
    lim = dict(max_velocity=0.5, max_acceleration=2.0, max_jerk=50.0)
    first = snapgen.plan(0.1, ts=1e-4, **lim)
    mid = first.registers_at(first.ticks // 2)
    assert mid[1] != 0  # moving
    lsb = snapgen.DEFAULT_LSB
    for order_kw, order in ((dict(max_jerk=50.0), 3), ({}, 2)):
        t = snapgen.replan(mid, max_velocity=0.5, max_acceleration=2.0, max_deceleration=3.0,
                           target_position=0.01, ts=1e-4, **order_kw)
        assert t.order == order
        assert t.start_registers == mid
        states = integrate(t)
        x, v, a, j = states[-1]
        assert (v, a, j) == (0, 0, 0)
        assert x >> snapgen.FRAC_BITS == round(0.01 / lsb)
        assert t.start_position + t.target_position == pytest.approx(0.01, abs=lsb)
        assert max(abs(s[1]) for s in states) / t.scale("velocity") <= 0.5 * (1 + 1e-12)
        assert max(abs(s[2]) for s in states) / t.scale("acceleration") <= 3.0 * (1 + 1e-12)
        if order == 3:
            assert max(abs(s[3]) for s in states) / t.scale("jerk") <= 50.0 * (1 + 1e-12)


def test_replanning_to_a_velocity_holds_it():
    t = snapgen.plan(0.1, max_velocity=0.5, max_acceleration=2.0, max_jerk=50.0, ts=1e-4)
    mid = t.registers_at(t.ticks // 3)
    r = snapgen.replan(mid, max_velocity=0.5, max_acceleration=2.0, max_jerk=50.0,
                       target_velocity=-0.2, ts=1e-4)
    x, v, a, j = integrate(r)[-1]
    assert (a, j) == (0, 0)
    assert abs(v / r.scale("velocity") + 0.2) <= 1 / r.scale("velocity")


def test_replanning_refuses_what_cannot_be_done():
    with pytest.raises(snapgen.PlanError, match="beyond the velocity limit"):
        snapgen.replan((0, 0, 0, 0), max_velocity=0.5, max_acceleration=2.0, target_velocity=1.0)
    with pytest.raises(snapgen.PlanError, match="does not fit the board's"):
        snapgen.replan((0, 1 << 120, 0, 0), max_velocity=0.5, max_acceleration=2.0)
    with pytest.raises(snapgen.PlanError, match="target_position = inf"):
        snapgen.replan((0, 0, 0, 0), max_velocity=0.5, max_acceleration=2.0,
                       target_position=float("inf"))
