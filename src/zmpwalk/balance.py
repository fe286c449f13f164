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
   ``Delta c'' = A (p_measured - p_d) - K_v Delta c' - K_p (Delta c - Delta c_rest)`` (in the cart-table
   model ``p = c - c'' / omega^2``, accelerating forward moves the ZMP back). Where the pattern's CoM point
   is its pelvis point (a box model's pattern: the cart-table's one mass at the base origin), the offset
   can rest (:attr:`StabilizerGains.whole_body_rest`, HUBO's file) at ``Delta c_rest = -(c_planned -
   c_pelvis)``, minus the planned whole-body CoM's offset from that point (the legs at the pattern's angles
   and the rest of the body, the estimate's mass model), so that the whole-body CoM stands where the
   cart-table puts its mass; resting at zero, the pull ``K_p`` held the CoM that far ahead and the DCM loop
   answered with a desired ZMP ahead of the plan (HUBO's fig27: 14.7 mm on average). A swinging sole that touches
   down early (it carries load again after it has lifted) carries load the plan does not give it: ``p_measured`` is
   then the stance sole's CoP alone, since answering the ZMP that foot moves would accelerate the CoM towards it
   (Menagerie's earlier Unitree G1 fell so in its side steps); step 4 raises that foot instead.
3. **Ankle damping control** (the damping control of Kajita et al. 2010): each loaded sole's centre of
   pressure follows its share of ``p_d`` by turning the foot, ``delta' = -(tau_d - tau) / D - delta / T``,
   written per metre of CoP error.
4. **Foot force difference control** (Kajita et al. 2010): in double support the feet's heights move apart
   until the measured force difference is the desired one. It runs as soon as one sole carries load: a sole
   that the plan has down but that carries none (it lands late, or the body rolled it off the floor) reads
   the whole weight as the difference and is lowered, at :attr:`StabilizerGains.touchdown_speed`, until it
   takes its share (landing timing). In single support the swinging sole's desired share is none: one that
   touches down early (it carries load again after it has lifted) carries load that the plan gives the
   stance sole, and it is raised at the same speed.
5. **Torso attitude**: the pelvis is turned against the measured roll and pitch (and their rates).
6. **Landing and stepping**: the swinging foot aims at its planned place in world from the odometry's
   base, seen through the measured pelvis attitude, moved by :attr:`StabilizerGains.step_gain` times the
   DCM error, towards where the body falls (the capture point of Pratt et al. 2006), and turns by the
   torso's measured yaw error so that it lands at its planned heading in world; it never steps across the
   stance foot (the soles' inner edges keep :attr:`StabilizerGains.feet_clearance` between them: a fall
   towards the stance side is caught by the next step, of the other foot). With
   :attr:`StabilizerGains.landing_height_limit` above 0 it also aims at its planned height above the stance
   sole, on the floor's estimated plane, from the measured legs and attitude, plus the stance sole's
   compression ``(f / k)^(1/e)`` under its measured force ``f`` where the robot file gives the soles' contact
   law (a stance sole pressed into the floor lowers the whole robot, and a swinging foot whose plan comes down
   gently reaches the floor that much early). The corrections are released once the plan puts the foot down,
   unless its sole has carried no load for over :data:`zmpwalk.stabilizer.landing.AIRBORNE_AIM` (a late
   touchdown), which keeps its aim until it carries load; a stance sole that unloads for a shorter moment
   (sensor noise, a rocking body) is not taken for one.
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

**Five-joint legs** (no ankle roll: Unitree H1). The leg's chain has a virtual ankle roll, an axis ``a`` along
the sole's centre line on the floor (:mod:`zmpwalk.leg_chain`), so ``J`` is still 6 x 6 and the same solve
runs; the change it gives the virtual joint is dropped (no motor turns it). Splitting ``J Delta q = Delta x``
into the five real columns ``J_5`` and the virtual one ``j_v = (a x (p - o), a)``,

.. math:: J_5 \Delta q_5 = \Delta x - j_v \Delta q_v,

the real joints make the whole correction less a twist about the virtual axis: a roll of the sole about its
centre line, the one motion five joints cannot make at any posture (the sole's roll then follows from its
position, heading and pitch). No ankle-roll torque is asked for: the ankle damping's roll and the torso roll
reach the sole only as that dropped twist, and the lateral balance is the hip roll's, moving the CoM sideways
(the CoM admittance) and placing the swinging foot (landing control); ``tests/test_five_joint_legs.py`` checks
the split on a five-joint chain. Nor can such a leg move the CoP across the stance sole: in single support the
CoM admittance's ZMP term keeps only its part along the pelvis (the ZMP error across it would only push the CoM
further sideways), and the sideways balance is the step's; in double support the load shared between the feet
moves the CoP across, and both parts act.

It runs compiled (:mod:`zmpwalk.balance_kernel`, one compiled function per loop in :mod:`zmpwalk.stabilizer`,
numba, cached on disk after the first compile) on arrays allocated once per stabilizer: a tick costs about 3 µs
from Python and allocates nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import leg_chains, rest_mass
from zmpwalk.robots.model import RobotModel
from zmpwalk.stabilizer.layout import LOG_SIZE, STATE_SIZE, L, S, chain_table, initial_state, pack_parameters
from zmpwalk.stabilizer_gains import StabilizerGains

Array = NDArray[np.float64]

LOAD_FRACTION = 0.05  # [-] of the robot's weight: a sole carries load above this normal force
COM_REFERENCES = ("auto", "pelvis", "whole_body")  # what the CoM point given to Stabilizer.update is


@dataclass
class BalanceMeasurement:
    """What the robot measures at one tick.

    Attributes:
        wrench_left, wrench_right: Force [N] (3) then torque [N m] (3) that the ground exerts on each foot,
            about the ankle point, in the foot frame (x forward along the sole, y left, z up), (6,).
        attitude: Torso (base) roll and pitch [rad] from the IMU, (2,): of the legs' base (docs/controller.md).
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
        whole_body_offset: The planned whole-body CoM less the pattern's pelvis point, times the gain
            ``whole_body_rest`` [m], (2,) (zero unless the stabilizer's ``com_reference`` is ``"pelvis"``); the
            CoM offset rests at minus it (plus the slope's offset).
    """

    zmp_desired: Array
    zmp_measured: Array
    dcm_error: Array
    com_offset: Array
    ankle_offsets: Array
    height_difference: float
    pelvis_turn: Array
    slope_offset: Array = field(default_factory=lambda: np.zeros(2))
    whole_body_offset: Array = field(default_factory=lambda: np.zeros(2))


class Stabilizer:
    """Balance feedback for one robot at a fixed control rate (see the module docstring).

    Args:
        robot: The robot (legs, masses, soles).
        rate: Control rate [Hz].
        gains: The gains (default: :class:`StabilizerGains` with the robot file's ``[stabilizer]`` gains, which
            HUBO's box model has; the defaults suit TALOS, Booster T1 and the small biped in the simulation;
            docs/balance.md).
        com_reference: What :meth:`update`'s ``position_com_in_world`` is: ``"pelvis"``, the pattern's
            pelvis point, which a box model's patterns plan as the cart-table's mass (the CoM offset can then
            rest where it puts the planned whole-body CoM on that point: the module docstring, step 2);
            ``"whole_body"``, the whole-body CoM (an imported robot's patterns, whose base is placed under
            it, and a multibody-corrected pattern's ``position_com_in_world``); ``"auto"`` (default):
            ``"whole_body"`` for an imported robot, else ``"pelvis"``. A pattern's
            :attr:`~zmpwalk.patterns.result.WalkingPattern.com_point` names the one it gives.

    Raises:
        InvalidParameterError: A rate outside [10, 10000] Hz or an unknown ``com_reference``.

    The first :meth:`update` initialises the filters; :meth:`reset` forgets the state. The tick itself is
    :func:`zmpwalk.balance_kernel.tick`, compiled on first use (cached on disk afterwards).
    """

    def __init__(self, robot: RobotModel, rate: float, gains: StabilizerGains | None = None, *,
                 com_reference: str = "auto") -> None:
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 10.0 <= rate <= 10_000.0:
            raise InvalidParameterError("rate", rate, "a control rate in [10, 10000] Hz")
        if com_reference not in COM_REFERENCES:
            raise InvalidParameterError("com_reference", com_reference, f"one of {', '.join(COM_REFERENCES)}")
        if com_reference == "auto":
            com_reference = "whole_body" if robot.own_model else "pelvis"
        self.com_reference = com_reference
        from zmpwalk import balance_kernel as kernel  # compiles (or loads) the tick: only where one is wanted

        self._kernel = kernel
        self._tick = kernel.tick
        self._convert = False  # convert the inputs before each tick (set once some were not float64 vectors)
        self.robot = robot
        self.gains = gains or StabilizerGains(**dict(robot.stabilizer_gains))
        self.dt = 1.0 / float(rate)
        self.omega = math.sqrt(robot.gravity / robot.pendulum_length)
        self.chains = leg_chains(robot)
        rest, rest_com = rest_mass(robot)
        self._mass = rest + sum(float(c.link_masses.sum()) for c in self.chains)
        self.load_threshold = LOAD_FRACTION * self._mass * robot.gravity  # [N] a sole carries load above this
        # 8. the outer loop's gain per joint column: G = kappa m g l / k - 1 where the servo is softer
        stiffness = servo_stiffness(robot)
        wanted = self.gains.servo_stiffness * self._mass * robot.gravity * robot.pendulum_length
        self.servo_gain = (np.zeros(12) if stiffness is None
                           else np.maximum(wanted / np.maximum(stiffness, 1e-9) - 1.0, 0.0))
        sole_law = robot.contact  # the soles' compliance, where the robot file gives it
        self._params = pack_parameters(
            self.gains, whole_body_rest=self.gains.whole_body_rest if com_reference == "pelvis" else 0.0,
            dt=self.dt, omega=self.omega, mass=self._mass, rest_moment=rest * np.asarray(rest_com),
            half_length=robot.foot_length / 2, half_width=robot.foot_width / 2, ankle_height=robot.ankle_height,
            pendulum_length=robot.pendulum_length, sole_center_x=robot.sole_center_x,
            sole_center_y=robot.sole_center_y, load_threshold=self.load_threshold,
            ankle_offset=np.concatenate([c.ankle for c in self.chains]), servo_gain=self.servo_gain,
            stiffen=float(self.servo_gain.any()), sole_stiffness=0.0 if sole_law is None else sole_law.stiffness,
            sole_exponent=0.0 if sole_law is None else sole_law.exponent,
            sole_normal=np.concatenate([c.sole_rotation[:, 2] for c in self.chains]),
            ankle_roll=float(all(c.virtual is None for c in self.chains)))
        self._chain = chain = chain_table(self.chains)
        self._state = np.zeros(STATE_SIZE)
        self._log = log = np.zeros(LOG_SIZE)
        self._work = np.zeros((6, 7, 12))
        self._targets = np.zeros(12)
        self.state = balance_state(log)
        # One tick on the legs' reference posture here, so that the first tick of the loop is no slower than the
        # others (numba's first call into a function is: about 0.5 ms).
        posture = np.concatenate([np.asarray(c.reference, dtype=float)[list(c.role_order)] for c in self.chains])
        vector = np.zeros(12)
        self.reset()
        kernel.tick(self._params, chain, self._state, log, self._work, self._targets, 0, vector[:3], 0.0, vector[:2],
                    vector[:3], vector[:3], 0.0, 0.0, posture, vector[:6], vector[:6], vector[:2], vector[:3], posture,
                    math.nan)
        self.reset()

    @property
    def log(self) -> Array:
        """The last update's log, (LOG_SIZE,), overwritten by every update: :attr:`state`'s arrays are views into
        it (:func:`balance_state` names its parts); a loop that keeps every tick's state copies this one row."""
        return self._log

    @property
    def _anchor(self) -> int:
        """The odometry's reference sole: 0 left, 1 right."""
        return int(self._state[S.anchor])

    @property
    def _feet(self) -> Array:
        """The odometry's ankles in world [m], (2, 2), a writable view of the state."""
        return self._state[S.feet:S.feet + 4].reshape(2, 2)

    @property
    def _landing(self) -> Array:
        """The swinging feet's landing corrections in world [m], (2, 2), a view of the state."""
        return self._state[S.landing:S.landing + 4].reshape(2, 2)

    @property
    def _landing_yaw(self) -> Array:
        """Their yaw corrections [rad], (2,), a view of the state."""
        return self._state[S.landing_yaw:S.landing_yaw + 2]

    def landing_correction(self, foot: str) -> Array:
        """The landing correction of ``foot`` (``"left"`` or ``"right"``) in world [m], (2,), a copy: where the
        stabilizer aims the swinging foot, relative to its planned place.

        Raises:
            InvalidParameterError: ``foot`` is not ``"left"`` or ``"right"``.
        """
        if foot not in ("left", "right"):
            raise InvalidParameterError("foot", foot, '"left" or "right"')
        return np.array(self._landing[0 if foot == "left" else 1], dtype=np.float64)

    def hand_over_landing(self, foot: str, taken: Array | None = None) -> Array:
        """Hand the landing correction of ``foot`` to a new plan whose swing starts from the planned place plus
        ``taken`` [m] (world, (2,); None: the whole correction now, :meth:`landing_correction`): a capture step,
        :func:`zmpwalk.capture.capture_step`. The correction keeps what the plan did not take (it may have moved
        since the plan read it), so the foot's target does not jump. Returns the part taken.

        Raises:
            InvalidParameterError: ``foot`` is not ``"left"`` or ``"right"``, or ``taken`` is not two finite values.
        """
        correction = self.landing_correction(foot)
        if taken is None:
            taken = correction
        taken = np.asarray(taken, dtype=np.float64)
        if taken.shape != (2,) or not np.isfinite(taken).all():
            raise InvalidParameterError("taken", taken.tolist(), "two finite values [m], or None")
        self._landing[0 if foot == "left" else 1] = correction - taken
        return np.array(taken, dtype=np.float64)

    def reset(self) -> None:
        """Forget the filters and offsets (the next update starts from the reference)."""
        initial_state(self._state, self._log)
        self.state.height_difference = 0.0

    def update(self, *, support: int, position_com_in_world: Array, yaw_pelvis_in_world: float, zmp_in_world: Array,
               ankles_in_world: tuple[Array, Array], foot_yaws: tuple[float, float], joint_angles: Array,
               measurement: BalanceMeasurement) -> Array:
        """Corrected joint targets (12,) [rad] for one tick.

        Args:
            support: The pattern's support at this tick: 0 double, 1 left, 2 right.
            position_com_in_world: The pattern's CoM point [m] (3,): its pelvis point, or its whole-body CoM
                (the constructor's ``com_reference`` says which).
            yaw_pelvis_in_world: [rad].
            zmp_in_world: The pattern's ZMP [m] (2,).
            ankles_in_world: Planned left and right ankle positions [m], each (3,).
            foot_yaws: Planned foot yaws [rad].
            joint_angles: The pattern's 12 joint angles [rad].
            measurement: The sensors (:class:`BalanceMeasurement`).

        Returns:
            The targets, in an array that the next update overwrites (copy what you keep).

        Raises:
            InvalidParameterError: ``support`` is not 0, 1 or 2, an input has too few values, or a leg's
                Jacobian at ``joint_angles`` is singular (a straight knee); the state is then as it was.

        The work is fixed: both legs' kinematics (measured and reference angles), one 6 x 6 LU factoring and
        solve per leg, and scalar arithmetic, compiled; nothing is planned, iterated or allocated.
        """
        m = measurement
        if type(support) is not int:  # an IntEnum (Support) or a numpy integer: numba types a subclass of int
            support = _integer("support", support)  # in Python, 10 us a call; a plain int in C
        measured_yaw = math.nan if m.yaw is None else m.yaw
        com, zmp, left, right = position_com_in_world, zmp_in_world, ankles_in_world[0], ankles_in_world[1]
        wl, wr, attitude, rate, encoders = m.wrench_left, m.wrench_right, m.attitude, m.rate, m.joint_angles
        if self._convert:
            com, zmp, left, right, joint_angles, wl, wr, attitude, rate, encoders = _vectors(
                com, zmp, left, right, joint_angles, wl, wr, attitude, rate, encoders)
        try:
            status = self._tick(self._params, self._chain, self._state, self._log, self._work, self._targets, support,
                                com, yaw_pelvis_in_world, zmp, left, right, foot_yaws[0], foot_yaws[1], joint_angles,
                                wl, wr, attitude, rate, encoders, measured_yaw)
        except TypeError:
            # Not every input is a float64 vector or a number (numba's dispatch checks them in C, at no cost):
            # convert them, at this tick and every later one (the failed dispatch costs a few hundred µs).
            self._convert = True
            com, zmp, left, right, joint_angles, wl, wr, attitude, rate, encoders = _vectors(
                com, zmp, left, right, joint_angles, wl, wr, attitude, rate, encoders)
            status = self._tick(self._params, self._chain, self._state, self._log, self._work, self._targets,
                                _integer("support", support), com, _number("yaw_pelvis_in_world", yaw_pelvis_in_world),
                                zmp, left, right, _number("foot_yaws[0]", foot_yaws[0]),
                                _number("foot_yaws[1]", foot_yaws[1]), joint_angles, wl, wr, attitude, rate, encoders,
                                _number("measurement.yaw", measured_yaw))
        if status:
            self._raise(status, position_com_in_world, zmp_in_world, ankles_in_world, joint_angles, m, support)
        self.state.height_difference = float(self._log[L.height_difference])
        return self._targets

    def _raise(self, status: int, com: Array, zmp: Array, ankles: tuple[Array, Array], angles: Array,
               m: BalanceMeasurement, support: int) -> None:
        kernel = self._kernel
        if status == kernel.BAD_SUPPORT:
            raise InvalidParameterError("support", support, "0 (double), 1 (left) or 2 (right)")
        if status in (kernel.SINGULAR_LEG, kernel.SINGULAR_LEG + 1):
            leg = status - kernel.SINGULAR_LEG
            values = np.round(np.asarray(angles, dtype=float)[6 * leg:6 * leg + 6], 4).tolist()
            raise InvalidParameterError(f"joint_angles[{6 * leg}:{6 * leg + 6}] ({('left', 'right')[leg]} leg)",
                                        values, "a posture where the leg's Jacobian is invertible (a knee that is "
                                        "not straight): no foot correction maps onto the joints at a singular one")
        given = (com, zmp, ankles[0], ankles[1], angles, m.wrench_left, m.wrench_right, m.attitude, m.rate,
                 m.joint_angles)[status - 1]
        raise InvalidParameterError(INPUT_NAMES[status - 1], f"{np.size(given)} values",
                                    f"{kernel.INPUT_SIZES[status - 1]} values")


def balance_state(log: Array) -> BalanceState:
    """The :class:`BalanceState` whose arrays are views into the compiled tick's ``log``: every update overwrites
    them in place."""
    return BalanceState(
        zmp_desired=log[L.zmp_desired:L.zmp_desired + 2],
        zmp_measured=log[L.zmp_measured:L.zmp_measured + 2],
        dcm_error=log[L.dcm_error:L.dcm_error + 2],
        com_offset=log[L.com_offset:L.com_offset + 2],
        ankle_offsets=log[L.ankle_offsets:L.ankle_offsets + 4].reshape(2, 2),
        height_difference=0.0,
        pelvis_turn=log[L.pelvis_turn:L.pelvis_turn + 2],
        slope_offset=log[L.slope_offset:L.slope_offset + 2],
        whole_body_offset=log[L.whole_body_offset:L.whole_body_offset + 2])


INPUT_NAMES = ("position_com_in_world", "zmp_in_world", "ankles_in_world[0]", "ankles_in_world[1]", "joint_angles",
               "measurement.wrench_left", "measurement.wrench_right", "measurement.attitude", "measurement.rate",
               "measurement.joint_angles")  # the update's vector inputs, in the kernel's order


def _vectors(*values: object) -> tuple[Array, ...]:
    """The update's vector inputs (in the order of :data:`INPUT_NAMES`) as float64 vectors."""
    return tuple(_vector(name, value) for name, value in zip(INPUT_NAMES, values, strict=True))


def _integer(name: str, value: object) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidParameterError(name, value, "an integer")
    return int(value)


def _vector(name: str, value: object) -> Array:
    try:
        return np.ascontiguousarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, "a vector of numbers") from None


def _number(name: str, value: object) -> float:
    try:
        return float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, "a number") from None


def servo_stiffness(robot: RobotModel) -> Array | None:
    """Stiffness of each leg joint's position servo or joint PD layer [N m/rad], (12,) in the joint-column order;
    None where the robot gives none (a robot file without ``[servos]``)."""
    if robot.plant is not None:
        return np.array([j.actuator.kp if j.actuator is not None and j.actuator.servo else np.inf
                         for j in robot.plant.joints])
    if robot.servos is not None:
        return np.full(12, robot.servos.kp)
    return None


__all__ = ["BalanceMeasurement", "BalanceState", "Stabilizer", "StabilizerGains"]
