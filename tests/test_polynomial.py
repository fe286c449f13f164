"""The HUBO pattern (Park et al. 2008, Section 3): paper equations, continuity, landing, no drift."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from zmpwalk import OnlineWalker, StepCommand, ZmpwalkError, generate
from zmpwalk import zmp as zmp_maps
from zmpwalk.footsteps import Stance
from zmpwalk.patterns.polynomial import Boundary, StageTable, evaluate, plan_next, plan_walk

POSITION_TOL = 1e-9  # [m]
VELOCITY_TOL = 1e-6  # [m/s]
EPS = 1e-10  # [s] one-sided limits around a breakpoint


# --------------------------------------------------------------------- paper equations

def test_fig10_step_follows_eqs_4_11_12_13(hubo, schedule):
    """b = 200 mm, f = 100 mm, 0.95 s: pelvis cubic of Eqs. 12-13 and swing cycloid of Eq. 11."""
    rate = 1000.0
    pattern = generate(hubo, [StepCommand(0.95, 0.2), StepCommand(0.95, 0.1)], rate=rate)
    step = [s for s in pattern.steps if s.kind == "step"][1]
    T, b, f = 0.95, 0.2, 0.1
    alpha = step.parameters["alpha"]
    assert alpha == pytest.approx(1.85)  # Table 2, 0.95 s
    i1 = round(step.start * rate)
    idx = np.arange(i1, i1 + round(T * rate) + 1)
    tau = (pattern.time[idx] - step.start) / T
    support = pattern.position_left_ankle_in_world if step.swing == "right" else pattern.position_right_ankle_in_world
    swing = pattern.position_right_ankle_in_world if step.swing == "right" else pattern.position_left_ankle_in_world
    x_support = support[idx[0], 0]
    # Eq. 13 boundary values (per unit normalised time), Eq. 4 coefficients, Eq. 12 cubic.
    a3, a2, a1, a0 = zmp_maps.CUBIC_FROM_BOUNDARY @ np.array([-b / 2, alpha * b, f / 2, alpha * f])
    expected_pelvis = a0 + a1 * tau + a2 * tau**2 + a3 * tau**3
    np.testing.assert_allclose(pattern.position_pelvis_in_world[idx, 0] - x_support, expected_pelvis, atol=1e-12)
    v = pattern.velocity_pelvis_in_world[idx, 0]
    assert v[0] == pytest.approx(alpha * b / T, abs=1e-12)
    assert v[-1] == pytest.approx(alpha * f / T, abs=1e-12)
    # Eq. 11: cycloid from -b to f over [t1 + d/2, t2 - d/2].
    d = step.parameters["dsp_time"]
    t = pattern.time[idx] - step.start
    s = np.clip((t - d / 2) / (T - d), 0, 1)
    expected_swing = (b + f) * (s - np.sin(2 * np.pi * s) / (2 * np.pi)) - b
    np.testing.assert_allclose(swing[idx, 0] - x_support, expected_swing, atol=1e-12)
    # Relative ankle positions of Fig. 11: support -x_P, swing x_A - x_P (pelvis frame, straight walk).
    left_swings = step.swing == "left"
    in_pelvis = pattern.position_right_ankle_in_pelvis if left_swings else pattern.position_left_ankle_in_pelvis
    np.testing.assert_allclose(in_pelvis[idx, 0], -expected_pelvis, atol=1e-12)


def test_sway_follows_eqs_18_to_20(hubo):
    """Y sway of a steady step: 0 -> -beta1 S_y (staying for d1 T) -> 0, slopes alpha1 V_y per unit 2 t_bar."""
    rate = 1000.0
    T = 0.8
    pattern = generate(hubo, [StepCommand(T, 0.1)] * 5, rate=rate)
    step = [s for s in pattern.steps if s.kind == "step"][2]
    p = step.parameters
    d1, S, V = p["d1"], p["beta1"] * p["sway"], p["alpha1"] * p["lateral_velocity"]
    sign = -1.0 if step.swing == "left" else 1.0  # towards the supporting foot
    i1 = round(step.start * rate)
    idx = np.arange(i1, i1 + round(T * rate) + 1)
    t_n = (pattern.time[idx] - step.start) / T
    y = pattern.position_pelvis_in_world[idx, 1]
    vy = pattern.velocity_pelvis_in_world[idx, 1]
    staying = (t_n > (1 - d1) / 2 + 1e-9) & (t_n < (1 + d1) / 2 - 1e-9)
    np.testing.assert_allclose(y[staying], sign * S, atol=1e-12)
    np.testing.assert_allclose(vy[staying], 0.0, atol=1e-12)
    assert y[0] == pytest.approx(0.0, abs=1e-12) and y[-1] == pytest.approx(0.0, abs=1e-12)
    half = (1 - d1) * T / 2  # [s] per unit of 2 t_bar
    assert vy[0] == pytest.approx(sign * V / half, abs=1e-9)
    assert vy[-1] == pytest.approx(-sign * V / half, abs=1e-9)


def test_turning_hip_yaws_follow_eqs_21_to_23(hubo):
    theta = 0.2
    rate = 1000.0
    pattern = generate(hubo, [StepCommand(0.95, turn=theta)], rate=rate)
    left_hip = pattern.yaw_left_foot_in_pelvis
    right_hip = pattern.yaw_right_foot_in_pelvis
    np.testing.assert_allclose(right_hip, -left_hip, atol=1e-15)  # Eq. 23
    open_stage, recovery = [s for s in pattern.steps if s.kind in ("open", "recovery")]
    for stage, sign in ((open_stage, -1.0), (recovery, 1.0)):
        d = stage.parameters["dsp_time"]
        mask = (pattern.time >= stage.start) & (pattern.time <= stage.start + stage.duration)
        s = np.clip((pattern.time[mask] - stage.start - d / 2) / (stage.duration - d), 0, 1)
        expected = theta / 4 * (1 + sign * np.cos(np.pi * s))  # Eq. 21 (open), Eq. 22 (recovery)
        np.testing.assert_allclose(left_hip[mask], expected, atol=1e-12)
    assert pattern.yaw_left_foot_in_world[-1] == pytest.approx(theta, abs=1e-15)
    assert pattern.yaw_right_foot_in_world[-1] == pytest.approx(theta, abs=1e-15)


def test_foot_is_still_in_double_support_and_lifts_to_the_commanded_height(hubo):
    pattern = generate(hubo, [StepCommand(0.8, 0.2, foot_lift=0.05)] * 3, rate=1000)
    double = pattern.support == 0
    for ankle in (pattern.velocity_left_ankle_in_world, pattern.velocity_right_ankle_in_world):
        np.testing.assert_allclose(ankle[double], 0.0, atol=1e-12)
    assert pattern.position_left_ankle_in_world[:, 2].max() == pytest.approx(hubo.ankle_height + 0.05, abs=1e-6)
    assert pattern.position_left_ankle_in_world[:, 2].min() == pytest.approx(hubo.ankle_height, abs=1e-15)


def test_pattern_starts_and_ends_in_the_ready_posture(hubo):
    pattern = generate(hubo, [StepCommand(0.8, 0.2)] * 4, rate=100)
    for i in (0, -1):
        np.testing.assert_allclose(pattern.velocity_pelvis_in_world[i], 0.0, atol=1e-12)
        middle = (pattern.position_left_ankle_in_world[i] + pattern.position_right_ankle_in_world[i]) / 2
        np.testing.assert_allclose(pattern.position_pelvis_in_world[i, :2], middle[:2], atol=1e-12)
        gap = pattern.position_left_ankle_in_world[i] - pattern.position_right_ankle_in_world[i]
        np.testing.assert_allclose(gap, [0.0, hubo.hip_spacing, 0.0], atol=1e-12)
    assert pattern.support[0] == 0 and pattern.support[-1] == 0


# --------------------------------------------------------------------- continuity, landing

durations = st.sampled_from([0.7, 0.75, 0.8, 0.9, 0.95, 1.1])


@st.composite
def step_commands(draw):
    mode = draw(st.sampled_from(["forward", "backward", "spot", "side", "turn", "curve", "stop"]))
    duration = draw(durations)
    if mode == "forward":
        return StepCommand(duration, draw(st.floats(0.0, 0.3)))
    if mode == "backward":
        return StepCommand(duration, -draw(st.floats(0.0, 0.15)))
    if mode == "spot":
        return StepCommand(duration, 0.0)
    if mode == "side":
        return StepCommand(duration, side=draw(st.sampled_from([-1, 1])) * draw(st.floats(0.01, 0.07)))
    if mode == "turn":
        return StepCommand(duration, turn=draw(st.sampled_from([-1, 1])) * draw(st.floats(0.02, 0.25)))
    if mode == "curve":
        sign = draw(st.sampled_from([-1, 1]))
        return StepCommand(duration, draw(st.floats(0.0, 0.15)), turn=sign * draw(st.floats(0.02, 0.15)))
    return StepCommand(duration, stop=True)


def _breakpoints(stage):
    """Every time inside a stage where a piece of some trajectory ends."""
    d = stage.dsp_time
    t1, T = stage.start, stage.duration
    points = [t1 + d / 2, t1 + T - d / 2, t1 + stage.sway_out_time, t1 + T - stage.sway_back_time, t1 + T / 2]
    if not stage.grounded:
        u = stage.plan.parameters.up_ratio
        points.append(t1 + d / 2 + u * (T - d))
    if stage.lipm is not None:  # the hyperbolic pelvis's pieces
        points += [t1 + start for axis in (stage.lipm.along, stage.lipm.across) for start in axis.starts]
    return [p for p in points if t1 < p < t1 + T]


def _all_breakpoints(stages):
    """The breakpoints of every stage but the last, and the index of each one's stage."""
    pairs = [(point, i) for i, stage in enumerate(stages[:-1]) for point in _breakpoints(stage)]
    return np.array([p for p, _ in pairs]), np.array([i for _, i in pairs], dtype=np.intp)


def _state(samples):
    position = np.hstack([samples.pelvis_xy, samples.left_position, samples.right_position,
                          samples.pelvis_yaw[:, None], samples.left_yaw[:, None], samples.right_yaw[:, None]])
    velocity = np.hstack([samples.pelvis_velocity_xy, samples.left_velocity, samples.right_velocity,
                          samples.pelvis_yaw_rate[:, None], samples.left_yaw_rate[:, None],
                          samples.right_yaw_rate[:, None]])
    return position, velocity


def assert_continuous(robot, stages):
    table = StageTable(stages)
    # Stage boundaries: the end of stage k against the start of stage k + 1.
    k = np.arange(len(stages) - 1)
    times = table.start[1:]
    before = evaluate(table, times, robot, k)
    after = evaluate(table, times, robot, k + 1)
    p0, v0 = _state(before)
    p1, v1 = _state(after)
    np.testing.assert_allclose(p0, p1, atol=POSITION_TOL, rtol=0)
    np.testing.assert_allclose(v0, v1, atol=VELOCITY_TOL, rtol=0)
    # Phase boundaries inside each stage: one-sided limits.
    times_a, index_a = _all_breakpoints(stages)
    left = _state(evaluate(table, times_a - EPS, robot, index_a))
    right = _state(evaluate(table, times_a + EPS, robot, index_a))
    exact = _state(evaluate(table, times_a, robot, index_a))  # the breakpoint itself, where pieces meet
    np.testing.assert_allclose(left[0], right[0], atol=POSITION_TOL, rtol=0)
    np.testing.assert_allclose(left[1], right[1], atol=VELOCITY_TOL, rtol=0)
    np.testing.assert_allclose(exact[0], right[0], atol=POSITION_TOL, rtol=0)
    np.testing.assert_allclose(exact[1], right[1], atol=VELOCITY_TOL, rtol=0)


@pytest.mark.slow
@pytest.mark.parametrize("pelvis", ["cubic", "hyperbolic"])
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(step_commands(), min_size=10, max_size=16))
def test_positions_and_velocities_are_continuous_for_random_command_sequences(hubo, schedule, pelvis, commands):
    """Both online generators: the polynomial (cubic pelvis) and the hyperbolic (the pendulum's own motion)."""
    try:
        stages, _ = plan_walk(hubo, commands, schedule, pelvis=pelvis)
    except ZmpwalkError:
        return  # an infeasible sequence is rejected as a whole (tested elsewhere)
    assert_continuous(hubo, stages)


@pytest.mark.parametrize("pelvis", ["cubic", "hyperbolic"])
def test_random_sequences_are_mostly_feasible(hubo, schedule, pelvis):
    """Guard for the property test above: the strategy must not be rejected wholesale."""
    rng = np.random.default_rng(3)
    feasible = 0
    for _ in range(50):
        commands = []
        for _ in range(10):
            duration = float(rng.choice([0.7, 0.8, 0.95]))
            mode = rng.integers(4)
            if mode == 0:
                commands.append(StepCommand(duration, float(rng.uniform(0, 0.3))))
            elif mode == 1:
                commands.append(StepCommand(duration, side=float(rng.uniform(-0.07, 0.07))))
            elif mode == 2:
                commands.append(StepCommand(duration, turn=float(rng.uniform(-0.25, 0.25))))
            else:
                forward, turn = float(rng.uniform(0, 0.15)), float(rng.uniform(-0.15, 0.15))
                commands.append(StepCommand(duration, forward, turn=turn))
        try:
            plan_walk(hubo, commands, schedule, pelvis=pelvis)
            feasible += 1
        except ZmpwalkError:
            pass
    assert feasible >= 45


class _Reference:
    """Independent bookkeeping of where the feet must be after each command (not the planner's formula)."""

    def __init__(self, spacing):
        self.w = spacing
        self.center = np.zeros(2)
        self.heading = 0.0
        self.feet = {1: np.array([0.0, spacing / 2]), -1: np.array([0.0, -spacing / 2])}
        self.next = 1

    def _lateral(self):
        return np.array([-math.sin(self.heading), math.cos(self.heading)])

    def apply(self, command):
        forward = np.array([math.cos(self.heading), math.sin(self.heading)])
        if command.side or command.turn:  # two stages; feet parallel at both ends
            lead = 1 if (command.side > 0 or (command.side == 0 and command.turn > 0)) else -1
            if self.next == -lead:  # an inserted plain step
                self._plain(-lead, command.forward)
            self.center = self.center + command.side * self._lateral() + command.forward * forward
            self.heading += command.turn
            forward = np.array([math.cos(self.heading), math.sin(self.heading)])
            self.center = self.center + command.forward * forward
            for foot in (1, -1):
                self.feet[foot] = self.center + foot * self.w / 2 * self._lateral()
            self.next = lead
        else:
            self._plain(self.next, command.forward)
            if command.stop:
                self.next = 1

    def _plain(self, foot, stride):
        forward = np.array([math.cos(self.heading), math.sin(self.heading)])
        self.feet[foot] = self.feet[-foot] + stride * forward + foot * self.w * self._lateral()
        self.center = (self.feet[1] + self.feet[-1]) / 2
        self.next = -foot


@pytest.mark.parametrize("pelvis", ["cubic", "hyperbolic"])
def test_feet_land_where_simple_commands_say(hubo, schedule, pelvis):
    commands = ([StepCommand(0.8, 0.2)] * 3 + [StepCommand(0.95, side=0.05)] * 2 + [StepCommand(0.8, 0.0)]
                + [StepCommand(0.95, turn=0.2)] * 3 + [StepCommand(0.8, -0.1)] * 2 + [StepCommand(0.7, side=-0.03)])
    reference = _Reference(hubo.hip_spacing)
    for command in commands:
        reference.apply(command)
    stages, _ = plan_walk(hubo, commands, schedule, pelvis=pelvis)
    # The closing stop of plan_walk lands the last swing beside the other foot.
    last = [s for s in stages if s.plan.kind == "stop"][-1]
    reference.apply(StepCommand(last.duration, stop=True))
    end = stages[-1].start
    sample = evaluate(StageTable(stages), np.array([end]), hubo)
    np.testing.assert_allclose(sample.left_position[0, :2], reference.feet[1], atol=POSITION_TOL)
    np.testing.assert_allclose(sample.right_position[0, :2], reference.feet[-1], atol=POSITION_TOL)
    assert sample.left_yaw[0] == pytest.approx(reference.heading, abs=1e-12)


def _rigid(pose_from, pose_to):
    """Planar transform (rotation angle, translation in pose_from's frame) taking one pose to another."""
    c, s = math.cos(pose_from[2]), math.sin(pose_from[2])
    dx, dy = pose_to[0] - pose_from[0], pose_to[1] - pose_from[1]
    return pose_to[2] - pose_from[2], np.array([c * dx + s * dy, -s * dx + c * dy])


@pytest.mark.slow
@pytest.mark.parametrize("stride, turn", [(0.2, 0.0), (0.0, 0.15), (0.1, 0.1)])
def test_no_drift_after_ten_thousand_steps(hubo, schedule, stride, turn):
    """Every command repeats the same rigid motion of the stance, so step N is known in closed form."""
    n = 10_000
    command = StepCommand(0.8, stride, turn=turn)
    stance, boundary = Stance.ready(hubo), Boundary(0.0)
    poses = []
    for _ in range(n):
        stages, stance, boundary = plan_next(hubo, schedule, stance, boundary, command)
        poses.append((stance.left.x, stance.left.y, stance.left.yaw))
    # The motion per period (two single-swing commands, or one two-stage command), in steady state.
    period = 1 if command.is_two_stage else 2
    first = 2
    angle, step = _rigid(poses[first], poses[first + period])
    assert angle == pytest.approx(period * turn, abs=1e-15)
    last = first + period * ((n - 1 - first) // period)
    # Closed form: p_last = p_first + R(psi_first) sum_{k=0}^{count-1} R(k angle) step.
    k = np.arange((last - first) // period)
    rotated = np.stack([np.cos(k * angle) * step[0] - np.sin(k * angle) * step[1],
                        np.sin(k * angle) * step[0] + np.cos(k * angle) * step[1]], axis=1)
    total = np.sum(rotated, axis=0, dtype=np.longdouble).astype(float)
    c, s = math.cos(poses[first][2]), math.sin(poses[first][2])
    expected = np.array(poses[first][:2]) + np.array([c * total[0] - s * total[1], s * total[0] + c * total[1]])
    np.testing.assert_allclose(poses[last][:2], expected, atol=POSITION_TOL, rtol=0)
    assert poses[last][2] == pytest.approx(poses[first][2] + len(k) * angle, abs=1e-9)
    # The sampled ankle at the end of the last swing is the planned landing.
    last = stages[-1]
    sample = evaluate(StageTable([last]), np.array([last.stop_time]), hubo, np.zeros(1, dtype=np.intp))
    landed = sample.left_position if last.plan.swing == 1 else sample.right_position
    np.testing.assert_allclose(landed[0, :2], [last.plan.swing_end.x, last.plan.swing_end.y], atol=POSITION_TOL)


# --------------------------------------------------------------------- long walks in pieces

@pytest.mark.parametrize("rate", [100.0, 333.0, 1000.0])
def test_pieces_of_a_walk_join_to_the_whole_pattern(hubo, rate):
    """generate_chunks: the same samples, support phases, steps and ZMP margins as generate, piece by piece."""
    from zmpwalk.patterns.polynomial import generate_chunks
    from zmpwalk.zmp import signed_margin

    rng = np.random.default_rng(11)
    commands = [StepCommand(duration=float(rng.uniform(0.7, 1.0)), forward=float(rng.uniform(-0.1, 0.2)),
                            side=float(rng.choice([0.0, 0.05, -0.05])), turn=float(rng.choice([0.0, 0.1, -0.1])))
                for _ in range(25)]
    whole = generate(hubo, commands, rate=rate)
    pieces = list(generate_chunks(hubo, commands, rate=rate, chunk_stages=4))
    assert len(pieces) > 5
    for name in ("time", "zmp_in_world", "position_pelvis_in_world", "position_left_ankle_in_world",
                 "velocity_right_ankle_in_world", "yaw_pelvis_in_world", "support"):
        joined = np.concatenate([getattr(piece, name) for piece in pieces])
        np.testing.assert_array_equal(joined, getattr(whole, name))  # bit for bit
    assert [s for piece in pieces for s in piece.steps] == whole.steps
    margin = np.concatenate([piece.zmp_margin() for piece in pieces])
    np.testing.assert_allclose(margin, whole.zmp_margin(), atol=1e-12)  # [m]
    # the vectorised margin against one polygon at a time
    polygons = whole.support_polygons()
    begins = np.array([phase.begin for phase in whole.support_phases])
    which = np.clip(np.searchsorted(begins, whole.time, side="right") - 1, 0, len(begins) - 1)
    for i in range(0, len(whole.time), 13):
        expected = signed_margin(whole.zmp_in_world[i:i + 1], polygons[which[i]])[0]
        assert margin[i] == pytest.approx(expected, abs=1e-12)  # [m]


def test_chunk_size_is_checked(hubo):
    from zmpwalk.patterns.polynomial import generate_chunks

    with pytest.raises(ZmpwalkError, match="chunk_stages = 0"):
        generate_chunks(hubo, [StepCommand(0.8, 0.1)], chunk_stages=0)


# --------------------------------------------------------------------- the quintic (jerk-continuous) pelvis

ZMP_JUMP_TOL = 1e-6  # [m] one-sided limits of the cart-table ZMP at every breakpoint


def _zmp_and_acceleration(samples):
    return np.hstack([samples.zmp_xy, samples.pelvis_acceleration_xy])


@pytest.mark.slow
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(step_commands(), min_size=10, max_size=16))
def test_quintic_pelvis_keeps_the_cart_table_zmp_continuous_for_random_command_sequences(hubo, schedule,
                                                                                           commands):
    """pelvis="quintic": positions and velocities continuous as with the cubics, and the pelvis acceleration
    and the cart-table ZMP continuous too, at every stage boundary and every breakpoint inside a stage."""
    try:
        stages, _ = plan_walk(hubo, commands, schedule, pelvis="quintic")
    except ZmpwalkError:
        return
    assert_continuous(hubo, stages)
    table = StageTable(stages)
    k = np.arange(len(stages) - 1)
    before = _zmp_and_acceleration(evaluate(table, table.start[1:], hubo, k))
    after = _zmp_and_acceleration(evaluate(table, table.start[1:], hubo, k + 1))
    np.testing.assert_allclose(before, after, atol=ZMP_JUMP_TOL, rtol=0)
    times, index_a = _all_breakpoints(stages)
    left = _zmp_and_acceleration(evaluate(table, times - EPS, hubo, index_a))
    right = _zmp_and_acceleration(evaluate(table, times + EPS, hubo, index_a))
    np.testing.assert_allclose(left, right, atol=ZMP_JUMP_TOL, rtol=0)


def test_quintic_pelvis_changes_only_the_pelvis_between_the_same_boundary_states(hubo):
    """Same feet, same pelvis positions and velocities at every stage boundary; the cubic's ZMP jumps there.
    (Side steps keep their shift's timing and amplitude, but its speed at the step change is 2 S'(1/2) = 3.75
    instead of the cosine's pi, per unit step time: forward and backward steps here.)"""
    commands = [StepCommand(0.8, 0.2), StepCommand(0.8, 0.05), StepCommand(0.95, 0.1),
                StepCommand(0.7, -0.1)]
    cubic, quintic = generate(hubo, commands, rate=1000.0), generate(hubo, commands, rate=1000.0, pelvis="quintic")
    for name in ("position_left_ankle_in_world", "position_right_ankle_in_world", "yaw_left_foot_in_world",
                 "yaw_right_foot_in_world", "yaw_pelvis_in_world"):
        np.testing.assert_array_equal(getattr(cubic, name), getattr(quintic, name))
    stages, _ = plan_walk(hubo, commands, pelvis="quintic")
    boundaries = np.array([round(s.start * 1000.0) for s in stages[1:]])
    np.testing.assert_allclose(quintic.position_pelvis_in_world[boundaries], cubic.position_pelvis_in_world[boundaries],
                               atol=POSITION_TOL)
    np.testing.assert_allclose(quintic.velocity_pelvis_in_world[boundaries],
                               cubic.velocity_pelvis_in_world[boundaries], atol=VELOCITY_TOL)
    cubic_steps = np.linalg.norm(np.diff(cubic.zmp_in_world, axis=0), axis=1)
    quintic_steps = np.linalg.norm(np.diff(quintic.zmp_in_world, axis=0), axis=1)
    assert cubic_steps.max() > 0.1  # [m] the cubic's ZMP jumps by decimetres between two 1 kHz samples
    assert quintic_steps.max() < 0.01  # [m] the quintic's moves by millimetres at most


def test_online_walker_with_the_quintic_pelvis_reproduces_the_offline_pattern(hubo):
    commands = [StepCommand(0.95, 0.0), StepCommand(0.8, 0.2), StepCommand(0.7, 0.1, turn=0.1),
                StepCommand(0.8, side=0.05)]
    pattern = generate(hubo, commands, rate=200.0, pelvis="quintic")
    walker = OnlineWalker(hubo, rate=200.0, pelvis="quintic")
    pending, rows = list(commands), []
    for _ in range(len(pattern.time)):
        if pending and walker.queued is None:
            walker.command(pending.pop(0), wait=True)
        sample = walker.tick()
        rows.append(np.concatenate([sample.position_pelvis_in_world, sample.zmp_in_world]))
    expected = np.column_stack([pattern.position_pelvis_in_world, pattern.zmp_in_world])
    np.testing.assert_allclose(np.array(rows), expected, atol=1e-12)


def test_pelvis_option_is_checked(hubo):
    with pytest.raises(ZmpwalkError, match="pelvis = 'septic' is not allowed; expected one of cubic, quintic"):
        generate(hubo, [StepCommand(0.8, 0.1)], pelvis="septic")
    with pytest.raises(ZmpwalkError, match="pelvis"):
        OnlineWalker(hubo, pelvis="quartic")
