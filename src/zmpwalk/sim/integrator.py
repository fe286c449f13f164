"""Which integrator a plant needs: MuJoCo's Euler applies an actuator's damping explicitly, which diverges past a
bound that the joint PD layer's gains can reach where a joint moves light bodies on both sides of it (Atlas's back
joints between a light pelvis and a heavy torso); :func:`zmpwalk.sim.plant.build_plant` then integrates with
``implicitfast`` (docs/robot-import.md, the PD layer's step bound)."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import SimulationError
from zmpwalk.robots.pd import element_name

Array = NDArray[np.float64]

_DIVERGED = ((mujoco.mjtWarning.mjWARN_BADQPOS, "position"), (mujoco.mjtWarning.mjWARN_BADQVEL, "velocity"),
             (mujoco.mjtWarning.mjWARN_BADQACC, "acceleration"))
EULER_BOUND = 2.0  # [-] kv h / I at which Euler's explicit damping stops decaying: |1 - kv h / I| = 1


def explicit_damping_ratio(model: mujoco.MjModel, qpos: Array) -> float:
    r"""The largest eigenvalue of ``h D^1/2 M^-1 D^1/2`` at ``qpos``: ``D`` the servos' damping on each degree of
    freedom [N m s/rad] (``-biasprm[2] gear^2`` of each affine servo on a joint), ``M`` the joint-space inertia
    [kg m^2] (everything free), ``h`` the time step [s].

    MuJoCo's Euler integrator applies an actuator's damping explicitly: ``v' = -M^-1 D v`` steps as ``v_{k+1} = (1
    - h M^-1 D) v_k``, whose modes (the eigenvalues of ``h M^-1 D``, those of the symmetric matrix above) grow once
    one reaches 2 (:data:`EULER_BOUND`); on one degree of freedom it is ``kv h / I``. :func:`zmpwalk.sim.plant.
    build_plant` then integrates with ``implicitfast`` (the damping implicit), as MuJoCo advises for such models. A
    servo's stiffness ``kp h^2 / I`` is far inside its own bound (4) wherever the damping is critical (``kv = 2 sqrt(kp
    I)``). The contacts of the feet are left out (they stiffen the legs' modes): the bound errs towards implicitfast."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    damping = np.zeros(model.nv)
    for actuator in range(model.nu):
        if (int(model.actuator_trntype[actuator]) != int(mujoco.mjtTrn.mjTRN_JOINT)
                or int(model.actuator_biastype[actuator]) != int(mujoco.mjtBias.mjBIAS_AFFINE)):
            continue  # a bias other than affine does not read biasprm[2] as damping
        dof = int(model.jnt_dofadr[model.actuator_trnid[actuator][0]])
        gear = float(model.actuator_gear[actuator][0])
        damping[dof] += max(0.0, -float(model.actuator_biasprm[actuator][2]) * gear * gear)
    root = np.sqrt(damping)
    modes = float(model.opt.timestep) * root[:, None] * np.linalg.inv(mass) * root[None, :]
    return float(np.linalg.eigvalsh(modes).max()) if model.nv else 0.0


def divergence_counters(data: mujoco.MjData) -> tuple[Any, ...]:
    """MuJoCo's counters of a diverged position, velocity and acceleration in ``data`` (live views: each step
    counts into them); read them with :func:`diverged`."""
    return tuple(data.warning[int(kind)] for kind, _ in _DIVERGED)


def diverged(model: mujoco.MjModel, counters: tuple[Any, ...], time: float) -> SimulationError | None:
    """The error for the first counter of :func:`divergence_counters` that counted (MuJoCo reset the state), naming
    the joint of the position or degree of freedom it found first; None while none has. ``time`` [s]: the run's
    clock at the end of the tick (MuJoCo's own restarts at its reset)."""
    for counter, (_, quantity) in zip(counters, _DIVERGED, strict=True):
        if not counter.number:
            continue
        index = int(counter.lastinfo)
        if quantity == "position":  # a qpos address: the joint whose positions start at or before it
            joint = int(np.searchsorted(model.jnt_qposadr, index, side="right")) - 1
        else:  # a degree of freedom
            joint = int(model.dof_jntid[index]) if 0 <= index < model.nv else -1
        name = element_name(model, mujoco.mjtObj.mjOBJ_JOINT, joint) if 0 <= joint < model.njnt else "?"
        return SimulationError(time, name, quantity, "a stiffer or more damped joint than the time step integrates "
                               f"({model.opt.timestep:g} s), or forces beyond the model's")
    return None
