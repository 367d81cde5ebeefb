"""Entity paths and timeline names of a sins-fw recording: one place, shared by the logger, the
blueprint and the tests."""

from __future__ import annotations

#: Emulated (virtual) time, a duration timeline in nanoseconds (the core's picoseconds, floored).
TIME = "emulated_time"
#: Attitude step index (the firmware's 8 ms cycle).
CYCLE = "cycle"
#: CPU timer 0 tick index (one acquisition ISR per tick).
TICK = "tick"
#: Event index (events share times; this keeps each one addressable).
EVENT = "event"
#: SPI character index since power-on (bus window only).
FRAME = "frame"

BOARD = "world/board"
BOARD_BODY = "world/board/body"
BOARD_AXES = "world/board/axes"
BOARD_ADIS = "world/board/adis16407"
TRUTH = "world/truth"
TRUTH_BODY = "world/truth/body"

ANGLES = ("roll", "pitch", "yaw")


def attitude(angle: str, what: str) -> str:
    """``attitude/<angle>/<estimate|truth>``."""
    return f"attitude/{angle}/{what}"


def attitude_error(angle: str) -> str:
    """``attitude_error/<roll|pitch|yaw|total>``."""
    return f"attitude_error/{angle}"


RATE_DECODED = "imu/rate/decoded"
RATE_PHYSICAL = "imu/rate/physical"
ACCEL_DECODED = "imu/accel/decoded"
ACCEL_PHYSICAL = "imu/accel/physical"
SAMPLE_AGE = "imu/sample_age"
REGISTER_WORDS = "registers/words"
REGISTER_ND = "registers/nd"
REGISTER_EA = "registers/ea"

#: The DCM's drift-cancellation terms (one scalar series per component; none for the other
#: algorithms): ω_P and ω_I (°/s), the roll–pitch and yaw errors, |R·Rᵀ − I|.
DCM_OMEGA_P = "dcm/omega_p"
DCM_OMEGA_I = "dcm/omega_i"
DCM_ERROR_RP = "dcm/error_rp"
DCM_ERROR_YAW = "dcm/error_yaw"
DCM_ORTHOGONALITY = "dcm/orthogonality"
#: The wing unit's hinge angle (estimate and the trace's truth, degrees), its error against the truth
#: (degrees) and the estimated axis (unit, IMU axes at the zero); none for the other algorithms.
WING_ALPHA = "wing/alpha"
WING_ALPHA_ERROR = "wing/alpha_error"
WING_AXIS = "wing/axis"

BUDGET_BUSY = "budget/busy"
BUDGET_FINISH = "budget/finish"
BUDGET_DEADLINE = "budget/deadline"
BUDGET_MARGIN = "budget/margin"

EVENTS = "events"

BUS_CS = "bus/cs"
BUS_SCLK = "bus/sclk"
BUS_FRAMES = "bus/frames"
BUS_STALL = "bus/stall"
BUS_STALL_MIN = "bus/stall_min"


#: A C firmware's watched globals (`replay` of a `run --firmware --out` file): one series each.
FIRMWARE_GLOBALS = "firmware"


def firmware_global(column: str) -> str:
    """``firmware/<column>``: a watched global of a C firmware, as its run output names it."""
    return f"{FIRMWARE_GLOBALS}/{column}"


def parity(backend: str, what: str) -> str:
    """``parity/<backend>/<euler|angle>``: that backend minus this run."""
    return f"parity/{backend}/{what}"


#: The gyro-free board (issue 25): one bus lane per link (``bus/<link>``: spi1…spi7 to the ADXL345s,
#: iic1 to the HMC6343, uart from the GR-87, spi8 to the C6727B), the array's channels as the DSP
#: decoded them, the compass, both processors' time per cycle.
GFSINS_LINKS = ("spi1", "spi2", "spi3", "spi4", "spi5", "spi6", "spi7", "iic1", "uart", "spi8")
GFSINS_ARRAY = "array/decoded"
GFSINS_COMPASS = "compass/heading"
GFSINS_NODE_BUSY = "budget/node_busy"
GFSINS_DSP_BUSY = "budget/dsp_busy"


def bus_lane(link: str) -> str:
    """``bus/<link>``: the link's state over time (what it carries, or idle)."""
    return f"bus/{link}"
