r"""Balance feedback: a stabilizer that corrects the pattern's joint targets from measured forces and attitude.

One :class:`Stabilizer` per robot, called once per control tick with the pattern's sample and what a
humanoid measures (each sole's force-torque sensor, the torso IMU's attitude and rate, the joint
encoders); it returns corrected joint targets. The formulation is the position-controlled stabilizer of
Kajita et al. (2010, *Biped walking stabilization based on linear inverted pendulum tracking*, IROS) in the
divergent-component-of-motion form of Englsberger et al. (2015) and Caron et al. (2019, *Stair climbing
stabilization of the HRP-4 humanoid robot using whole-body admittance control*, ICRA), chosen because it
needs only what a position-controlled robot has (no torque control) and each of its parts is a small,
separately tunable loop. ``docs/balance.md`` derives it; in short, with ``omega = sqrt(g / l)``:

1. **DCM tracking.** The CoM ``c`` is estimated from the encoders and the IMU, anchored at the loaded sole,
   whose place in world comes from leg odometry (when the load passes to the other sole, that sole is
   placed from the measured kinematics), so a step landed short shows as a DCM error; the divergent
   component of motion ``xi = c + c' / omega`` must follow the
   pattern's. Its error ``e = xi - xi_ref`` decays at rate ``k_xi`` when the ZMP is

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

All corrections are small offsets of the feet relative to the pelvis, mapped onto the joints through each
leg's Jacobian at the pattern's angles (``Delta q = J^{-1} Delta x``): nothing is planned or solved
iteratively on the control path, and the work per tick is fixed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import leg_chains, rest_mass
from zmpwalk.leg_chain import cross3
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


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

    Attributes:
        zmp_desired: ``p_d`` [m], (2,).
        zmp_measured: From both soles' sensors [m], (2,) (nan when no sole is loaded).
        dcm_error: ``xi - xi_ref`` [m], (2,).
        com_offset: The CoM admittance's offset [m], (2,).
        ankle_offsets: Foot turns (roll, pitch) of the left and right foot [rad], (2, 2).
        height_difference: Left foot lowered, right raised by half of this [m].
        pelvis_turn: Roll and pitch of the pelvis correction [rad], (2,).
    """

    zmp_desired: Array
    zmp_measured: Array
    dcm_error: Array
    com_offset: Array
    ankle_offsets: Array
    height_difference: float
    pelvis_turn: Array


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
        self._orders = [list(chain.role_order) for chain in self.chains]
        self._rest_mass, self._rest_com = rest_mass(robot)
        self._mass = self._rest_mass + sum(float(c.link_masses.sum()) for c in self.chains)
        self._half_length = robot.foot_length / 2
        self._half_width = robot.foot_width / 2
        self._sole_centre = np.array([robot.sole_center_x, robot.sole_center_y])
        self._angles = np.empty((2, 6))  # work buffer: measured and reference angles of one leg
        self.reset()

    def reset(self) -> None:
        """Forget the filters and offsets (the next update starts from the reference)."""
        self._started = False
        self._previous_reference = np.zeros(2)
        self._previous_relative = np.zeros((2, 3))
        self._com_velocity = np.zeros(2)
        self._offset = np.zeros(2)
        self._offset_rate = np.zeros(2)
        self._ankle = np.zeros((2, 2))
        self._height = 0.0
        self._feet = np.zeros((2, 2))  # estimated ankle positions in world (leg odometry) [m]
        self._landing = np.zeros((2, 2))  # landing corrections of the feet in world [m]
        self._anchor = 0
        self.state = BalanceState(np.zeros(2), np.full(2, np.nan), np.zeros(2), np.zeros(2), np.zeros((2, 2)),
                                  0.0, np.zeros(2))

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
        """
        g, dt, omega = self.gains, self.dt, self.omega
        reference = np.asarray(position_com_in_world, dtype=float)[:2]
        if not self._started:
            self._previous_reference = reference.copy()
        velocity_reference = (reference - self._previous_reference) / dt
        self._previous_reference = reference.copy()
        # --- measured sole wrenches: CoPs in world and the total ZMP
        forces = np.array([measurement.wrench_left[2], measurement.wrench_right[2]])
        loaded = forces > 0.05 * self._mass * self.robot.gravity
        # --- CoM estimate: kinematics of the measured legs, tilted by the IMU, anchored at the loaded sole
        roll, pitch = float(measurement.attitude[0]), float(measurement.attitude[1])
        heading = yaw_pelvis_in_world if measurement.yaw is None else float(measurement.yaw)
        rotation = _rz(heading) @ _ry(pitch) @ _rx(roll)
        q = np.asarray(measurement.joint_angles, dtype=float)
        com_in_base = self._rest_mass * self._rest_com
        relative = np.empty((2, 3))
        reference_angles = np.asarray(joint_angles, dtype=float)
        kinematics = []  # per leg: transforms of (measured, reference) angles, computed once
        for index, chain in enumerate(self.chains):
            angles = self._angles
            angles[0, self._orders[index]] = q[6 * index:6 * index + 6]
            angles[1, self._orders[index]] = reference_angles[6 * index:6 * index + 6]
            transforms = chain.transforms(angles)
            kinematics.append((angles[1:].copy(), (transforms[0][1:], transforms[1][1:])))
            com_in_base = com_in_base + chain.link_masses @ chain.link_com_positions(angles, transforms)[0]
            relative[index] = chain.fk(angles, transforms)[0][0]
        com_in_base = com_in_base / self._mass
        if not self._started:
            self._previous_relative = relative.copy()
            self._feet = np.array([ankles_in_world[0][:2], ankles_in_world[1][:2]], dtype=float)
            self._anchor = 0 if forces[0] >= forces[1] else 1
            self._started = True
        # Leg odometry: when the load moves to the other sole, place it from the measured kinematics.
        anchor = 0 if forces[0] >= forces[1] else 1
        if anchor != self._anchor and loaded.all():
            self._feet[anchor] = self._feet[self._anchor] + (rotation @ (relative[anchor] - relative[self._anchor]))[:2]
            self._anchor = anchor
        anchor = self._anchor
        arm = rotation @ (com_in_base - relative[anchor])
        com = self._feet[anchor] + arm[:2]
        # Where the feet are (odometry; the swing foot follows from the stance foot and the kinematics): the
        # measured CoPs, the support polygon and the wrench distribution use these places.
        feet = [self._feet[anchor], self._feet[anchor] + (rotation @ (relative[1 - anchor] - relative[anchor]))[:2]]
        if anchor == 1:
            feet.reverse()
        cops = np.zeros((2, 2))
        for foot, wrench in enumerate((measurement.wrench_left, measurement.wrench_right)):
            if loaded[foot]:
                h = self.robot.ankle_height
                local = np.array([-(wrench[4] + h * wrench[0]) / wrench[2], (wrench[3] - h * wrench[1]) / wrench[2]])
                cops[foot] = feet[foot] + _rotate(local, foot_yaws[foot])
        zmp_measured = np.full(2, np.nan)
        if loaded.any():
            weights = np.where(loaded, forces, 0.0)
            zmp_measured = (weights @ cops) / weights.sum()
        measured_feet = (feet[0], feet[1])
        previous_arm = rotation @ (com_in_base - self._previous_relative[anchor])
        spin = rotation @ np.asarray(measurement.rate, dtype=float)
        raw_velocity = (arm[:2] - previous_arm[:2]) / dt + cross3(spin, arm)[:2]
        self._previous_relative = relative
        alpha = dt / (g.velocity_filter + dt)
        self._com_velocity += alpha * (raw_velocity - self._com_velocity)
        # --- 1. DCM feedback -> desired ZMP inside the support polygon
        dcm_error = (com + self._com_velocity / omega) - (reference + velocity_reference / omega)
        zmp_desired = np.asarray(zmp_in_world, dtype=float) + (1.0 + g.dcm / omega) * dcm_error
        zmp_desired = self._clamp(zmp_desired, support, measured_feet, foot_yaws)
        # --- 2. CoM admittance
        acceleration = g.com_admittance * (zmp_measured - zmp_desired) if loaded.any() else np.zeros(2)
        acceleration -= g.com_damping * self._offset_rate + g.com_stiffness * self._offset
        self._offset_rate += acceleration * dt
        self._offset += self._offset_rate * dt
        norm = float(np.hypot(*self._offset))
        if norm > g.com_limit:
            self._offset *= g.com_limit / norm
            self._offset_rate *= 0.0
        # --- 3. ankle damping: each loaded sole's CoP follows its share of p_d
        shares, targets = self._distribute(zmp_desired, support, measured_feet, foot_yaws)
        decay = dt / g.ankle_time_constant
        for foot in range(2):
            if loaded[foot] and shares[foot] > 0.0:
                error = _rotate(targets[foot] - cops[foot], -foot_yaws[foot])  # in the foot frame
                self._ankle[foot, 0] += dt * (-g.ankle_gain * error[1])
                self._ankle[foot, 1] += dt * (g.ankle_gain * error[0])
            self._ankle[foot] -= decay * self._ankle[foot]
        np.clip(self._ankle, -g.ankle_limit, g.ankle_limit, out=self._ankle)
        # --- 4. foot force difference (double support)
        weight = float(forces.sum())
        if support == 0 and loaded.all() and weight > 0:
            wanted = (shares[0] - shares[1]) * weight
            self._height += dt * g.force_gain * (wanted - (forces[0] - forces[1])) / weight
        self._height -= dt / g.force_time_constant * self._height
        self._height = float(np.clip(self._height, -g.force_limit, g.force_limit))
        # --- 5. torso attitude
        turn = np.clip(-g.attitude_gain * np.array([roll, pitch])
                       - g.attitude_damping * np.asarray(measurement.rate, dtype=float)[:2],
                       -g.attitude_limit, g.attitude_limit)
        # --- 6. landing: a swinging foot aims at its planned place in world from where the base is (odometry),
        # not where the plan has it; the correction is released once the foot carries load.
        base_estimate = self._feet[anchor] - (rotation @ relative[anchor])[:2]
        planned_relative = [chain.fk(angles, transforms)[0][0] for chain, (angles, transforms)
                            in zip(self.chains, kinematics, strict=True)]
        yaw_rotation = _rz(yaw_pelvis_in_world)
        base_planned = (np.asarray(ankles_in_world[anchor], dtype=float)[:2]
                        - (yaw_rotation @ planned_relative[anchor])[:2])
        for foot in range(2):
            swinging = (support == 1 and foot == 1) or (support == 2 and foot == 0)
            if swinging:
                target = base_planned + self._offset - base_estimate
                self._landing[foot] += dt / g.landing_time_constant * (target - self._landing[foot])
            else:
                self._landing[foot] -= dt / g.landing_release * self._landing[foot]
        np.clip(self._landing, -g.landing_limit, g.landing_limit, out=self._landing)
        # --- corrections of the feet relative to the pelvis, onto the joints through the Jacobians
        result = reference_angles.copy()
        shift_in_pelvis = _rotate(self._offset, -yaw_pelvis_in_world)
        pelvis_turn = np.array([turn[0], turn[1], 0.0])
        for index, chain in enumerate(self.chains):
            angles, transforms = kinematics[index]
            position = planned_relative[index][None]
            jacobian = chain.jacobian(angles, transforms)[0]
            foot_turn = _rotate(self._ankle[index], foot_yaws[index] - yaw_pelvis_in_world)
            change = np.empty(6)
            change[:2] = _rotate(self._landing[index], -yaw_pelvis_in_world) - shift_in_pelvis
            change[2] = -self._height / 2 if index == 0 else self._height / 2
            change[:3] -= cross3(pelvis_turn, position[0])
            change[3:5] = foot_turn
            change[5] = 0.0
            change[3:] -= pelvis_turn
            delta = np.linalg.solve(jacobian, change)
            result[6 * index:6 * index + 6] += delta[self._orders[index]]
        self.state = BalanceState(zmp_desired, zmp_measured, dcm_error, self._offset.copy(), self._ankle.copy(),
                                  self._height, turn)
        return result

    def _distribute(self, zmp: Array, support: int, ankles: tuple[Array, Array],
                    yaws: tuple[float, float]) -> tuple[tuple[float, float], tuple[Array, Array]]:
        """Load shares of the feet and each sole's CoP target [m] for a desired ZMP."""
        centres = [ankles[f][:2] + _rotate(self._sole_centre * [1.0, 1.0 if f == 0 else -1.0], yaws[f])
                   for f in range(2)]
        if support == 1:
            return (1.0, 0.0), (zmp, centres[1])
        if support == 2:
            return (0.0, 1.0), (centres[0], zmp)
        span = centres[1] - centres[0]
        ratio = float(np.clip((zmp - centres[0]) @ span / max(float(span @ span), 1e-12), 0.0, 1.0))
        base = centres[0] + ratio * span
        return (1.0 - ratio, ratio), (centres[0] + zmp - base, centres[1] + zmp - base)

    def _clamp(self, zmp: Array, support: int, ankles: tuple[Array, Array], yaws: tuple[float, float]) -> Array:
        """``zmp`` moved into the support polygon shrunk by the margin (single support: the sole; double:
        the segment between the soles' centres widened by the soles' half widths, a conservative hull)."""
        margin = self.gains.zmp_margin
        lx, ly = max(self._half_length - margin, 0.0), max(self._half_width - margin, 0.0)
        centres = [ankles[f][:2] + _rotate(self._sole_centre * [1.0, 1.0 if f == 0 else -1.0], yaws[f])
                   for f in range(2)]
        if support in (1, 2):
            foot = support - 1
            local = _rotate(zmp - centres[foot], -yaws[foot])
            local = np.clip(local, [-lx, -ly], [lx, ly])
            return centres[foot] + _rotate(local, yaws[foot])
        span = centres[1] - centres[0]
        length = float(np.hypot(*span))
        if length < 1e-9:
            return zmp
        along = span / length
        across = np.array([-along[1], along[0]])
        rel = zmp - centres[0]
        s = float(np.clip(rel @ along, 0.0, length))
        d = float(np.clip(rel @ across, -lx, lx))
        return centres[0] + s * along + d * across


def _rotate(vector: Array, angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def _rx(angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rz(angle: float) -> Array:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


__all__ = ["BalanceMeasurement", "BalanceState", "Stabilizer", "StabilizerGains"]
