"""Bad input as a new user would try it: one clear error each, naming the parameter, value and range."""

from __future__ import annotations

import math
from importlib import resources

import pytest

from zmpwalk import (
    FileFormatError,
    InfeasibleCommandError,
    InvalidParameterError,
    StepCommand,
    UnknownNameError,
    UnreachableError,
    ZmpwalkError,
    generate,
    load_robot,
)
from zmpwalk.scenarios import load_scenario, load_steps_file


@pytest.mark.parametrize("kwargs, parameter", [
    ({"duration": 0.0}, "duration"),
    ({"duration": -0.8}, "duration"),
    ({"duration": math.nan}, "duration"),
    ({"duration": 0.8, "forward": math.inf}, "forward"),
    ({"duration": 0.8, "side": math.nan}, "side"),
    ({"duration": 0.8, "turn": 2.0}, "turn"),
    ({"duration": 0.8, "up_ratio": 1.2}, "up_ratio"),
    ({"duration": 0.8, "up_ratio": 0.0}, "up_ratio"),
    ({"duration": 0.8, "d1": 1.0}, "d1"),
    ({"duration": 0.8, "d1": -0.1}, "d1"),
    ({"duration": 0.8, "dsp_time": 0.9}, "dsp_time"),
    ({"duration": 0.8, "dsp_time": 0.41}, "dsp_time"),
    ({"duration": 0.8, "up_ratio": 0.05}, "up_ratio"),
    ({"duration": 0.8, "up_ratio": 0.95}, "up_ratio"),
    ({"duration": 0.8, "d1_recovery": 0.99}, "d1_recovery"),
    ({"duration": 0.001}, "duration"),
    ({"duration": 800.0}, "duration"),
    ({"duration": 0.8, "alpha": -1.0}, "alpha"),
    ({"duration": 0.8, "forward": 0.1, "stop": True}, "forward"),
    ({"duration": "0.8"}, "duration"),
])
def test_bad_step_commands(kwargs, parameter):
    with pytest.raises(InvalidParameterError) as info:
        StepCommand(**kwargs)
    assert info.value.parameter == parameter
    assert parameter in str(info.value) and "expected" in str(info.value)
    assert isinstance(info.value, ZmpwalkError)


def test_duration_shorter_than_the_double_support(hubo):
    with pytest.raises(InvalidParameterError, match=r"step 2: duration = 0.1 .*double-support time d = 0.1 s"):
        generate(hubo, [StepCommand(0.8, 0.1), StepCommand(0.1, 0.1)])


def test_stride_beyond_reach_names_the_stride_the_largest_that_fits_leg_time_and_excess(hubo):
    with pytest.raises(InfeasibleCommandError) as info:
        generate(hubo, [StepCommand(0.8, 0.2), StepCommand(0.8, 0.9)])
    error = info.value
    assert error.parameter == "forward" and error.value == 0.9
    assert "step 2: forward = 0.9 is not allowed" in str(error) and " m forward (forward = 0." in str(error)
    cause = error.cause
    assert isinstance(cause, UnreachableError) and cause.excess > 0 and cause.leg in ("left", "right")
    assert "out of reach from t =" in str(error) and "by up to" in str(error) and cause.time > 0
    # the largest stride that fits does fit, and 1 % more does not
    largest = error.largest["forward"]
    generate(hubo, [StepCommand(0.8, 0.2), StepCommand(0.8, largest)])
    with pytest.raises(InfeasibleCommandError):
        generate(hubo, [StepCommand(0.8, 0.2), StepCommand(0.8, largest * 1.01)])


def test_feet_that_would_overlap(hubo):
    with pytest.raises(InvalidParameterError, match=r"turn = 0\.7"):
        generate(hubo, [StepCommand(0.95, turn=0.7)])


@pytest.mark.parametrize("rate", [0.0, -1.0, 1e5, math.nan])
def test_bad_rate(hubo, rate):
    with pytest.raises(InvalidParameterError, match="rate"):
        generate(hubo, [StepCommand(0.8, 0.1)], rate=rate)


def test_unknown_names():
    with pytest.raises(UnknownNameError, match=r"known: .*fig28"):
        load_scenario("fig99")
    with pytest.raises(UnknownNameError, match=r"known: .*hubo"):
        load_robot("asimo")


@pytest.mark.parametrize("text, message", [
    ("[[steps]]\nduration = 0.8\nforwrd = 0.1\n", r"\[\[steps\]\] 1: unknown field 'forwrd'"),
    ("[[steps]]\nforward = 0.1\n", r"\[\[steps\]\] 1: missing field 'duration'"),
    ("[[steps]]\nduration = 0.8\n[[steps]]\nduration = -1\n", r"\[\[steps\]\] 2: duration = -1"),
    ("[[steps]]\nduration = 0.8\nrepeat = 0\n", r"\[\[steps\]\] 1: repeat = 0"),
    ("[[steps]]\nduration = 0.8\nforward = 'far'\n", r"\[\[steps\]\] 1: forward = 'far'"),
    ("steps = 3\n", r"no \[\[steps\]\]"),
    ("[[steps]\nduration = 0.8\n", r"not valid TOML"),
    ("", r"no \[\[steps\]\]"),
])
def test_malformed_steps_files(tmp_path, text, message):
    path = tmp_path / "walk.toml"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=message) as info:
        load_steps_file(path)
    assert str(path) in str(info.value)


def test_missing_steps_file(tmp_path):
    with pytest.raises(FileFormatError, match=r"walk\.toml"):
        load_steps_file(tmp_path / "walk.toml")


def test_malformed_robot_file(tmp_path):
    path = tmp_path / "bot.toml"
    path.write_text('name = "bot"\ndescription = "x"\nmass = 1.0\nheight = 0.5\n[legs]\nhip_spacing = -0.1\n')
    with pytest.raises(FileFormatError, match=r"bot\.toml"):
        load_robot(path)


@pytest.mark.parametrize("table, message", [
    ("[stabilizer]\ncom_stifness = 3.0\n", r"\[stabilizer\] unknown gain 'com_stifness'; known: dcm, "),
    ("[stabilizer]\ncom_stiffness = -3.0\n", r"\[stabilizer\] gains.com_stiffness = -3"),
    ("[stabilizer]\nlanding_release = 0.0\n", r"\[stabilizer\] gains.landing_release = 0 .*> 0 s"),
])
def test_a_robot_files_stabilizer_gains_are_checked(tmp_path, table, message):
    """A robot file's [stabilizer] table names gains of StabilizerGains, checked as the gains check them; the
    built-in HUBO file's own gains reach the stabilizer."""
    from zmpwalk.balance import Stabilizer

    text = (resources.files("zmpwalk") / "robots" / "data" / "hubo.toml").read_text()
    path = tmp_path / "bot.toml"
    path.write_text(text.replace("[stabilizer]\ncom_stiffness = 3.0", table.rstrip("\n")))
    with pytest.raises(FileFormatError, match=message):
        load_robot(path)
    hubo = load_robot("hubo")
    assert dict(hubo.stabilizer_gains) == {"com_stiffness": 3.0, "touchdown_speed": 0.2, "whole_body_rest": 1.0}
    gains = Stabilizer(hubo, 1000.0).gains
    assert (gains.com_stiffness, gains.touchdown_speed) == (3.0, 0.2)
    assert Stabilizer(load_robot("mju-biped"), 1000.0).gains.com_stiffness == 10.0  # the default


def test_unknown_generator_lists_the_known_ones():
    from zmpwalk.patterns import generator

    with pytest.raises(UnknownNameError, match=r"unknown generator 'lipm'; known: hyperbolic, polynomial"):
        generator("lipm")


@pytest.mark.parametrize(("fields", "words"), [
    ({"duration": None}, "duration = None is not allowed; expected a finite number"),
    ({"duration": 0.8, "forward": None}, "forward = None"),
    ({"duration": 0.8, "forward": 10**400}, "forward = an integer of 401 digits"),
    ({"duration": 1e300}, r"duration = 1e\+300 is not allowed; expected a value in \[0.1, 5\] s \(seconds\)"),
    ({"duration": 800}, r"\(seconds\)"),  # milliseconds by mistake
    ({"duration": 0.8, "forward": 20}, r"forward = 20 is not allowed; expected a value in \[-2, 2\] m \(metres\)"),
    ({"duration": 0.8, "side": -3.0}, r"side = -3"),
])
def test_hostile_step_fields_are_one_clear_error(fields, words):
    with pytest.raises(InvalidParameterError, match=words):
        StepCommand(**fields)


def test_numpy_scalars_are_numbers():
    import numpy as np

    command = StepCommand(duration=np.float32(0.8), forward=np.int64(0), sway=np.float64(0.03))
    assert type(command.duration) is float and command.duration == pytest.approx(0.8, abs=1e-7)  # [s]
    assert type(command.forward) is float and command.forward == 0.0


def test_simulate_rejects_a_stabilizer_told_the_wrong_com_point():
    """A box model's pattern gives its pelvis point; a multibody-corrected one its whole-body CoM: a stabilizer
    made for the other is rejected with what the pattern gives, before anything is simulated."""
    from zmpwalk.balance import Stabilizer
    from zmpwalk.kinematics import pattern_joint_trajectory
    from zmpwalk.patterns.polynomial import generate
    from zmpwalk.sim import simulate

    hubo = load_robot("hubo")
    pattern = generate(hubo, [StepCommand(duration=0.8)], rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    with pytest.raises(InvalidParameterError, match=r"stabilizer.com_reference.*'whole_body'.*pelvis: the CoM"):
        simulate(hubo, joints, pattern, stabilizer=Stabilizer(hubo, 1000.0, com_reference="whole_body"))


def _every_error_class() -> set[type[ZmpwalkError]]:
    import importlib
    import pkgutil

    import zmpwalk

    for module in pkgutil.walk_packages(zmpwalk.__path__, "zmpwalk."):
        if module.name != "zmpwalk.__main__":
            importlib.import_module(module.name)
    found: set[type[ZmpwalkError]] = set()
    todo = [ZmpwalkError]
    while todo:
        kind = todo.pop()
        found.add(kind)
        todo.extend(kind.__subclasses__())
    return found


def _error_examples() -> list[ZmpwalkError]:
    from zmpwalk.errors import InfeasiblePatternError, SimulationError
    from zmpwalk.kinematics import JointLimitError

    reach = UnreachableError("left", 1.25, 0.012, "stage 3")
    reach.sample, reach.stage = 125, 3
    return [
        ZmpwalkError("the walk has no samples"),
        InvalidParameterError("duration", 800, "a step time in [0.3, 5] s", context="step 2"),
        InfeasibleCommandError("forward", 0.9, {"forward": 0.41}, reach),
        InfeasibleCommandError("side", 0.3, {}, InfeasiblePatternError("ZMP outside the feet")),
        UnknownNameError("robot", "hubbo", ["hubo", "mju-biped"]),
        reach,
        FileFormatError("steps.toml", "[[steps]] 2: missing field 'duration'"),
        InfeasiblePatternError("the sway cubic reverses"),
        JointLimitError("left_knee", 2.7, 1.5, (0.0, 2.6)),
        SimulationError(0.009, "root", "acceleration", "a stiffer joint than the time step integrates"),
    ]


def test_every_error_survives_pickling_with_its_message_and_fields():
    """A worker process's error reaches the pool's caller as raised (a pool that cannot unpickle one hangs)."""
    import pickle

    examples = _error_examples()
    assert {type(e) for e in examples} >= _every_error_class(), "an error class without a pickling example"
    for error in examples:
        for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
            copy = pickle.loads(pickle.dumps(error, protocol))
            assert type(copy) is type(error) and str(copy) == str(error)
            assert vars(copy).keys() == vars(error).keys()
            for name, value in vars(error).items():
                assert str(getattr(copy, name)) == str(value), name
    context = pickle.loads(pickle.dumps(FileFormatError("robot.toml", "bad").in_context("loading")))
    assert str(context) == "loading: robot.toml: bad" and context.path == "robot.toml"


def test_an_error_raised_in_a_worker_process_reaches_the_caller():
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1) as pool:
        result = pool.apply_async(_raise_in_worker)
        with pytest.raises(InvalidParameterError, match=r"duration = 800 is not allowed") as info:
            result.get(timeout=60)
    assert info.value.parameter == "duration" and info.value.value == 800


def _raise_in_worker() -> None:
    raise InvalidParameterError("duration", 800, "a step time in [0.3, 5] s")
