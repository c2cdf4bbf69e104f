"""snapgen: moves exact on the integer chain of the snapgen FPGA core.

plan / plan_duration: rest-to-rest moves; replan: seed 002's online planner from any exact
state; Board: a board (virtual, on a serial port, or a Zynq's station through UIO) that runs
moves as `snapgen send` does and timed PLCopen scripts as `snapgen online` does.
The state at time t is the state after the last tick k with k * ts <= t, clamped to the move
(the fabric's output holds between ticks). Positions are in units from the start, velocities
in units/s, ...
"""

from typing import Any, Dict, List, Optional, Tuple, Union

import os

import numpy as np
import numpy.typing as npt

DEFAULT_TS: float
"""The tick period the board runs after reset (s)."""
DEFAULT_LSB: float
"""The default size of one output position LSB (units)."""
FRAC_BITS: int
"""Fractional bits of the position register: its output cell is x >> FRAC_BITS."""

class PlanError(ValueError):
    """A move that cannot be planned; the message says what to change."""

class Trajectory:
    """A planned move: the program the fabric plays and the trajectory it makes."""

    @property
    def duration(self) -> float:
        """The move's duration (s): its ticks times ts."""
    @property
    def ticks(self) -> int:
        """The move's length in ticks."""
    @property
    def ts(self) -> float:
        """The tick period (s)."""
    @property
    def order(self) -> int:
        """4 (snap-limited), 3 (jerk-limited) or 2 (acceleration-limited)."""
    @property
    def target_position(self) -> float:
        """Where the move ends (units from the start): the distance on the LSB grid."""
    @property
    def program(self) -> List[Tuple[int, int]]:
        """(ticks, raw snap) per segment, as the fabric plays them."""
    @property
    def start_position(self) -> float:
        """Where the move starts (absolute units, from the centre of output cell 0)."""
    @property
    def start_registers(self) -> Tuple[int, int, int, int]:
        """The chain's raw (x, v, a, j) before the move."""
    def registers_at(self, tick: int) -> Tuple[int, int, int, int]:
        """The chain's raw (x, v, a, j) after `tick` ticks (the final state past the end)."""
    def scale(self, quantity: str) -> float:
        """Raw value per physical unit of "position", "velocity", "acceleration", "jerk", "snap"."""
    def at_time(self, t: float) -> Tuple[float, float, float, float]:
        """Position, velocity, acceleration and jerk at time t (s)."""
    def at_times(
        self, times: npt.NDArray[np.float64]
    ) -> Tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
    ]:
        """at_time for each time of a 1-D array: four arrays of its length."""
    def peaks(self) -> Dict[str, float]:
        """The largest |velocity|, |acceleration|, |jerk| and |snap| over the move."""

def plan(
    distance: float,
    *,
    max_velocity: float,
    max_acceleration: float,
    max_jerk: Optional[float] = None,
    max_snap: Optional[float] = None,
    ts: float = ...,
    lsb: float = ...,
) -> Trajectory:
    """A rest-to-rest move of `distance` units: order 4 with max_snap, 3 with max_jerk, else 2."""

def plan_duration(
    distance: float,
    *,
    duration: float,
    gamma: float,
    phi: float,
    ts: float = ...,
    lsb: float = ...,
) -> Trajectory:
    """Seed 001's duration-based S-curve: `distance` in `duration` s, gamma and phi in (0, 0.5]."""

def replan(
    registers: Tuple[int, int, int, int],
    *,
    max_velocity: float,
    max_acceleration: float,
    max_deceleration: Optional[float] = None,
    max_jerk: Optional[float] = None,
    target_position: Optional[float] = None,
    target_velocity: float = 0.0,
    ts: float = ...,
    lsb: float = ...,
) -> Trajectory:
    """Online from raw registers (x, v, a, j) to target_position (absolute units; passed at
    target_velocity) or, without one, to holding target_velocity: order 3 with max_jerk, else 2."""

class BoardError(RuntimeError):
    """The link or the board failed (no reply, a NAK, an axis error, a wrong end)."""

class MoveReport:
    """The outcome of Board.move_by."""

    trajectory: Trajectory
    """The move as planned from the board's registers with its Ts and uploaded."""
    end_registers: Tuple[int, int, int, int]
    """The board's raw (x, v, a, j) after it."""
    ticks: int
    """The board's tick count at its end."""
    stopped: bool
    """Cut short by a controlled stop (stop_after)."""
    warnings: List[str]
    """What the host warned about (stop limits)."""

class CommandOutcome:
    """What became of a command of a played script."""

    event: int
    """The event's index in the script."""
    at_ms: float
    """Its time (ms from the script's start)."""
    command: str
    """MC_MoveAbsolute, MC_MoveVelocity or MC_Halt."""
    outcome: str
    """Done, CommandAborted, Busy, Active, InVelocity, Error (NotGiven: its position was never
    reached)."""
    error_id: Optional[str]
    """Its ErrorID when refused (invalid_input, planner, board, link_too_slow, diverged)."""
    error: Optional[str]
    """The refusal's message."""
    note: Optional[str]
    """What the axis noted about it."""
    due_tick: Optional[int]
    """The tick it was due on (its time, or when its position was reached), when taken."""
    swap_tick: Optional[int]
    """The tick of the swap that realised it (the first tick that obeyed it), if one did."""
    latency_ms: Optional[float]
    """From the tick it was due to the first tick that obeyed it (ms), when it had one."""

class OverrideOutcome:
    """What became of a feed-override change of a played script."""

    event: int
    at_ms: float
    factor: float
    """The feed override (0-2)."""
    error_id: Optional[str]
    """Refused (its ErrorID), or taken."""
    error: Optional[str]
    due_tick: Optional[int]
    swap_tick: Optional[int]
    latency_ms: Optional[float]

class OnlineReport:
    """What Board.play did."""

    commands: List[CommandOutcome]
    overrides: List[OverrideOutcome]
    replans: int
    """Program swaps."""
    extension_swaps: int
    """More swaps that uploaded the rest of a change longer than the program memory."""
    ticks: int
    """Ticks from the script's start to its last state read."""
    end_registers: Tuple[int, int, int, int]
    """The board's raw (x, v, a, j) at its last state read."""
    end_lsb: int
    """Its position (output LSBs)."""
    target_lsb: Optional[int]
    """Where the last command not refused ends (output LSBs), if on a position."""
    state_checks: int
    """States read back and compared bit for bit with the host's prediction."""
    warnings: List[str]
    """What the stop-limit rule warned about."""

class Board:
    """A board behind the host's session: virtual (time in its own clocks), on a serial port, or
    a Zynq's station through its UIO device."""

    @staticmethod
    def model(*, baud: int = 115200, lsb: float = ...) -> "Board":
        """The device model (the I/O top's clock-accurate twin) as a virtual board."""
    @staticmethod
    def fabric(*, baud: int = 115200, lsb: float = ...) -> "Board":
        """The Verilated I/O top with the device model in lockstep (needs Verilator and a C++
        compiler)."""
    @staticmethod
    def axi_model(*, lsb: float = ...) -> "Board":
        """The AXI4-Lite top's model through the host's UIO link on a simulated memory map."""
    @staticmethod
    def axi_fabric(*, lsb: float = ...) -> "Board":
        """The Verilated AXI4-Lite top, its model in lockstep, through the UIO link's code."""
    @staticmethod
    def serial(port: str, *, baud: int = 115200, lsb: float = ...) -> "Board":
        """A real board on a serial port."""
    @staticmethod
    def uio(path: Union[str, "os.PathLike[str]"], *, lsb: float = ...) -> "Board":
        """A Zynq's station through its UIO device (/dev/uioN; Linux only)."""
    @property
    def mismatches(self) -> Optional[int]:
        """Clocks on which a Verilated top and its model in lockstep differed (None: no both)."""
    def play(self, script: Union[str, Dict[str, Any]]) -> OnlineReport:
        """Plays a timed script of PLCopen commands (TOML text or a dict; docs/ONLINE.md)
        through the host axis, as `snapgen online` does; every state read is checked bit for
        bit against the host's prediction, and on fabric boards the Verilated top against its
        model on every clock (BoardError when either differs). A script that breaks a rule
        raises PlanError; a dict JSON cannot encode, TypeError. A str is the script's text,
        not a file name."""
    @property
    def ts(self) -> float:
        """The board's tick period (s), read from it."""
    @property
    def clock_hz(self) -> int:
        """The board's fabric clock (Hz)."""
    @property
    def time(self) -> float:
        """The link's clock (s): a virtual board's own time, or the wall clock."""
    def state(self) -> Tuple[int, int, int, int, int]:
        """(ticks, x, v, a, j), raw."""
    def stop(self) -> None:
        """A controlled stop (STOP)."""
    def move_by(
        self,
        distance: float,
        *,
        max_velocity: float,
        max_acceleration: float,
        max_jerk: Optional[float] = None,
        max_snap: Optional[float] = None,
        stop_decel: Optional[float] = None,
        stop_jerk: Optional[float] = None,
        stop_after: Optional[float] = None,
        watchdog_ms: int = 1000,
        reset: bool = False,
    ) -> MoveReport:
        """Moves `distance` units as `snapgen send` does; the end is checked bit for bit."""
