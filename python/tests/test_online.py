"""Timed PLCopen scripts from Python (Board.play, as `snapgen online`): the same script on the
virtual board behind its UART and behind the AXI4-Lite registers (the host's UIO link on a
simulated memory map), its end checked against this file's own arithmetic (the target's LSB),
its override latency against the issue's targets, and the Verilated AXI top against its model
on every clock."""

import pytest

import snapgen

MOVE = dict(velocity=200.0, acceleration=4000.0, deceleration=4000.0, jerk=200000.0)


def script(target=1.0):
    """A move, a feed override while it runs, an aborting move elsewhere before it ends."""
    return {
        "order": 3,
        "stop_deceleration": 4000.0,
        "stop_jerk": 200000.0,
        "event": [
            dict(at_ms=0, kind="move_absolute", position=3.0, buffer_mode="aborting", **MOVE),
            dict(at_ms=8, override=0.5),
            dict(at_ms=16, kind="move_absolute", position=target, buffer_mode="aborting", **MOVE),
        ],
    }


def lsb_of(position):
    return round(position / snapgen.DEFAULT_LSB)


def test_a_script_plays_alike_behind_the_uart_and_the_registers():
    reports = {}
    for name, board in (("uart", snapgen.Board.model()), ("axi", snapgen.Board.axi_model())):
        r = board.play(script())
        reports[name] = r
        assert [c.outcome for c in r.commands] == ["CommandAborted", "Done"], name
        assert [c.command for c in r.commands] == ["MC_MoveAbsolute", "MC_MoveAbsolute"]
        # At rest exactly on the last target, by this file's arithmetic.
        x, v, a, j = r.end_registers
        assert (v, a, j) == (0, 0, 0)
        assert r.end_lsb == lsb_of(1.0) == x >> snapgen.FRAC_BITS
        assert board.state()[1:] == r.end_registers
        assert r.state_checks >= 3 and r.replans >= 2
        assert r.commands[1].latency_ms is not None and r.overrides[0].latency_ms is not None
        assert [o.factor for o in r.overrides] == [0.5] and r.overrides[0].error_id is None
        assert board.mismatches is None
    # The override's latency: under 100 µs over the registers, tens of ms over the UART.
    assert reports["axi"].overrides[0].latency_ms < 0.1
    assert reports["uart"].overrides[0].latency_ms > 10.0


def test_toml_text_and_a_dict_are_the_same_script():
    toml = """
order = 3
[[event]]
at_ms = 0
kind = "move_absolute"
position = 0.5
velocity = 200.0
acceleration = 4000.0
deceleration = 4000.0
jerk = 200000.0
"""
    a = snapgen.Board.axi_model().play(toml)
    b = snapgen.Board.axi_model().play(
        {"event": [dict(at_ms=0, kind="move_absolute", position=0.5, **MOVE)]}
    )
    assert a.end_registers == b.end_registers and a.ticks == b.ticks
    assert a.end_lsb == lsb_of(0.5)
    assert [c.outcome for c in a.commands] == ["Done"]


@pytest.mark.verilated
def test_the_verilated_axi_top_agrees_with_its_model_on_every_clock():
    board = snapgen.Board.axi_fabric()
    r = board.play(script(target=2.0))
    assert board.mismatches == 0
    assert r.end_lsb == lsb_of(2.0) and r.end_registers[1:] == (0, 0, 0)


def test_bad_scripts_and_a_missing_device():
    b = snapgen.Board.axi_model()
    with pytest.raises(snapgen.PlanError, match="order = 4"):
        b.play(dict(script(), order=4))
    with pytest.raises(snapgen.PlanError, match="event 1: at_ms"):
        b.play({"event": [dict(at_ms=5, override=1.0), dict(at_ms=1, override=0.5)]})
    with pytest.raises(snapgen.PlanError, match="not a valid script"):
        b.play("order = ")
    with pytest.raises(snapgen.BoardError, match="UIO"):
        snapgen.Board.uio("/nonexistent/uio0")


def test_a_refused_override_names_its_error_id():
    r = snapgen.Board.axi_model().play(
        {"event": [dict(at_ms=0, kind="move_absolute", position=0.5, **MOVE),
                   dict(at_ms=2, override=3.0)]}
    )
    (o,) = r.overrides
    assert o.error_id == "invalid_input" and "0" in o.error and o.swap_tick is None
    assert o.due_tick is not None and o.latency_ms is None
    (c,) = r.commands
    assert c.outcome == "Done" and c.error_id is None and c.swap_tick > c.due_tick
    assert r.end_lsb == lsb_of(0.5)

