"""The stabilizer's compiled parts: :func:`zmpwalk.balance_kernel.tick` runs them once per control tick.

- :mod:`~zmpwalk.stabilizer.layout`: which named value sits where in the parameter, state and log arrays (the
  gains by their :class:`~zmpwalk.stabilizer_gains.StabilizerGains` field names);
- :mod:`~zmpwalk.stabilizer.rotations`: rotations and limits on plain floats;
- :mod:`~zmpwalk.stabilizer.leg`: the compiled leg (kinematics, Jacobian, the 6 x 6 solve);
- :mod:`~zmpwalk.stabilizer.estimation`: leg odometry, floor slope, the CoM and the measured ZMP;
- :mod:`~zmpwalk.stabilizer.loops`: DCM feedback, CoM admittance, ankle damping, foot force difference, torso
  attitude;
- :mod:`~zmpwalk.stabilizer.landing`: landing and stepping;
- :mod:`~zmpwalk.stabilizer.joints`: the corrections onto the joints and the servo stiffness loop;
- :mod:`~zmpwalk.stabilizer.freshness`: whether numba's disk cache of them is current.

The laws are those of :mod:`zmpwalk.balance`, whose docstring numbers them. A new gain is a field of
:class:`~zmpwalk.stabilizer_gains.StabilizerGains` and its use, ``params[P.<field>]``, in its loop.
"""
