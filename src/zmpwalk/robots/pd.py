"""Each joint's actuator read from a robot's own model, and the joint PD layer (a humanoid's firmware loop) for
torque motors and unactuated joints: :func:`pd_gains`'s rule from the joint's reflected inertia and the weight it
holds."""

from __future__ import annotations

import math
import numbers
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots.description import (
    PD_BANDWIDTH,
    PD_DAMPING_RATIO,
    PD_LOAD_STIFFNESS,
    PD_PREFIX,
    PD_STEP_LIMIT,
    PHYSICS_STEP,
    PHYSICS_SUBSTEPS,
    Actuator,
)
from zmpwalk.robots.linkages import close_equalities, driven_torque_limits, equality_loops, joint_dofs

Array = NDArray[np.float64]


def element_name(model: object, kind: object, index: int) -> str:
    """The name of a model's element (a joint, a body, an actuator: ``kind``), or ``#index`` where it has none."""
    import mujoco

    return str(mujoco.mj_id2name(model, kind, index) or f"#{index}")


def is_position_servo(model: Any, actuator: int) -> bool:
    """Whether an actuator is a position servo on a joint: ``gain (u - q) - kv q'`` (MuJoCo ``<position>``
    or an equivalent ``<general>``)."""
    import mujoco

    gain, bias = model.actuator_gainprm[actuator], model.actuator_biasprm[actuator]
    return bool(model.actuator_trntype[actuator] == mujoco.mjtTrn.mjTRN_JOINT and gain[0] > 0
                and model.actuator_biastype[actuator] == mujoco.mjtBias.mjBIAS_AFFINE
                and abs(bias[1] + gain[0]) < 1e-9 * max(1.0, gain[0]))


def joint_actuator(model: object, joint: int) -> Actuator | None:
    """The model's actuator of ``joint`` (the first with a joint transmission to it), or None; its ``kp``, ``kv``
    are the model's (0 for a motor: see :func:`pd_layer`)."""
    import mujoco

    m = model
    for a in range(m.nu):  # type: ignore[attr-defined]
        if m.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT or int(m.actuator_trnid[a][0]) != joint:  # type: ignore[attr-defined]
            continue
        gear = float(m.actuator_gear[a][0])  # type: ignore[attr-defined]
        gain, bias = m.actuator_gainprm[a], m.actuator_biasprm[a]  # type: ignore[attr-defined]
        if is_position_servo(m, a):
            kind, kp, kv = "position", float(gain[0]) * gear, float(-bias[2]) * gear + 0.0  # + 0.0: no -0.0 damping
        elif _is_motor(m, a):
            kind, kp, kv = "motor", 0.0, 0.0
        else:
            kind, kp, kv = "general", float(gain[0]), float(-bias[2]) + 0.0
        limit = _joint_torque_limit(m, joint)
        if m.actuator_forcelimited[a]:  # type: ignore[attr-defined]
            limit = min(limit, float(np.max(np.abs(m.actuator_forcerange[a]))) * abs(gear))  # type: ignore[attr-defined]
        if kind == "motor" and m.actuator_ctrllimited[a]:  # type: ignore[attr-defined]
            limit = min(limit, float(np.max(np.abs(m.actuator_ctrlrange[a]))) * abs(float(gain[0]) * gear))  # type: ignore[attr-defined]
        return Actuator(element_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a), kind, kp, kv, limit)
    return None


def _is_motor(model: Any, actuator: int) -> bool:
    """Whether an actuator is a torque motor on a joint: ``gain ctrl`` (MuJoCo ``<motor>``: fixed gain, no bias,
    no activation dynamics)."""
    import mujoco

    return bool(model.actuator_trntype[actuator] == mujoco.mjtTrn.mjTRN_JOINT
                and model.actuator_biastype[actuator] == mujoco.mjtBias.mjBIAS_NONE
                and model.actuator_gaintype[actuator] == mujoco.mjtGain.mjGAIN_FIXED
                and model.actuator_dyntype[actuator] == mujoco.mjtDyn.mjDYN_NONE)


def joint_torque_limit(model: Any, joint: int) -> float:
    """The most torque a joint's actuator (or, without one, the joint's own ``actuatorfrcrange``) can apply [N m];
    inf where nothing limits it."""
    actuator = joint_actuator(model, joint)
    return actuator.force_limit if actuator is not None else _joint_torque_limit(model, joint)


def _joint_torque_limit(model: Any, joint: int) -> float:
    """The joint's own limit on its actuators' total torque, ``actuatorfrcrange`` (a URDF's ``<limit effort>``)
    [N m]; inf where it has none."""
    if not model.jnt_actfrclimited[joint]:
        return math.inf
    return float(np.max(np.abs(model.jnt_actfrcrange[joint])))


def pd_gains(inertia: float, moment: float, timestep: float = PHYSICS_STEP,
             load_stiffness: float = PD_LOAD_STIFFNESS) -> tuple[float, float]:
    r"""The joint PD layer's gains of one joint: stiffness ``kp`` [N m/rad] and damping ``kv`` [N m s/rad].

    .. math::

        k_p = \min\left(\max(I \omega^2,\ \kappa W),\ I (\beta / \Delta t)^2\right), \qquad
        k_v = 2 \zeta \sqrt{k_p I}

    with :data:`PD_BANDWIDTH` ``omega`` (the joint swings on its own inertia at least this fast),
    :data:`PD_LOAD_STIFFNESS` ``kappa`` times the weight moment ``W`` it holds (a leg joint holds the robot on
    one foot, ``W = m g l``, whose toppling moment grows by ``m g l`` per radian of lean: at ``kappa = 4`` the
    joint's net stiffness against it is ``3 m g l``, above the 1.7 ``m g l`` below which the stabilizer
    stiffens servos with its encoder loop; 4 is the least whole value with which every walk of the torque-driven
    robots tried passes, docs/robot-import.md), the discrete bound :data:`PD_STEP_LIMIT` ``beta``
    (``sqrt(kp / I) dt <= beta``, and so ``kv dt / I <= 2 zeta beta``: stable at the physics step even where the
    damping is integrated explicitly, the bound being 2) and :data:`PD_DAMPING_RATIO` ``zeta`` (critical damping
    of the joint swinging on its own inertia).

    Args:
        inertia: ``I``, the joint's reflected inertia: the diagonal of the joint-space mass matrix at the ready
            posture, the rotor's armature included [kg m^2].
        moment: ``W``, the weight moment the joint holds [N m] (0: the bandwidth alone).
        timestep: ``dt``, the period of the PD loop, the physics step [s].
        load_stiffness: ``kappa`` [-], a robot file's ``[pd] load_stiffness`` where it gives one.

    Raises:
        InvalidParameterError: A non-positive inertia or time step, a negative moment, or a load stiffness
            that is not a finite number > 1.
    """
    if not inertia > 0 or not math.isfinite(inertia):
        raise InvalidParameterError("inertia", inertia, "a finite reflected inertia > 0 kg m^2")
    if not timestep > 0:
        raise InvalidParameterError("timestep", timestep, "a physics step > 0 s")
    if not moment >= 0:
        raise InvalidParameterError("moment", moment, "a weight moment >= 0 N m")
    kp = min(rule_stiffness(inertia, moment, load_stiffness), inertia * (PD_STEP_LIMIT / timestep) ** 2)
    return kp, 2.0 * PD_DAMPING_RATIO * math.sqrt(kp * inertia)


def rule_stiffness(inertia: float, moment: float, load_stiffness: float = PD_LOAD_STIFFNESS) -> float:
    """The rule's ``kp = max(I omega^2, kappa W)`` [N m/rad] before the discrete bound (:func:`pd_gains`)."""
    return max(inertia * PD_BANDWIDTH ** 2, check_load_stiffness(load_stiffness) * moment)


def check_load_stiffness(load_stiffness: object) -> float:
    """``load_stiffness`` (``kappa`` of :func:`pd_gains`) as a float [-].

    Raises:
        InvalidParameterError: It is not a finite number > 1: at 1 or less a joint is no stiffer than the toppling
            of the weight it holds.
    """
    value = math.nan
    if isinstance(load_stiffness, numbers.Real) and not isinstance(load_stiffness, bool):
        try:
            value = float(load_stiffness)
        except OverflowError:  # an integer beyond a float's range
            value = math.inf
    if not (math.isfinite(value) and value > 1.0):
        raise InvalidParameterError("load_stiffness", load_stiffness, "a finite number > 1 [-] (the rule's kappa, "
                                    f"{PD_LOAD_STIFFNESS:g} by default): the joint's stiffness over the weight "
                                    "moment it holds per radian")
    return value


def _weight_moment(model: Any, data: Any, joint: int) -> float:
    """The largest moment of the weight of the bodies a hinge moves about its axis [N m]: their mass times g
    times their centre of mass's distance from the axis line."""
    body = int(model.jnt_bodyid[joint])
    axis = data.xaxis[joint]
    lever = data.subtree_com[body] - data.xanchor[joint]
    distance = float(np.linalg.norm(lever - axis * float(axis @ lever)))
    return float(model.body_subtreemass[body]) * float(np.linalg.norm(model.opt.gravity)) * distance


def coupled_joints(model: Any, leg_joints: set[int]) -> frozenset[int]:
    """Joints a driven joint moves through an active equality: tied to a leg joint by a joint equality
    (ToddlerBot's hip yaw motor, whose gear turns the passive joint in the leg), or the actuated and ball joints of
    a loop that a connect or weld equality closes through an unactuated hinge (a parallel ankle's cranks and rods,
    which turn its pitch and roll; a parallel waist's): the PD layer drives the loop's unactuated hinges
    (:func:`loop_driven_joints`), as a robot's firmware maps their targets onto its cranks, and nothing holds the
    coupled joints at the reference pose (a hold would pull against that loop)."""
    import mujoco

    coupled: set[int] = set()
    for e in range(model.neq):
        if model.eq_active0[e] and int(model.eq_type[e]) == mujoco.mjtEq.mjEQ_JOINT:
            pair = (int(model.eq_obj1id[e]), int(model.eq_obj2id[e]))
            for mine, other in (pair, pair[::-1]):
                if mine in leg_joints and other >= 0 and other not in leg_joints:
                    coupled.add(other)
    for loop in equality_loops(model):
        hinges = _unactuated_hinges(model, loop)
        if hinges:
            coupled |= {j for j in loop - hinges - leg_joints if int(model.jnt_type[j]) != mujoco.mjtJoint.mjJNT_FREE}
    return frozenset(coupled)


def loop_driven_joints(model: Any) -> frozenset[int]:
    """The unactuated hinges of the loops that active connect or weld equalities close (a parallel waist's pitch
    and roll; a parallel ankle's, which are leg joints): the PD layer drives them (:func:`coupled_joints`)."""
    driven: set[int] = set()
    for loop in equality_loops(model):
        driven |= _unactuated_hinges(model, loop)
    return frozenset(driven)


def _unactuated_hinges(model: Any, joints: set[int]) -> set[int]:
    """The hinges among ``joints`` that no actuator drives, on the joint or through a fixed tendon."""
    import mujoco

    by_tendon = _tendon_driven(model)
    return {j for j in joints if int(model.jnt_type[j]) == mujoco.mjtJoint.mjJNT_HINGE and j not in by_tendon
            and joint_actuator(model, j) is None}


def _tendon_driven(model: Any) -> set[int]:
    """The joints of the fixed tendons that an actuator drives (a tendon-driven gripper's, ToddlerBot's waist)."""
    import mujoco

    joints = set()
    for a in range(model.nu):
        if int(model.actuator_trntype[a]) != mujoco.mjtTrn.mjTRN_TENDON:
            continue
        tendon = int(model.actuator_trnid[a][0])
        start, count = int(model.tendon_adr[tendon]), int(model.tendon_num[tendon])
        joints |= {int(model.wrap_objid[w]) for w in range(start, start + count)
                   if int(model.wrap_type[w]) == mujoco.mjtWrap.mjWRAP_JOINT}
    return joints


def linkage_limits(model: Any, qpos: Array, coupled: frozenset[int]) -> dict[int, float]:
    """The torque limit [N m] of each unactuated hinge a linkage's motors turn (a parallel ankle's pitch and roll),
    from the motors' limits through the linkage (:func:`~zmpwalk.robots.linkages.driven_torque_limits`) in the
    posture ``qpos`` with its loops closed; the loops sharing driven hinges make one linkage."""
    import mujoco

    linkages: list[tuple[set[int], set[int]]] = []  # (driven hinges, every joint)
    for loop in equality_loops(model):
        driven = _unactuated_hinges(model, loop)
        if not driven:
            continue
        for index, (hinges, joints) in enumerate(linkages):
            if hinges & driven:
                linkages[index] = (hinges | driven, joints | loop)
                break
        else:
            linkages.append((driven, set(loop)))
    if not linkages:
        return {}
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    close_equalities(model, data, joint_dofs(model, sorted(coupled)))
    limits: dict[int, float] = {}
    for hinges, joints in linkages:
        turned, rest = sorted(hinges), sorted(joints - hinges)
        motors = [j for j in rest if joint_actuator(model, j) is not None]
        others = [j for j in rest if j not in motors]
        motor_limits = [joint_torque_limit(model, j) for j in motors]
        limits.update(zip(turned, driven_torque_limits(model, data, turned, motors, others, motor_limits),
                          strict=True))
    return limits


def model_physics_step(model: Any) -> float:
    """The model's own physics step, at most :data:`PHYSICS_STEP` [s]: the step the simulation starts from."""
    return min(float(model.opt.timestep), PHYSICS_STEP)


def pd_physics_step(leg_joints: list[tuple[float, float]], timestep: float) -> float:
    """The PD layer's period [s]: the longest of ``timestep`` over :data:`PHYSICS_SUBSTEPS` at which the discrete
    bound ``I (beta / dt)^2`` of :func:`pd_gains` lets every leg joint have the stiffness it needs, else the
    shortest of them. The bound is the simulation's, not the robot's (a motor driver runs its joint loop at several
    kHz): where it binds, the joint would be simulated softer than the rule, by as much as its reflected inertia
    is small (a URDF's ankles carry no rotor inertia).

    Args:
        leg_joints: Each leg joint the layer drives: its reflected inertia ``I`` [kg m^2] and the stiffness it
            needs [N m/rad] (the rule's ``max(I omega^2, kappa W)``, or a robot file's ``kp``).
        timestep: The model's physics step, at most :data:`PHYSICS_STEP` [s].
    """
    for count in PHYSICS_SUBSTEPS:
        if all(inertia * (PD_STEP_LIMIT * count / timestep) ** 2 >= needed for inertia, needed in leg_joints):
            return timestep / count
    return timestep / PHYSICS_SUBSTEPS[-1]


def pd_layer(model: Any, data: Any, qpos: Array, leg_joints: set[int], leg_moment: float,
             given: dict[str, tuple[float, float | None]], coupled: frozenset[int] = frozenset(),
             load_stiffness: float = PD_LOAD_STIFFNESS) -> tuple[tuple[tuple[str, Actuator], ...], float]:
    """The joints the PD layer drives, with their actuators (gains from :func:`pd_gains` at the posture ``qpos``,
    or ``given``: joint name -> (kp, kv or None for critical damping)): every torque motor on a hinge or slide,
    every leg joint without an actuator, every unactuated hinge a linkage's motors turn (:func:`loop_driven_joints`,
    its torque limit theirs through the linkage: :func:`linkage_limits`), and every joint of a model without
    actuators (a URDF), but the ``coupled`` joints (moved through an equality: :func:`coupled_joints`). A leg joint
    holds ``leg_moment`` [N m]; another hinge the weight of what it moves (:func:`_weight_moment`); a slide nothing;
    ``load_stiffness`` is the rule's ``kappa``. With them the layer's period, the physics step
    (:func:`pd_physics_step`) [s].

    Raises:
        InvalidParameterError: ``given`` names a joint the layer does not drive, a leg joint's torque
            limit is 0, or the load stiffness is not a finite number > 1.
    """
    import mujoco

    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    inertia = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, inertia)
    loop_driven = loop_driven_joints(model)
    through_linkage = linkage_limits(model, qpos, coupled)
    driven = []
    for j in range(model.njnt):
        hinge = int(model.jnt_type[j]) == mujoco.mjtJoint.mjJNT_HINGE  # a numpy integer is never `in` enums
        if not hinge and int(model.jnt_type[j]) != mujoco.mjtJoint.mjJNT_SLIDE:
            continue
        if j in coupled:
            continue
        name = element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        existing = joint_actuator(model, j)
        if existing is None and (j in leg_joints or model.nu == 0 or j in loop_driven):
            existing = Actuator(PD_PREFIX + name, "none", 0.0, 0.0,
                                min(_joint_torque_limit(model, j), through_linkage.get(j, math.inf)))
        if existing is None or existing.kind not in ("motor", "none"):
            continue
        if existing.force_limit == 0.0:
            if j in leg_joints:
                raise InvalidParameterError(f"{name} torque limit", 0.0, "a leg joint's torque limit > 0 N m "
                                            "(actuatorfrcrange, a URDF's <limit effort>, the motor's ctrlrange)")
            continue  # the model holds it passive
        dof = int(model.jnt_dofadr[j])
        moment = leg_moment if j in leg_joints else _weight_moment(model, data, j) if hinge else 0.0
        driven.append((name, existing, float(inertia[dof, dof]), moment, j in leg_joints))
    unknown = sorted(set(given) - {name for name, *_ in driven})
    if unknown:
        raise InvalidParameterError("pd joint", unknown[0], "a joint the PD layer drives (a torque motor's or an "
                                    "unactuated leg joint): " + ", ".join(name for name, *_ in driven))
    timestep = pd_physics_step([(i, given[name][0] if name in given else rule_stiffness(i, w, load_stiffness))
                                for name, _, i, w, leg in driven if leg], model_physics_step(model))
    layer = []
    for name, existing, reflected, moment, _ in driven:
        kp, kv = pd_gains(reflected, moment, timestep, load_stiffness)
        if name in given:
            kp, wanted = given[name]
            kv = 2.0 * PD_DAMPING_RATIO * math.sqrt(kp * reflected) if wanted is None else wanted
        layer.append((name, replace(existing, kp=kp, kv=kv, pd_layer=True, inertia=reflected)))
    return tuple(layer), timestep
