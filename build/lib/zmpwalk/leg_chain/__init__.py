"""The kinematics of a leg, in one place: :class:`LegChain`, six revolute joints from the pelvis to the foot.

Any leg is a :class:`LegChain`: an imported model's (:mod:`zmpwalk.robots.legs`) as its axes and points,
a robot file's (HUBO's) from its link lengths (:meth:`LegChain.from_lengths`). The chain gives the forward
kinematics and the Jacobian of any leg, and its inverse kinematics chosen from the geometry:

* :mod:`zmpwalk.leg_chain.straight`: the straight yaw-roll-pitch-pitch-pitch-roll leg of Lim et al. (HUBO),
  in its own closed form, vectorised with joint rates for whole trajectories and in ``math`` for one tick;
* :mod:`zmpwalk.leg_chain.paden_kahan`: any leg whose hip axes meet and whose ankle axes meet;
* :mod:`zmpwalk.leg_chain.numeric`: damped least squares for any other leg.

:mod:`zmpwalk.leg_chain.chain` describes the chain (product of exponentials, foot and sole frames,
five-joint legs); :mod:`zmpwalk.leg_chain.rotations` holds the rotations they share.
"""

from zmpwalk.leg_chain.chain import AXES_MEET_TOLERANCE, LegChain
from zmpwalk.leg_chain.numeric import IK_DAMPING, IK_MAX_ITERATIONS, IK_MAX_STEP, IK_TOLERANCE
from zmpwalk.leg_chain.rotations import cross3, rot_x, rot_y, rot_z
from zmpwalk.leg_chain.straight import StraightLeg

__all__ = ["AXES_MEET_TOLERANCE", "IK_DAMPING", "IK_MAX_ITERATIONS", "IK_MAX_STEP", "IK_TOLERANCE", "LegChain",
           "StraightLeg", "cross3", "rot_x", "rot_y", "rot_z"]
