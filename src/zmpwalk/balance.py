r"""Balance feedback: a stabilizer that corrects the pattern's joint targets from measured forces and attitude.

One :class:`Stabilizer` per robot, called once per control tick with the pattern's sample and what a
humanoid measures (each sole's force-torque sensor, the torso IMU's attitude and rate, the joint
encoders); it returns corrected joint targets. The formulation is the position-controlled stabilizer of
Kajita et al. (2010, *Biped walking stabilization based on linear inverted pendulum tracking*, IROS) in the
divergent-component-of-motion form of Englsberger et al. (2015) and Caron et al. (2019, *Stair climbing
stabilization of the HRP-4 humanoid robot using whole-body admittance control*, ICRA), chosen because it
needs only what a position-controlled robot has (no torque control) and each of its parts is a small,
separately tunable loop. ``docs/balance.md`` derives it; in short, with ``omega = sqrt(g / l)``:

1. **DCM tracking.** The CoM ``c`` is estimated from the encoders and the IMU, anchored at the sole that
   has carried load the longest, whose place in world comes from leg odometry (while both soles carry load
   the newer one is placed from it by the measured kinematics, tick by tick, as is a sole that takes the load
   with no tick of both loaded; while the reference sole rolls
   on an edge, its ankle moves by the ankle height times the change of the sole normal's horizontal part),
   so a step landed short shows as a DCM error; the divergent component of motion ``xi = c + c' / omega``
   must follow the pattern's.
   Its error ``e = xi - xi_ref`` decays at rate ``k_xi`` when the ZMP is

   .. math:: p_d = p_{ref} + (1 + k_\xi / \omega)\, e, \qquad \dot e = -k_\xi e

   (from ``xi' = omega (xi - p)``), kept :attr:`StabilizerGains.zmp_margin` inside the support polygon.
2. **CoM admittance** realises ``p_d``: the commanded CoM accelerates by
   ``Delta c'' = A (p_measured - p_d) - K_v Delta c' - K_p Delta c`` (in the cart-table model
   ``p = c - c'' / omega^2``, accelerating forward moves the ZMP back).
3. **Ankle damping control** (the damping control of Kajita et al. 2010): each loaded sole's centre of
   pressure follows its share of ``p_d`` by turning the foot, ``delta' = -(tau_d - tau) / D - delta / T``,
   written per metre of CoP error.
4. **Foot force difference control** (Kajita et al. 2010): in double support the feet's heights move apart
   until the measured force difference is the desired one.
5. **Torso attitude**: the pelvis is turned against the measured roll and pitch (and their rates).
6. **Landing and stepping**: the swinging foot aims at its planned place in world from the odometry's
   base, seen through the measured pelvis attitude, moved by :attr:`StabilizerGains.step_gain` times the
   DCM error, towards where the body falls (the capture point of Pratt et al. 2006), and turns by the
   torso's measured yaw error so that it lands at its planned heading in world; the corrections are
   released once the foot carries load.
7. **Floor slope**: in double support both soles lie on the floor, so their attitude (IMU and measured leg
   kinematics) is the floor's; with unit normal ``n`` the CoM must stand ``l (n_x, n_y) / n_z`` uphill of
   its plan for the ZMP to stay where planned, and the CoM admittance is pulled to that offset instead of
   to zero.
8. **Servo stiffness**: a position servo of stiffness ``k`` that carries an unplanned torque ``tau`` sags
   by ``tau / k``; a leg joint whose servo is softer than :attr:`StabilizerGains.servo_stiffness` times
   ``m g l`` per radian (the weight's moment on the pendulum length: the sag angle is then the same on a
   robot of any size) gets an outer loop on its encoder, ``u = q_d + G (q_d - q)`` with
   ``G = kappa m g l / k - 1``, so that the servo acts with ``kappa m g l`` (Booster T1: 75 -> 294 N m/rad;
   TALOS: 1000 -> 1427).

All corrections are small offsets of the feet relative to the pelvis, mapped onto the joints through each
leg's Jacobian at the pattern's angles (``Delta q = J^{-1} Delta x``): nothing is planned or solved
iteratively on the control path, and the work per tick is fixed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import leg_chains, rest_mass
from zmpwalk.leg_chain import cross3
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]

MIN_SHARE = 1e-9  # [-] a sole's share of the desired ZMP below which its CoP is not controlled


@dataclass(frozen=True)
class StabilizerGains:
    """Gains of the stabilizer (see the module docstring), robot-independent units.

    Attributes:
        dcm: ``k_xi``, decay rate of the DCM error [1/s].
        com_admittance: ``A``, CoM acceleration per metre of ZMP error [1/s^2].
        com_stiffness: ``K_p``, pull of the CoM offset back to the pattern [1/s^2].
        com_damping: ``K_v`` [1/s].
        com_limit: Largest CoM offset [m].
        ankle_gain: Foot turn rate per metre of CoP error [rad/(s m)] (``F / D`` of Kajita's damping control).
        ankle_time_constant: ``T`` of the ankle offsets' return to zero [s].
        ankle_limit: Largest foot turn [rad].
        force_gain: Foot height rate per newton of force-difference error per newton of weight [m/s].
        force_time_constant: Return of the height difference to zero [s].
        force_limit: Largest height difference [m].
        attitude_gain: Pelvis turn per radian of torso tilt [-].
        attitude_damping: Pelvis turn per rad/s of torso rate [s].
        attitude_limit: Largest pelvis turn [rad].
        zmp_margin: ``p_d`` is kept this far inside the support polygon [m].
        velocity_filter: Time constant of the CoM velocity estimate's low-pass filter [s].
        landing_time_constant: How fast a swinging foot's aim moves to its planned place in world [s].
        landing_release: How fast that correction is released once the foot carries load [s].
        landing_limit: Largest landing correction [m].
        slope_time_constant: Low-pass filter of the floor normal measured under both soles in double support
            [s]; 0 turns the slope compensation off.
        step_gain: The swinging foot's aim moves by this fraction of the DCM error (a step towards where the
            body is falling) [-]; 1 puts it on the capture point (Pratt et al. 2006: the DCM error is how far
            ahead of its plan the body will come to rest over the ZMP), 0 lands it where planned.
        step_deadband: The part of the DCM error's length that does not move the aim [m] (nominal walking
            stays within it, so only a push makes the foot step aside).
        landing_yaw_limit: Largest turn of a swinging foot towards its planned heading in world [rad] (the
            torso's measured yaw error, which a sole slipping in yaw leaves; 0 turns it off).
        servo_stiffness: ``kappa``: each leg servo softer than ``kappa m g l`` per radian (m the robot's mass,
            l its pendulum length) is stiffened to it by an outer loop on its encoder [-]; 0 turns it off.
    """

    dcm: float = 3.0  # [1/s]
    com_admittance: float = 20.0  # [1/s^2]
    com_stiffness: float = 10.0  # [1/s^2]
    com_damping: float = 6.0  # [1/s]
    com_limit: float = 0.05  # [m]
    ankle_gain: float = 2.0  # [rad/(s m)]
    ankle_time_constant: float = 0.5  # [s]
    ankle_limit: float = 0.12  # [rad]
    force_gain: float = 0.05  # [m/s]
    force_time_constant: float = 0.5  # [s]
    force_limit: float = 0.03  # [m]
    attitude_gain: float = 0.5  # [-]
    attitude_damping: float = 0.02  # [s]
    attitude_limit: float = 0.15  # [rad]
    zmp_margin: float = 0.01  # [m]
    velocity_filter: float = 0.01  # [s]
    landing_time_constant: float = 0.2  # [s]
    landing_release: float = 0.3  # [s]
    landing_limit: float = 0.1  # [m]
    slope_time_constant: float = 0.5  # [s]
    step_gain: float = 1.0  # [-]
    step_deadband: float = 0.03  # [m]
    landing_yaw_limit: float = 0.1  # [rad]
    servo_stiffness: float = 1.7  # [-] of m g l per rad

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                       and value >= 0):
                raise InvalidParameterError(f"gains.{name}", value, "a finite number >= 0")


@dataclass
class BalanceMeasurement:
    """What the robot measures at one tick.

    Attributes:
        wrench_left, wrench_right: Force [N] (3) then torque [N m] (3) that the ground exerts on each foot,
            about the ankle point, in the foot frame (x forward along the sole, y left, z up), (6,).
        attitude: Torso (base) roll and pitch [rad] from the IMU, (2,).
        rate: Torso angular velocity in the base frame [rad/s] (gyro), (3,).
        joint_angles: The 12 leg joint encoders [rad], columns of :data:`zmpwalk.kinematics.JOINT_COLUMNS`.
        yaw: Torso heading in world [rad] (the IMU's, from the walk's start), or None to use the pattern's.
    """

    wrench_left: Array
    wrench_right: Array
    attitude: Array
    rate: Array
    joint_angles: Array
    yaw: float | None = None


@dataclass
class BalanceState:
    """What the stabilizer did at the last tick (for plots and logs), in world unless said otherwise.

    :attr:`Stabilizer.state` is one object whose arrays every update overwrites: copy what you keep.

    Attributes:
        zmp_desired: ``p_d`` [m], (2,).
        zmp_measured: From both soles' sensors [m], (2,) (nan when no sole is loaded).
        dcm_error: ``xi - xi_ref`` [m], (2,).
        com_offset: The CoM admittance's offset [m], (2,).
        ankle_offsets: Foot turns (roll, pitch) of the left and right foot [rad], (2, 2).
        height_difference: Left foot lowered, right raised by half of this [m].
        pelvis_turn: Roll and pitch of the pelvis correction [rad], (2,).
        slope_offset: Where the floor's slope puts the CoM offset [m], (2,).
    """

    zmp_desired: Array
    zmp_measured: Array
    dcm_error: Array
    com_offset: Array
    ankle_offsets: Array
    height_difference: float
    pelvis_turn: Array
    slope_offset: Array = field(default_factory=lambda: np.zeros(2))


class Stabilizer:
    """Balance feedback for one robot at a fixed control rate (see the module docstring).

    Args:
        robot: The robot (legs, masses, soles).
        rate: Control rate [Hz].
        gains: The gains (defaults suit HUBO, TALOS and Booster T1 in the simulation; docs/balance.md).

    The first :meth:`update` initialises the filters; :meth:`reset` forgets the state.
    """

    def __init__(self, robot: RobotModel, rate: float, gains: StabilizerGains | None = None) -> None:
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 10.0 <= rate <= 10_000.0:
            raise InvalidParameterError("rate", rate, "a control rate in [10, 10000] Hz")
        self.robot = robot
        self.gains = gains or StabilizerGains()
        self.dt = 1.0 / float(rate)
        self.omega = math.sqrt(robot.gravity / robot.pendulum_length)
        self.chains = leg_chains(robot)
        rest, rest_com = rest_mass(robot)
        self._mass = rest + sum(float(c.link_masses.sum()) for c in self.chains)
        self._rest_moment = tuple(float(v) for v in rest * np.asarray(rest_com))  # m_rest c_rest in the base [kg m]
        self._half_length = robot.foot_length / 2
        self._half_width = robot.foot_width / 2
        # Both legs' kinematics in one batch of four poses: (left, right) x (measured, reference).
        chains = (self.chains[0], self.chains[0], self.chains[1], self.chains[1])
        skews = np.array([[[[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]] for w in c.axes]
                          for c in chains])  # (4, 6, 3, 3)
        points = np.array([c.points for c in chains])  # (4, 6, 3)
        self._skews = skews
        self._skews2 = skews @ skews
        # exp(xi q) maps x -> R x + (I - R) r with (I - R) r = -(sin q) K r - (1 - cos q) K^2 r
        self._skew_points = np.einsum("lkij,lkj->lki", skews, points)  # (4, 6, 3)
        self._skew2_points = np.einsum("lkij,lkj->lki", self._skews2, points)
        self._axes = np.array([c.axes for c in chains])  # (4, 6, 3)
        self._points = points
        self._ankles = np.array([c.ankle for c in chains])  # (4, 3)
        self._link_masses = np.array([c.link_masses for c in self.chains])  # (2, 6)
        self._link_coms = np.array([c.link_coms for c in self.chains])  # (2, 6, 3)
        # gather the 12 measured and 12 reference columns into the four chain-ordered poses
        gather = np.empty((4, 6), dtype=np.intp)
        for leg, chain in enumerate(self.chains):
            inverse = np.argsort(np.asarray(chain.role_order))  # chain index -> role index
            gather[2 * leg] = 6 * leg + inverse  # measured columns are 0..11
            gather[2 * leg + 1] = 12 + 6 * leg + inverse  # reference columns are 12..23
        self._gather = gather
        self._scatter = [list(chain.role_order) for chain in self.chains]
        self._eye = np.eye(3)
        # 8. the outer loop's gain per joint column: G = kappa m g l / k - 1 where the servo is softer
        stiffness = servo_stiffness(robot)
        wanted = self.gains.servo_stiffness * self._mass * robot.gravity * robot.pendulum_length
        self.servo_gain = (np.zeros(12) if stiffness is None
                           else np.maximum(wanted / np.maximum(stiffness, 1e-9) - 1.0, 0.0))
        self._stiffen = bool(self.servo_gain.any())
        self.reset()

    def reset(self) -> None:
        """Forget the filters and offsets (the next update starts from the reference)."""
        self._started = False
        self._previous_reference = (0.0, 0.0)
        self._previous_relative = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        self._com_velocity = [0.0, 0.0]
        self._offset = [0.0, 0.0]
        self._offset_rate = [0.0, 0.0]
        self._ankle = [[0.0, 0.0], [0.0, 0.0]]
        self._height = 0.0
        self._feet = [[0.0, 0.0], [0.0, 0.0]]  # estimated ankle positions in world (leg odometry) [m]
        self._landing = [[0.0, 0.0], [0.0, 0.0]]  # landing corrections of the feet in world [m]
        self._landing_yaw = [0.0, 0.0]  # yaw landing corrections of the feet relative to the pelvis [rad]
        self._anchor = 0
        self._floor_normal = [0.0, 0.0, 1.0]  # filtered, in world (gravity up)
        self._sole_normals = [(0.0, 0.0), (0.0, 0.0)]  # horizontal parts of each sole's normal in world, last tick
        self.state = BalanceState(np.zeros(2), np.full(2, np.nan), np.zeros(2), np.zeros(2), np.zeros((2, 2)),
                                  0.0, np.zeros(2))

    def _kinematics(self, poses: Array) -> tuple[Array, Array]:
        """Cumulative rotations (4, 7, 3, 3) and translations (4, 7, 3) of the four chain poses (4, 6) [rad]:
        the product of exponentials of :meth:`zmpwalk.leg_chain.LegChain.transforms`, both legs at once."""
        sines, versines = np.sin(poses)[:, :, None], (1.0 - np.cos(poses))[:, :, None]
        joints = self._eye + sines[..., None] * self._skews + versines[..., None] * self._skews2  # (4, 6, 3, 3)
        rotations = np.empty((4, 7, 3, 3))
        rotations[:, 0] = self._eye
        rotations[:, 1] = joints[:, 0]
        for i in range(1, 6):
            rotations[:, i + 1] = rotations[:, i] @ joints[:, i]
        shifts = -(sines * self._skew_points + versines * self._skew2_points)  # (I - R_i) r_i, (4, 6, 3)
        translations = np.empty((4, 7, 3))
        translations[:, 0] = 0.0
        np.cumsum((rotations[:, :6] @ shifts[..., None])[..., 0], axis=1, out=translations[:, 1:])
        return rotations, translations

    def update(self, *, support: int, position_com_in_world: Array, yaw_pelvis_in_world: float, zmp_in_world: Array,
               ankles_in_world: tuple[Array, Array], foot_yaws: tuple[float, float], joint_angles: Array,
               measurement: BalanceMeasurement) -> Array:
        """Corrected joint targets (12,) [rad] for one tick.

        Args:
            support: The pattern's support at this tick: 0 double, 1 left, 2 right.
            position_com_in_world: The pattern's CoM point [m] (3,) (the pelvis point of the pattern).
            yaw_pelvis_in_world: [rad].
            zmp_in_world: The pattern's ZMP [m] (2,).
            ankles_in_world: Planned left and right ankle positions [m], each (3,).
            foot_yaws: Planned foot yaws [rad].
            joint_angles: The pattern's 12 joint angles [rad].
            measurement: The sensors (:class:`BalanceMeasurement`).

        The work is fixed: one batch of leg kinematics (both legs, measured and reference angles), one
        6 x 6 solve per leg, and scalar arithmetic; nothing is planned or iterated.
        """
        g, dt, omega = self.gains, self.dt, self.omega
        yaw = float(yaw_pelvis_in_world)
        yaw_left, yaw_right = float(foot_yaws[0]), float(foot_yaws[1])
        rx, ry = float(position_com_in_world[0]), float(position_com_in_world[1])
        if not self._started:
            self._previous_reference = (rx, ry)
        vrx, vry = (rx - self._previous_reference[0]) / dt, (ry - self._previous_reference[1]) / dt
        self._previous_reference = (rx, ry)
        # --- measured sole wrenches
        wl, wr = measurement.wrench_left, measurement.wrench_right
        f0, f1 = float(wl[2]), float(wr[2])
        threshold = 0.05 * self._mass * self.robot.gravity
        loaded0, loaded1 = f0 > threshold, f1 > threshold
        # --- CoM estimate: kinematics of the measured legs, tilted by the IMU, anchored at the loaded sole
        roll, pitch = float(measurement.attitude[0]), float(measurement.attitude[1])
        heading = yaw if measurement.yaw is None else float(measurement.yaw)
        rot = _rotation_zyx(heading, pitch, roll)
        reference_angles = np.asarray(joint_angles, dtype=float)
        columns = np.concatenate([np.asarray(measurement.joint_angles, dtype=float), reference_angles])
        rotations, translations = self._kinematics(columns[self._gather])
        ankles = translations[:, 6] + (rotations[:, 6] @ self._ankles[:, :, None])[:, :, 0]  # (4, 3) in the base
        measured = rotations[0::2, 1:]  # the measured poses' segment frames (2, 6, 3, 3)
        coms = (measured @ self._link_coms[:, :, :, None])[..., 0] + translations[0::2, 1:]  # (2, 6, 3)
        moment = np.einsum("lk,lki->i", self._link_masses, coms)
        com_in_base = [(self._rest_moment[i] + float(moment[i])) / self._mass for i in range(3)]
        relative = (tuple(ankles[0].tolist()), tuple(ankles[2].tolist()))
        planned_relative = (ankles[1].tolist(), ankles[3].tolist())
        sole_normals = [_rotate3(rot, rotations[2 * foot, 6, :, 2].tolist())[:2] for foot in range(2)]  # in world
        if not self._started:
            self._sole_normals = sole_normals
            self._previous_relative = relative
            self._feet = [[float(ankles_in_world[0][0]), float(ankles_in_world[0][1])],
                          [float(ankles_in_world[1][0]), float(ankles_in_world[1][1])]]
            self._anchor = 0 if f0 >= f1 else 1
            self._started = True
        # Leg odometry: the sole that has carried load the longest is the reference. While the other carries
        # load too, it is placed from the reference by the measured kinematics at every tick, so a foot that
        # lands heel first and rolls flat is followed; when the reference unloads, the other one takes over.
        anchor = self._anchor
        # A loaded sole that tilts rolls on an edge below its ankle (a heel-first landing rolling flat): the
        # ankle moves by the ankle height times the change of the sole normal's horizontal part.
        if loaded0 if anchor == 0 else loaded1:
            now, last = sole_normals[anchor], self._sole_normals[anchor]
            h = self.robot.ankle_height
            self._feet[anchor][0] += h * (now[0] - last[0])
            self._feet[anchor][1] += h * (now[1] - last[1])
        self._sole_normals = sole_normals
        loaded_now = 0 if loaded0 else 1
        if (loaded0 and loaded1) or (loaded0 != loaded1 and loaded_now != anchor):
            # Both carry load, or the load passed to the other sole with no tick of both (a hurried step after
            # a push): the other sole is placed from the reference one by the measured kinematics.
            other_foot = 1 - anchor
            d = _rotate3(rot, _sub3(relative[other_foot], relative[anchor]))
            self._feet[other_foot] = [self._feet[anchor][0] + d[0], self._feet[anchor][1] + d[1]]
        if loaded0 != loaded1:
            anchor = self._anchor = loaded_now
        foot_anchor = self._feet[anchor]
        # --- 6. floor slope: the soles' normal in world (IMU and measured kinematics), low-pass filtered
        normal = self._floor_normal
        if g.slope_time_constant > 0.0 and loaded0 and loaded1:  # both soles down: both flat on the floor
            soles = rotations[0::2, 6, :, 2].sum(axis=0)
            measured_normal = _rotate3(rot, (float(soles[0]) / 2, float(soles[1]) / 2, float(soles[2]) / 2))
            beta = dt / (g.slope_time_constant + dt)
            for i in range(3):
                normal[i] += beta * (measured_normal[i] - normal[i])
        slope_x = self.robot.pendulum_length * normal[0] / normal[2] if g.slope_time_constant > 0.0 else 0.0
        slope_y = self.robot.pendulum_length * normal[1] / normal[2] if g.slope_time_constant > 0.0 else 0.0
        slope_norm = math.hypot(slope_x, slope_y)
        if slope_norm > g.com_limit:
            slope_x, slope_y = slope_x * g.com_limit / slope_norm, slope_y * g.com_limit / slope_norm
        arm = _rotate3(rot, _sub3(com_in_base, relative[anchor]))
        cx, cy = foot_anchor[0] + arm[0], foot_anchor[1] + arm[1]
        # Where the feet are (odometry; the swing foot follows from the stance foot and the kinematics): the
        # measured CoPs, the support polygon and the wrench distribution use these places.
        other = _rotate3(rot, _sub3(relative[1 - anchor], relative[anchor]))
        feet = [(foot_anchor[0], foot_anchor[1]), (foot_anchor[0] + other[0], foot_anchor[1] + other[1])]
        if anchor == 1:
            feet.reverse()
        h = self.robot.ankle_height
        cops = [(0.0, 0.0), (0.0, 0.0)]
        for foot, wrench, loaded, foot_yaw in ((0, wl, loaded0, yaw_left), (1, wr, loaded1, yaw_right)):
            if loaded:
                w0, w1, w2, w3, w4 = (float(wrench[i]) for i in range(5))
                local = _rotate2(-(w4 + h * w0) / w2, (w3 - h * w1) / w2, foot_yaw)
                cops[foot] = (feet[foot][0] + local[0], feet[foot][1] + local[1])
        zmx = zmy = math.nan
        if loaded0 or loaded1:
            a0, a1 = (f0 if loaded0 else 0.0), (f1 if loaded1 else 0.0)
            zmx = (a0 * cops[0][0] + a1 * cops[1][0]) / (a0 + a1)
            zmy = (a0 * cops[0][1] + a1 * cops[1][1]) / (a0 + a1)
        previous_arm = _rotate3(rot, _sub3(com_in_base, self._previous_relative[anchor]))
        rate = measurement.rate
        spin = _rotate3(rot, (float(rate[0]), float(rate[1]), float(rate[2])))
        raw_vx = (arm[0] - previous_arm[0]) / dt + (spin[1] * arm[2] - spin[2] * arm[1])
        raw_vy = (arm[1] - previous_arm[1]) / dt + (spin[2] * arm[0] - spin[0] * arm[2])
        self._previous_relative = relative
        alpha = dt / (g.velocity_filter + dt)
        velocity = self._com_velocity
        velocity[0] += alpha * (raw_vx - velocity[0])
        velocity[1] += alpha * (raw_vy - velocity[1])
        # --- 1. DCM feedback -> desired ZMP inside the support polygon
        ex = (cx + velocity[0] / omega) - (rx + vrx / omega)
        ey = (cy + velocity[1] / omega) - (ry + vry / omega)
        gain = 1.0 + g.dcm / omega
        pdx, pdy = self._clamp(float(zmp_in_world[0]) + gain * ex, float(zmp_in_world[1]) + gain * ey,
                               support, feet, (yaw_left, yaw_right))
        # --- 2. CoM admittance
        offset, offset_rate = self._offset, self._offset_rate
        if loaded0 or loaded1:
            ax, ay = g.com_admittance * (zmx - pdx), g.com_admittance * (zmy - pdy)
        else:
            ax = ay = 0.0
        ax -= g.com_damping * offset_rate[0] + g.com_stiffness * (offset[0] + slope_x)
        ay -= g.com_damping * offset_rate[1] + g.com_stiffness * (offset[1] + slope_y)
        offset_rate[0] += ax * dt
        offset_rate[1] += ay * dt
        offset[0] += offset_rate[0] * dt
        offset[1] += offset_rate[1] * dt
        norm = math.hypot(offset[0], offset[1])
        if norm > g.com_limit:
            offset[0] *= g.com_limit / norm
            offset[1] *= g.com_limit / norm
            offset_rate[0] = offset_rate[1] = 0.0
        # --- 3. ankle damping: each loaded sole's CoP follows its share of p_d
        shares, targets = self._distribute(pdx, pdy, support, feet, (yaw_left, yaw_right))
        decay = dt / g.ankle_time_constant
        limit = g.ankle_limit
        for foot, loaded, foot_yaw in ((0, loaded0, yaw_left), (1, loaded1, yaw_right)):
            turn_foot = self._ankle[foot]
            if loaded and shares[foot] > MIN_SHARE:
                error = _rotate2(targets[foot][0] - cops[foot][0], targets[foot][1] - cops[foot][1], -foot_yaw)
                turn_foot[0] += dt * (-g.ankle_gain * error[1])
                turn_foot[1] += dt * (g.ankle_gain * error[0])
            turn_foot[0] = min(max(turn_foot[0] - decay * turn_foot[0], -limit), limit)
            turn_foot[1] = min(max(turn_foot[1] - decay * turn_foot[1], -limit), limit)
        # --- 4. foot force difference (double support)
        weight = f0 + f1
        if support == 0 and loaded0 and loaded1 and weight > 0:
            wanted = (shares[0] - shares[1]) * weight
            self._height += dt * g.force_gain * (wanted - (f0 - f1)) / weight
        self._height -= dt / g.force_time_constant * self._height
        self._height = min(max(self._height, -g.force_limit), g.force_limit)
        # --- 5. torso attitude
        turn_roll = min(max(-g.attitude_gain * roll - g.attitude_damping * float(rate[0]), -g.attitude_limit),
                        g.attitude_limit)
        turn_pitch = min(max(-g.attitude_gain * pitch - g.attitude_damping * float(rate[1]), -g.attitude_limit),
                         g.attitude_limit)
        # --- 7. landing: a swinging foot aims at its planned place in world from where the base is (odometry),
        # not where the plan has it, moved by step_gain times the DCM error (a step towards where the body is
        # falling: the capture point of Pratt et al. 2006 lies xi - p ahead of the ZMP); the correction is
        # released once the foot carries load.
        stance = _rotate3(rot, relative[anchor])
        base_ex, base_ey = foot_anchor[0] - stance[0], foot_anchor[1] - stance[1]
        # the step towards the fall: step_gain times the DCM error beyond step_deadband
        error_norm = math.hypot(ex, ey)
        step = g.step_gain * max(error_norm - g.step_deadband, 0.0) / error_norm if error_norm > 0.0 else 0.0
        step_x, step_y = step * ex, step * ey
        landing_rate, release_rate = dt / g.landing_time_constant, dt / g.landing_release
        landing_limit = g.landing_limit
        # the swinging foot also turns by the torso's measured yaw error, so that it lands at its planned heading
        # in world (a sole that slipped in yaw leaves the torso turned by as much)
        yaw_aim = min(max(math.remainder(yaw - heading, math.tau), -g.landing_yaw_limit), g.landing_yaw_limit)
        for foot in range(2):
            land = self._landing[foot]
            swinging = (support == 1 and foot == 1) or (support == 2 and foot == 0)
            self._landing_yaw[foot] += (landing_rate * (yaw_aim - self._landing_yaw[foot]) if swinging
                                        else -release_rate * self._landing_yaw[foot])
            if swinging:
                # the foot's planned place seen from the estimated base through the measured attitude, less the
                # pelvis turn and shift applied to every foot below: what puts it there in world
                px, py, pz = planned_relative[foot]
                seen = _rotate3_back(rot, (float(ankles_in_world[foot][0]) - base_ex,
                                           float(ankles_in_world[foot][1]) - base_ey, pz))
                aim = _rotate2(seen[0] - px + turn_pitch * pz, seen[1] - py - turn_roll * pz, yaw)
                land[0] += landing_rate * (aim[0] + offset[0] + step_x - land[0])
                land[1] += landing_rate * (aim[1] + offset[1] + step_y - land[1])
            else:
                land[0] -= release_rate * land[0]
                land[1] -= release_rate * land[1]
            land[0] = min(max(land[0], -landing_limit), landing_limit)
            land[1] = min(max(land[1], -landing_limit), landing_limit)
        # --- corrections of the feet relative to the pelvis, onto the joints through the Jacobians
        shift = _rotate2(offset[0], offset[1], -yaw)
        changes = np.empty((2, 6))
        for leg, foot_yaw in ((0, yaw_left), (1, yaw_right)):
            px, py, pz = planned_relative[leg]
            landing = _rotate2(self._landing[leg][0], self._landing[leg][1], -yaw)
            foot_turn = _rotate2(self._ankle[leg][0], self._ankle[leg][1], foot_yaw - yaw)
            # minus pelvis_turn x position, pelvis_turn = (roll, pitch, 0)
            changes[leg] = (landing[0] - shift[0] - turn_pitch * pz, landing[1] - shift[1] + turn_roll * pz,
                            (-self._height / 2 if leg == 0 else self._height / 2) - (turn_roll * py - turn_pitch * px),
                            foot_turn[0] - turn_roll, foot_turn[1] - turn_pitch, self._landing_yaw[leg])
        deltas = np.linalg.solve(self._jacobians(rotations, translations, ankles), changes[:, :, None])[:, :, 0]
        result = reference_angles.copy()
        result[0:6] += deltas[0, self._scatter[0]]
        result[6:12] += deltas[1, self._scatter[1]]
        if self._stiffen:  # --- 8. servo stiffness: the encoder loop on the soft servos
            result += self.servo_gain * (result - columns[:12])
        state = self.state  # written in place: the control path allocates no state
        state.zmp_desired[:] = pdx, pdy
        state.zmp_measured[:] = zmx, zmy
        state.dcm_error[:] = ex, ey
        state.com_offset[:] = offset
        state.ankle_offsets[:] = self._ankle
        state.height_difference = self._height
        state.pelvis_turn[:] = turn_roll, turn_pitch
        state.slope_offset[:] = -slope_x, -slope_y
        return result

    def _jacobians(self, rotations: Array, translations: Array, ankles: Array) -> Array:
        """Geometric Jacobians (2, 6, 6) of the reference poses' ankle points in the base frame, rows
        (v, omega) (:meth:`zmpwalk.leg_chain.LegChain.jacobian`)."""
        frames = rotations[1::2, :6]  # (2, 6, 3, 3)
        axes = (frames @ self._axes[1::2, :, :, None])[..., 0]  # (2, 6, 3)
        origins = (frames @ self._points[1::2, :, :, None])[..., 0] + translations[1::2, :6]
        jacobians = np.empty((2, 6, 6))
        jacobians[:, :3, :] = np.swapaxes(cross3(axes, ankles[1::2, None, :] - origins), 1, 2)
        jacobians[:, 3:, :] = np.swapaxes(axes, 1, 2)
        return jacobians

    def _sole_centres(self, feet: list[tuple[float, float]], yaws: tuple[float, float]) -> list[tuple[float, float]]:
        cx, cy = self.robot.sole_center_x, self.robot.sole_center_y
        centres = []
        for foot, side in ((0, 1.0), (1, -1.0)):
            offset = _rotate2(cx, side * cy, yaws[foot])
            centres.append((feet[foot][0] + offset[0], feet[foot][1] + offset[1]))
        return centres

    def _distribute(self, zx: float, zy: float, support: int, feet: list[tuple[float, float]],
                    yaws: tuple[float, float]) -> tuple[tuple[float, float],
                                                        tuple[tuple[float, float], tuple[float, float]]]:
        """Load shares of the feet and each sole's CoP target [m] for a desired ZMP."""
        centres = self._sole_centres(feet, yaws)
        if support == 1:
            return (1.0, 0.0), ((zx, zy), centres[1])
        if support == 2:
            return (0.0, 1.0), (centres[0], (zx, zy))
        sx, sy = centres[1][0] - centres[0][0], centres[1][1] - centres[0][1]
        ratio = min(max(((zx - centres[0][0]) * sx + (zy - centres[0][1]) * sy) / max(sx * sx + sy * sy, 1e-12),
                        0.0), 1.0)
        dx, dy = zx - (centres[0][0] + ratio * sx), zy - (centres[0][1] + ratio * sy)
        targets = ((centres[0][0] + dx, centres[0][1] + dy), (centres[1][0] + dx, centres[1][1] + dy))
        return (1.0 - ratio, ratio), targets

    def _clamp(self, zx: float, zy: float, support: int, feet: list[tuple[float, float]],
               yaws: tuple[float, float]) -> tuple[float, float]:
        """The ZMP moved into the support polygon shrunk by the margin (single support: the sole; double:
        the segment between the soles' centres widened by the soles' half widths, a conservative hull)."""
        margin = self.gains.zmp_margin
        lx, ly = max(self._half_length - margin, 0.0), max(self._half_width - margin, 0.0)
        centres = self._sole_centres(feet, yaws)
        if support in (1, 2):
            foot = support - 1
            local = _rotate2(zx - centres[foot][0], zy - centres[foot][1], -yaws[foot])
            back = _rotate2(min(max(local[0], -lx), lx), min(max(local[1], -ly), ly), yaws[foot])
            return centres[foot][0] + back[0], centres[foot][1] + back[1]
        sx, sy = centres[1][0] - centres[0][0], centres[1][1] - centres[0][1]
        length = math.hypot(sx, sy)
        if length < 1e-9:
            return zx, zy
        ax, ay = sx / length, sy / length
        rx, ry = zx - centres[0][0], zy - centres[0][1]
        along = min(max(rx * ax + ry * ay, 0.0), length)
        across = min(max(-rx * ay + ry * ax, -lx), lx)
        return centres[0][0] + along * ax - across * ay, centres[0][1] + along * ay + across * ax


def servo_stiffness(robot: RobotModel) -> Array | None:
    """Stiffness of each leg joint's position servo [N m/rad], (12,) in the joint-column order; None where the
    robot gives none (a robot file without ``[servos]``)."""
    if robot.plant is not None:
        return np.array([j.actuator.kp if j.actuator is not None and j.actuator.kind == "position" else np.inf
                         for j in robot.plant.joints])
    if robot.servos is not None:
        return np.full(12, robot.servos.kp)
    return None


def _rotate2(x: float, y: float, angle: float) -> tuple[float, float]:
    """``(x, y)`` turned by ``angle`` [rad] about z."""
    c, s = math.cos(angle), math.sin(angle)
    return c * x - s * y, s * x + c * y


def _rotation_zyx(yaw: float, pitch: float, roll: float) -> tuple[float, ...]:
    """``Rz(yaw) Ry(pitch) Rx(roll)``, row-major (9 floats)."""
    cz, sz, cy, sy = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    cx, sx = math.cos(roll), math.sin(roll)
    return (cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
            sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
            -sy, cy * sx, cy * cx)


def _rotate3(r: tuple[float, ...], v: tuple[float, ...] | list[float]) -> tuple[float, float, float]:
    """The row-major rotation ``r`` applied to ``v``."""
    x, y, z = v[0], v[1], v[2]
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z, r[6] * x + r[7] * y + r[8] * z)


def _rotate3_back(r: tuple[float, ...], v: tuple[float, ...] | list[float]) -> tuple[float, float, float]:
    """The transpose of the row-major rotation ``r`` applied to ``v``."""
    x, y, z = v[0], v[1], v[2]
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z, r[2] * x + r[5] * y + r[8] * z)


def _sub3(a: tuple[float, ...] | list[float], b: tuple[float, ...] | list[float]) -> tuple[float, float, float]:
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


__all__ = ["BalanceMeasurement", "BalanceState", "Stabilizer", "StabilizerGains"]
