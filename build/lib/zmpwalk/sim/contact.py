"""When a sole touches the floor and when it carries the robot: the two thresholds of the simulated sole forces,
one definition each (the simulation's CoP, the verdict's touchdowns and loaded soles, the report's plots)."""

CONTACT_FRACTION = 0.01  # [-] of the weight: a sole carrying more touches the floor
LOADED_FRACTION = 0.15  # [-] of the weight: a sole carrying more is "loaded" (its CoP is measured)
