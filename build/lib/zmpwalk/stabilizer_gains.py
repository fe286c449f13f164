"""The stabilizer's gains (:class:`StabilizerGains`): data a robot file may carry (``[stabilizer]``), read by
:mod:`zmpwalk.robots.model` and used by :class:`zmpwalk.balance.Stabilizer` (whose module docstring gives each
loop's law)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from zmpwalk.errors import InvalidParameterError

TIME_CONSTANTS = ("ankle_time_constant", "force_time_constant", "landing_time_constant", "landing_release")


@dataclass(frozen=True)
class StabilizerGains:
    """Gains of the stabilizer (see the module docstring), robot-independent units.

    Attributes:
        dcm: ``k_xi``, decay rate of the DCM error [1/s].
        com_admittance: ``A``, CoM acceleration per metre of ZMP error [1/s^2].
        com_stiffness: ``K_p``, pull of the CoM offset back to its rest point (the module docstring, steps 2
            and 7) [1/s^2].
        com_damping: ``K_v`` [1/s].
        com_limit: Largest CoM offset [m].
        ankle_gain: Foot turn rate per metre of CoP error [rad/(s m)] (``F / D`` of Kajita's damping control).
        ankle_time_constant: ``T`` of the ankle offsets' return to zero [s] (> 0, as are the force and
            landing time constants and the landing release; every other gain is >= 0).
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
        landing_release: How fast that correction is released once the plan puts the foot down, unless its
            sole has been bare for over ``zmpwalk.stabilizer.landing.AIRBORNE_AIM`` (a late touchdown, still
            aiming) [s].
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
        feet_clearance: The least gap between the soles' inner edges that a landing correction leaves, across
            the pelvis [m] (a step towards a fall on the stance side would cross the stance foot: without this
            limit, HUBO pushed backward with 32 N s stepped its left foot into its right one).
        touchdown_speed: ``force_gain`` while only one sole carries load in double support: how fast a sole
            the plan has down but that carries none (a late touchdown) is lowered, per newton of
            force-difference error per newton of weight [m/s]. Apart from ``force_gain`` because the two-sole
            loop must stay slow under sensor latency while a bare sole may be lowered faster: with 10 ms of
            latency stiff HUBO fails its verdict with 0.2 m/s for both cases, passes with 0.05 for two soles
            and 0.2 for a bare one, and falls with 0.3 for a bare one. The same speed raises a swinging sole
            that carries load in single support (an early touchdown).
        landing_height_limit: Largest height correction of a swinging foot that aims at its planned height
            above the floor [m]; 0 (the default) leaves the swing height to the pattern. The small biped's
            file sets it: its CoP - ZMP RMS 12.0 -> 9.5 mm; HUBO's gets worse with it (docs/balance.md).
        whole_body_rest: Against a pelvis point (``com_reference`` ``"pelvis"``), the CoM offset rests at this
            fraction of minus the planned whole-body CoM's offset from that point (the module docstring, step 2)
            [-]; 0 (the default) rests it at zero. HUBO's file sets 1: fig27's CoP - ZMP RMS 26.3 -> 24.6 mm
            on soft servos (28.1 -> 28.6 on stiff ones), the other scenarios 0-4 mm lower; the small biped's
            9.5 -> 9.1 mm, but it then falls with 2 ms of sensor latency (docs/balance.md).
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
    feet_clearance: float = 0.02  # [m]
    touchdown_speed: float = 0.05  # [m/s]
    landing_height_limit: float = 0.0  # [m]
    whole_body_rest: float = 0.0  # [-]

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                       and value >= 0):
                raise InvalidParameterError(f"gains.{name}", value, "a finite number >= 0")
            if name in TIME_CONSTANTS and value <= 0:  # each tick divides by them
                raise InvalidParameterError(f"gains.{name}", value, "a time > 0 s")
