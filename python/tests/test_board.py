"""A board from Python: moves on the virtual board (the device model behind its UART, time in
its own clocks) through the host's session, each checked against this file's own integration
of the program the host uploaded (test_plan.integrate: Python's integers, tick by tick)."""

import pytest

import snapgen
from test_plan import integrate

LIMITS = dict(max_velocity=0.2, max_acceleration=5.0, max_jerk=500.0)


def test_moves_on_the_virtual_board_end_where_their_programs_say():
    b = snapgen.Board.model()
    assert b.ts == snapgen.DEFAULT_TS and b.clock_hz == 125_000_000
    before = b.state()[1:]
    r = b.move_by(0.002, **LIMITS)
    t = r.trajectory
    # Planned from the board's exact registers with its Ts.
    assert t.start_registers == before and t.ts == b.ts
    states = integrate(t)
    assert r.end_registers == states[-1] == b.state()[1:]
    assert not r.stopped
    # Back again, from where it stands: the start cell.
    r2 = b.move_by(-0.002, **LIMITS)
    assert r2.trajectory.start_registers == states[-1]
    end = integrate(r2.trajectory)[-1]
    assert r2.end_registers == end
    assert end[0] >> snapgen.FRAC_BITS == before[0] >> snapgen.FRAC_BITS
    assert end[1:] == (0, 0, 0)


def test_a_stop_cuts_a_move_short_at_rest():
    b = snapgen.Board.model()
    x0 = b.state()[1]
    r = b.move_by(0.05, stop_after=0.03, **LIMITS)
    assert r.stopped
    x, v, a, j = r.end_registers
    assert (v, a, j) == (0, 0, 0)
    moved = (x - x0) / r.trajectory.scale("position")
    assert 0 < moved < 0.05
    assert b.state()[1:] == r.end_registers


def test_bad_input_and_a_missing_port():
    b = snapgen.Board.model()
    with pytest.raises(snapgen.PlanError, match="vmax"):
        b.move_by(0.001, max_velocity=-1.0, max_acceleration=1.0)
    with pytest.raises(snapgen.PlanError, match="stop_after = NaN"):
        b.move_by(0.001, stop_after=float("nan"), **LIMITS)
    with pytest.raises(snapgen.BoardError):
        snapgen.Board.serial("/nonexistent/tty")
