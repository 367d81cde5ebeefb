"""The default layout of a sins-fw recording (a Rerun blueprint), so that a replay opens organised:
one tab per question. *Attitude*: is it right, and where did it go wrong (the board and its truth
ghost, roll/pitch/yaw against truth, the errors, the events). *Sensor*: what the firmware decoded
next to what the IMU felt, the raw register words and their ND/EA flags, the sample age. *Budget*:
which cycle missed its deadline. *DCM*: how the DCM's drift cancellation pulls the attitude (its
correction terms and errors, the matrix's orthogonality). *Bus*: what was on the SPI bus in the
recorded window. *Parity*: how the other numeric backends differ. A C firmware's run output
(`replay RUN.h5` of a `run --firmware --out` file): the same *Attitude* tab when its globals give the
attitude, and *Globals*, one plot per watched global."""

from __future__ import annotations

import uuid
from collections.abc import Iterable, Mapping

import rerun.blueprint as rrb

from sins_fw.viewer import paths


def _events(name: str = "Events") -> rrb.TextLogView:
    return rrb.TextLogView(origin=paths.EVENTS, name=name)


def default_blueprint(
    *,
    bus: bool,
    parity: Iterable[str] = (),
    dcm: bool = False,
    wing: bool = False,
    firmware: Mapping[str, str] | None = None,
    attitude: bool = True,
) -> rrb.Blueprint:
    """Tabs Attitude, Sensor, Budget, and DCM / Bus / Parity when the recording has them (``dcm``:
    the firmware is the DCM, :func:`sins_fw.harness.has_dcm`; ``bus``: a bus window was recorded;
    ``parity``: the other backends' names); emulated time selected.

    ``firmware`` (column → its series' name): the recording of a C firmware's run output, which
    holds the firmware's globals and no sensor reads or budget: the Attitude tab (when ``attitude``:
    the globals give it), then a Globals tab with one plot per global."""
    if firmware is not None:
        return _firmware_blueprint(firmware, attitude)
    parity = list(parity)
    tabs: list[rrb.Container] = [_attitude_tab()]
    sensor = rrb.Vertical(
        rrb.Horizontal(
            rrb.TimeSeriesView(name="Rate: decoded and physical (°/s)", origin="imu/rate"),
            rrb.TimeSeriesView(name="Acceleration: decoded and physical (g)", origin="imu/accel"),
        ),
        rrb.Horizontal(
            rrb.TimeSeriesView(name="Raw register words", origin=paths.REGISTER_WORDS),
            rrb.TimeSeriesView(name="ND flags (1: new data)", origin=paths.REGISTER_ND),
            rrb.TimeSeriesView(name="EA flags (1: error/alarm)", origin=paths.REGISTER_EA),
            rrb.TimeSeriesView(name="Sample age at the read (µs)", origin=paths.SAMPLE_AGE),
        ),
        name="Sensor",
    )
    budget = rrb.Vertical(
        rrb.TimeSeriesView(
            name="ISR per tick: busy, end and deadline after the tick (µs)",
            contents=[paths.BUDGET_BUSY, paths.BUDGET_FINISH, paths.BUDGET_DEADLINE],
        ),
        rrb.TimeSeriesView(name="Margin to the deadline (µs)", origin=paths.BUDGET_MARGIN),
        _events("Events (overruns, violations)"),
        row_shares=[2, 1, 1],
        name="Budget",
    )
    tabs += [sensor, budget]
    if dcm:
        tabs.append(
            rrb.Vertical(
                rrb.Horizontal(
                    rrb.TimeSeriesView(name="ω_P = K_P·e (°/s, body axes)", origin=paths.DCM_OMEGA_P),
                    rrb.TimeSeriesView(name="ω_I, the integrator (°/s, body axes)", origin=paths.DCM_OMEGA_I),
                ),
                rrb.Horizontal(
                    rrb.TimeSeriesView(name="Roll–pitch error (body axes)", origin=paths.DCM_ERROR_RP),
                    rrb.TimeSeriesView(name="Yaw error (body axes)", origin=paths.DCM_ERROR_YAW),
                ),
                rrb.TimeSeriesView(name="|R·Rᵀ − I| after renormalisation", origin=paths.DCM_ORTHOGONALITY),
                name="DCM",
            )
        )
    if wing:  # the wing unit: :func:`sins_fw.harness.has_wing`
        tabs.append(
            rrb.Vertical(
                rrb.TimeSeriesView(name="Hinge angle α: estimate and truth (°)", origin=paths.WING_ALPHA),
                rrb.TimeSeriesView(name="α error against the truth (°)", origin=paths.WING_ALPHA_ERROR),
                rrb.TimeSeriesView(
                    name="Estimated hinge axis (IMU axes at the zero)", origin=paths.WING_AXIS
                ),
                name="Wing",
            )
        )
    if bus:
        tabs.append(
            rrb.Vertical(
                rrb.StateTimelineView(
                    name="CS and SCLK (frames: DIN/DOUT, stalls)", contents=[paths.BUS_CS, paths.BUS_SCLK]
                ),
                rrb.TimeSeriesView(
                    name="Stall before each frame (µs)", contents=[paths.BUS_STALL, paths.BUS_STALL_MIN]
                ),
                rrb.TextLogView(name="Frames", origin=paths.BUS_FRAMES),
                name="Bus",
            )
        )
    if parity:
        tabs.append(
            rrb.Vertical(
                *(rrb.TimeSeriesView(name=f"{name} − this run", origin=f"parity/{name}") for name in parity),
                name="Parity",
            )
        )
    return _blueprint(tabs)


def _attitude_tab() -> rrb.Container:
    angles = [
        rrb.TimeSeriesView(
            name=f"{angle.capitalize()}: estimate and truth (°)",
            origin=f"attitude/{angle}",
        )
        for angle in paths.ANGLES
    ]
    return rrb.Horizontal(
        rrb.Vertical(
            rrb.Spatial3DView(name="Board (estimate) and truth (wireframe), ENU", origin="world"),
            _events(),
            row_shares=[3, 1],
        ),
        rrb.Vertical(
            *angles,
            rrb.TimeSeriesView(name="Attitude error (°), estimate − truth", origin="attitude_error"),
        ),
        column_shares=[2, 3],
        name="Attitude",
    )


def _firmware_blueprint(globals_: Mapping[str, str], attitude: bool) -> rrb.Blueprint:
    views = [
        rrb.TimeSeriesView(name=name, origin=paths.firmware_global(column))
        for column, name in globals_.items()
    ]
    tabs: list[rrb.Container] = [_attitude_tab()] if attitude else []
    tabs.append(rrb.Grid(*views, name="Globals"))
    return _blueprint(tabs)


def _blueprint(tabs: list[rrb.Container]) -> rrb.Blueprint:
    root = rrb.Tabs(*tabs, active_tab=0)
    _name_ids(root, "")
    return rrb.Blueprint(root, rrb.TimePanel(timeline=paths.TIME, expanded=True), collapse_panels=False)


def _name_ids(part: rrb.Container | rrb.View, where: str) -> None:
    """Give each container and view an id from its place in the layout (Rerun draws a random one),
    so that the same layout is logged with the same ids (docs/traces.md, "Determinism")."""
    part.id = uuid.uuid5(uuid.NAMESPACE_URL, f"sins-fw:layout{where}")
    if isinstance(part, rrb.Container):
        for i, sub in enumerate(part.contents):
            _name_ids(sub, f"{where}/{i}")
