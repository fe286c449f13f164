"""What the simulator drives on a robot's own model: each joint's actuator as the simulation runs it
(:class:`Actuator`), the leg joints by role (:class:`LegJoint`) and the model's plant (:class:`ModelPlant`), with
the constants of the joint PD layer's gain rule (:func:`zmpwalk.robots.pd.pd_gains`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


PHYSICS_STEP = 0.001  # [s] the simulation's physics step at most (zmpwalk.sim.plant), the PD layer's period at most
PHYSICS_SUBSTEPS = (1, 2, 4)  # [-] the model's step (at most PHYSICS_STEP) over these: the PD layer's periods


HUBO_FOOT_LIFT = 0.04  # [m] HUBO's foot lift, scaled by the leg length for another robot
LIFT_RANGE_MARGIN = 0.1  # [rad] of a pitch joint's range the default foot lift leaves free at the swing's apex
PD_BANDWIDTH = 2 * math.pi * 4.0  # [rad/s] omega: a PD joint's natural frequency on its own inertia, at least


PD_DAMPING_RATIO = 1.0  # [-] zeta: damping of a PD joint on its own inertia (critical)


PD_LOAD_STIFFNESS = 4.0  # [-] kappa: a PD joint is at least this many times the weight moment it holds per rad


PD_WEAK_ANKLE_LOAD_STIFFNESS = 8.0  # [-] kappa where an ankle roll cannot hold the weight at the sole's side edge


PD_STEP_LIMIT = 0.5  # [-] beta: sqrt(kp / I) times the physics step at most (discrete stability below 2)


PD_PREFIX = "zmpwalk_pd_"  # name of the actuator the simulation adds to a joint the model leaves unactuated


ACTUATOR_LABELS = {"position": "position servo", "motor": "torque motor + PD", "none": "PD (no actuator)",
                   "general": "general"}


@dataclass(frozen=True)
class Actuator:
    """The actuator driving one joint, as the simulation runs it.

    Attributes:
        name: Actuator name in the model (``zmpwalk_pd_JOINT`` where the model has none and the simulation adds one).
        kind: The model's actuator: ``"position"`` (a servo ``kp (u - q) - kv q'``), ``"motor"`` (torque),
            ``"general"`` (anything else), or ``"none"`` (the joint has no actuator in the model).
        kp: Position gain [N m/rad]: the servo's, or the PD layer's (0 for a motor or general actuator without one).
        kv: Velocity gain [N m s/rad], likewise.
        force_limit: Largest |torque| the actuator or the joint allows [N m] (inf where unlimited): a motor's
            ``ctrlrange`` times its gain and gear, the actuator's ``forcerange`` times its gear, the joint's
            ``actuatorfrcrange`` (a URDF's ``<limit effort>``), the smallest that applies.
        pd_layer: The joint is driven by a joint PD loop (a humanoid's firmware): ``kp``, ``kv`` from
            :func:`pd_gains` or the robot file's ``[pd]``, the torque clipped at ``force_limit``.
        inertia: The joint's reflected inertia ``I`` at the ready posture, from which the PD layer's gains are
            derived [kg m^2] (nan without the PD layer).
    """

    name: str
    kind: str
    kp: float  # [N m/rad]
    kv: float  # [N m s/rad]
    force_limit: float  # [N m]
    pd_layer: bool = False
    inertia: float = math.nan  # [kg m^2]

    @property
    def servo(self) -> bool:
        """Whether the simulation drives the joint with angles: a position servo or the PD layer."""
        return self.kind == "position" or self.pd_layer

    @property
    def label(self) -> str:
        """What drives the joint, in words: ``position servo``, ``torque motor + PD``, ``PD (no actuator)``."""
        return ACTUATOR_LABELS.get(self.kind, self.kind)


@dataclass(frozen=True)
class LegJoint:
    """One leg joint of the model, by role.

    Attributes:
        role: One of :data:`zmpwalk.robots.imported.ROLES`.
        name: The model's joint name.
        axis: Unit axis in the pelvis frame at the zero pose, (3,).
        sign: +1 where the axis points along +z (yaw), +x (roll) or +y (pitch), else -1.
        zero_offset: The model's zero pose bend of this joint [rad] (the knee's; 0 for the others).
        limits: (lower, upper) [rad].
        actuator: Its actuator, or None.
    """

    role: str
    name: str
    axis: tuple[float, float, float]
    sign: int
    zero_offset: float  # [rad]
    limits: tuple[float, float]  # [rad]
    actuator: Actuator | None


@dataclass(frozen=True)
class ModelPlant:
    """What the simulator needs to run the robot's own model (see :mod:`zmpwalk.sim.plant`).

    Attributes:
        path: The model file.
        base_body: Name of the legs' base (the pelvis frame): the floating base, or the pelvis below a waist that no
            actuator of its own drives (:func:`zmpwalk.robots.tree.legs_base`).
        feet: Foot body names (left, right).
        joints: The 12 leg joints (left then right, role order).
        qpos_reference: The reference pose (keyframe or zero pose), ``nq`` values.
        ctrl_reference: Controls holding that pose, ``nu`` values.
        package_paths: Folders searched for a URDF's ``package://`` paths.
        sole_polygon: Sole corners in the left foot frame (x forward, y left) [m], counter-clockwise, (m, 2).
        held_joints: Joints held at the reference pose (names).
        keyframe: The keyframe of the reference pose, or None (the zero pose).
        rest_mass: Mass of everything but the leg segments (rigid with the base) [kg].
        rest_com: Its centre of mass in the pelvis frame [m].
        pd_joints: Every joint driven by the joint PD layer, leg joints included: (joint name, its actuator).
        physics_step: The simulation's physics step, the PD layer's period [s]: :attr:`model_step`, or a half or
            a quarter of it where the layer's discrete bound would hold a leg joint below the rule's stiffness
            (:func:`zmpwalk.robots.pd.pd_physics_step`).
        model_step: The model's own physics step, at most :data:`PHYSICS_STEP` [s].
        load_stiffness: The PD layer's ``kappa`` [-] (:func:`~zmpwalk.robots.pd.pd_gains`) its gains were derived
            with.
        ankle_roll_torque: The weaker ankle roll's torque limit [N m] (0 for a five-joint leg, inf unlimited).
        sole_edge_moment: The robot's weight times the lateral distance from the ankle to the sole's nearer side
            edge [N m]: the ankle roll torque that holds the weight with the CoP on that edge.
        pd_given: The joints whose PD gains the robot file gives (names), not derived.
        root_body: Name of the floating base where it is not ``base_body``, else empty.
        coupled_joints: Joints a driven joint moves through an equality (names; a geared hip yaw's drive, a parallel
            ankle's or waist's cranks and rods: :func:`~zmpwalk.robots.pd.coupled_joints`): neither held nor driven
            (their actuators' controls 0).
        ready_stretch: The ready posture's hip-to-ankle distance over the straight leg [-] (the left leg's).
        file_values: The fields of the robot file's ``[posture]`` and ``[walking]`` (or ``load_robot``'s
            ``ready_stretch``) that replace derived values (names).
    """

    path: Path
    base_body: str
    feet: tuple[str, str]
    joints: tuple[LegJoint, ...]
    qpos_reference: tuple[float, ...]
    ctrl_reference: tuple[float, ...]
    package_paths: tuple[Path, ...] = ()
    sole_polygon: tuple[tuple[float, float], ...] = ()
    held_joints: tuple[str, ...] = field(default=())
    keyframe: str | None = None
    rest_mass: float = 0.0  # [kg]
    rest_com: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m]
    pd_joints: tuple[tuple[str, Actuator], ...] = ()
    physics_step: float = PHYSICS_STEP  # [s]
    model_step: float = PHYSICS_STEP  # [s]
    load_stiffness: float = PD_LOAD_STIFFNESS  # [-]
    ankle_roll_torque: float = math.inf  # [N m]
    sole_edge_moment: float = 0.0  # [N m]
    pd_given: tuple[str, ...] = ()
    root_body: str = ""
    coupled_joints: tuple[str, ...] = ()
    ready_stretch: float = 0.0  # [-]
    file_values: tuple[str, ...] = ()

    @property
    def derived_load_stiffness(self) -> float:
        """The rule's ``kappa`` for this robot where no robot file sets it [-]: :data:`PD_LOAD_STIFFNESS`, or
        :data:`PD_WEAK_ANKLE_LOAD_STIFFNESS` where an ankle roll cannot hold the robot's weight with the CoP on
        the sole's side edge (``ankle_roll_torque < sole_edge_moment``; a five-joint leg has none): on one foot
        the hips then carry the sideways balance the ankle cannot, and twice the stiffness halves what they yield
        to it (docs/robot-import.md: PNDbotics Adam Lite, Unitree's H2 URDF and BXI Elf2 walk their three example
        walks at 8; at 4 the first two fail them)."""
        return PD_WEAK_ANKLE_LOAD_STIFFNESS if self.ankle_roll_torque < self.sole_edge_moment else PD_LOAD_STIFFNESS

    @property
    def posture_set_by(self) -> str:
        """The field that set the ready posture, ``"ready_stretch"`` or ``"pelvis_height"``; empty: derived (the
        keyframe's)."""
        return next((name for name in ("ready_stretch", "pelvis_height") if name in self.file_values), "")
