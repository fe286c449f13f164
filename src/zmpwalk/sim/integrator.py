"""Which integrator a plant needs: MuJoCo's Euler applies an actuator's damping explicitly, which diverges past a
bound that the joint PD layer's gains can reach where a joint moves light bodies on both sides of it (Atlas's back
joints between a light pelvis and a heavy torso); :func:`zmpwalk.sim.plant.build_plant` then integrates with
``implicitfast`` (docs/robot-import.md, the PD layer's step bound)."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

EULER_BOUND = 2.0  # [-] kv h / I at which Euler's explicit damping stops decaying: |1 - kv h / I| = 1


def explicit_damping_ratio(model: mujoco.MjModel, qpos: Array) -> float:
    r"""The largest ``kv h / I`` over the model's servos on a joint at ``qpos``: ``kv`` a servo's damping on its
    joint [N m s/rad] (``-biasprm[2] gear^2``), ``h`` the time step [s], ``I = 1 / (M^{-1})_{jj}`` the inertia the
    joint's degree of freedom moves with everything else free [kg m^2].

    MuJoCo's Euler integrator applies an actuator's damping explicitly: on one degree of freedom ``v' = -(kv / I)
    v`` steps as ``v_{k+1} = (1 - kv h / I) v_k``, which grows once ``kv h / I >= 2`` (:data:`EULER_BOUND`);
    :func:`zmpwalk.sim.plant.build_plant` then integrates with ``implicitfast`` (the damping implicit), as MuJoCo
    advises for such models. A servo's stiffness ``kp h^2 / I`` is far inside its own bound (4) wherever the damping
    is critical (``kv = 2 sqrt(kp I)``). The bound on the diagonal is a lower bound of the damping modes' (the
    largest eigenvalue of ``h D^1/2 M^-1 D^1/2``), which the stance feet's contacts stiffen: the diagonal's is the one
    kept (docs/design-log/robot-import.md)."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    inverse_diagonal = np.diag(np.linalg.inv(mass))
    largest = 0.0
    for actuator in range(model.nu):
        if model.actuator_trntype[actuator] != mujoco.mjtTrn.mjTRN_JOINT:
            continue
        damping = -float(model.actuator_biasprm[actuator][2]) * float(model.actuator_gear[actuator][0]) ** 2
        dof = int(model.jnt_dofadr[model.actuator_trnid[actuator][0]])
        largest = max(largest, damping * float(model.opt.timestep) * float(inverse_diagonal[dof]))
    return largest
